#include "debugtools/gui/session.h"

#include "core/compiled_scene.h"
#include "core/error.h"
#include "core/film.h"
#include "core/parallel.h"
#include "core/render.h"
#include "core/scene_loader.h"
#include "core/tracer.h"
#include "debugtools/aov.h"
#include "debugtools/bounce_aov.h"
#include "debugtools/stage_buffers.h"
#include "debugtools/tracers.h"
#include "debugtools/vtk_export.h"

#include <algorithm>
#include <chrono>
#include <memory>
#include <optional>
#include <sstream>

namespace pathlab::debug {
namespace {

Scene load(const SessionSettings& s) {
  Scene scene = s.scene_file.empty() ? builtin_cornell_box() : load_scene(s.scene_file);
  if (s.width) scene.film.width = *s.width;
  if (s.height) scene.film.height = *s.height;
  return scene;
}

std::string lower_extension(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

std::atomic<std::uint64_t> g_version{0};

}  // namespace

Session::Session(SessionSettings settings) { apply(settings); }

Session::~Session() { stop(); }

const Scene& Session::scene() const { return compiled_->scene(); }

void Session::apply(const SessionSettings& next) {
  if (next.tracer != "reference" && next.tracer != "wavefront")
    throw InputError("unknown tracer '" + next.tracer + "' (expected reference or wavefront)");
  if (next.intermediate == SessionSettings::Intermediate::StageBuffers) {
    if (next.tracer != "wavefront")
      throw InputError("stage buffers are the wavefront's: choose the wavefront tracer first");
    if (next.stage_vertex < 1 || next.stage_vertex > kMaxVerticesUncapped)
      throw InputError("stage buffers at vertex " + std::to_string(next.stage_vertex) + ": give a vertex in [1, " +
                       std::to_string(kMaxVerticesUncapped) + "] (1 = the camera rays' hits)");
  }
  // Load before stopping anything: a bad file leaves the current render alone.
  std::unique_ptr<Scene> authored;
  const bool reload = !authored_ || next.scene_file != loaded_file_ || next.width != settings_.width ||
                      next.height != settings_.height;
  if (reload) authored = std::make_unique<Scene>(load(next));
  stop();
  if (reload) {
    authored_ = std::move(authored);
    loaded_file_ = next.scene_file;
    compiled_.reset();
  }
  if (!compiled_ || compiled_materials_ != next.materials) {
    tracer_.reset();
    compiled_ = std::make_unique<CompiledScene>(override_materials(*authored_, next.materials));
    compiled_materials_ = next.materials;
    retrace_.reset();
  }
  settings_ = next;
  RenderSettings r = authored_->render;
  if (next.strategy) r.strategy = *next.strategy;
  if (next.max_depth) r.max_depth = *next.max_depth;
  if (next.spp) r.spp = std::max(1, *next.spp);
  if (next.seed) r.seed = *next.seed;
  if (!next.freeze_seed) r.seed += ++restarts_;  // a fresh stream of numbers on every restart
  render_settings_ = r;
  tracer_ = make_tracer(next.tracer, *compiled_, r);
  const Scene& sc = compiled_->scene();
  projection_ = std::make_unique<FilmProjection>(sc.camera, sc.film.width, sc.film.height);
  start();
}

void Session::stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  stop_ = false;
}

void Session::start() {
  {
    const std::lock_guard lock(mutex_);
    latest_.reset();
  }
  thread_ = std::thread([this] { worker(0); });
}

void Session::worker(std::uint64_t /*generation*/) {
  const ThreadLimit limit(settings_.all_threads ? 0 : 1);
  const Scene& sc = compiled_->scene();
  const int w = sc.film.width, h = sc.film.height, target = render_settings_.spp;
  const std::size_t pixels = static_cast<std::size_t>(w) * h;
  Film film(w, h, sc.film.filter);
  AovAccumulator aovs(*compiled_, render_settings_);
  // The intermediate layers: the tracer wrapped to record them.
  const Tracer* tracer = tracer_.get();
  std::optional<BounceAccumulator> bounces;
  std::optional<StageBuffers> stages;
  std::unique_ptr<Tracer> recording;
  if (settings_.intermediate == SessionSettings::Intermediate::Bounces) {
    bounces.emplace(w, h);
    recording = std::make_unique<BounceTracer>(*tracer_, *bounces);
  } else if (settings_.intermediate == SessionSettings::Intermediate::StageBuffers) {
    stages.emplace(w, h, settings_.stage_vertex);
    recording = std::make_unique<StageBufferTracer>(dynamic_cast<const WavefrontTracer&>(*tracer_), *stages);
  }
  if (recording) tracer = recording.get();
  const std::uint32_t batch = batch_size(w, h, target);
  SampleBuffer samples(pixels * batch);
  const auto start = std::chrono::steady_clock::now();

  const auto publish = [&](int done) {
    auto snap = std::make_shared<Snapshot>();
    snap->version = ++g_version;
    snap->width = w;
    snap->height = h;
    snap->spp_done = done;
    snap->spp_target = target;
    snap->seed = render_settings_.seed;
    snap->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    snap->beauty = film.image();
    snap->variance = film.variance_of_mean();
    snap->albedo = aovs.albedo();
    snap->normal = aovs.normal();
    snap->depth = aovs.depth();
    snap->material = aovs.material();
    snap->path_length = aovs.path_length();
    snap->nonfinite = aovs.nonfinite();
    snap->samples.resize(pixels);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        snap->samples[static_cast<std::size_t>(y) * w + x] = static_cast<std::uint32_t>(film.sample_count(x, y));
    std::vector<ExrChannel> channels = aov_channels(film, aovs, kAccumulatedAovs);
    add_exr_layer(channels, "nonfinite", snap->nonfinite, "Y");
    Image counts(w, h);
    for (std::size_t i = 0; i < pixels; ++i) counts.pixels[i] = vec3(static_cast<float>(snap->samples[i]));
    add_exr_layer(channels, "samples", counts, "Y");
    if (bounces) add_bounce_channels(channels, *bounces);
    if (stages)
      for (const StageBuffers::Named& n : stages->images())
        add_exr_layer(channels, "stage" + std::to_string(stages->vertex()) + "." + n.name, n.image, n.channels);
    snap->layers = layers_from_channels(w, h, channels);
    {
      const std::lock_guard lock(mutex_);
      latest_ = std::move(snap);
    }
    progress_.notify_all();
  };

  publish(0);
  for (std::uint32_t first = 0; first < static_cast<std::uint32_t>(target) && !stop_; first += batch) {
    const std::uint32_t count = std::min<std::uint32_t>(batch, static_cast<std::uint32_t>(target) - first);
    const std::span<FilmSample> out = samples.first(pixels * count);
    tracer->render_batch(first, count, out);
    if (stop_) break;
    film.add_batch(first, count, out);
    aovs.add_batch(first, count, out);
    publish(static_cast<int>(first + count));
  }
}

bool Session::snapshot(Snapshot& out) const {
  std::shared_ptr<const Snapshot> snap;
  {
    const std::lock_guard lock(mutex_);
    snap = latest_;
  }
  if (!snap || snap->version == out.version) return false;
  out = *snap;
  return true;
}

int Session::spp_done() const {
  const std::lock_guard lock(mutex_);
  return latest_ ? latest_->spp_done : 0;
}

bool Session::finished() const {
  const std::lock_guard lock(mutex_);
  return latest_ && latest_->spp_done >= latest_->spp_target;
}

bool Session::wait_spp(int spp, double timeout_seconds) const {
  std::unique_lock lock(mutex_);
  return progress_.wait_for(lock, std::chrono::duration<double>(timeout_seconds), [&] {
    return latest_ && latest_->spp_done >= std::min(spp, latest_->spp_target);
  });
}

PixelReadout Session::readout(const Snapshot& snap, int x, int y) const {
  PixelReadout r;
  r.x = x;
  r.y = y;
  if (x < 0 || y < 0 || x >= snap.width || y >= snap.height || snap.beauty.pixels.empty()) return r;
  const std::size_t i = static_cast<std::size_t>(y) * snap.width + x;
  r.radiance = snap.beauty.pixels[i];
  r.std_error = glm::sqrt(snap.variance.pixels[i]);
  r.samples = snap.samples[i];
  r.path_length = snap.path_length.pixels[i].x;
  r.nonfinite = static_cast<std::uint32_t>(snap.nonfinite.pixels[i].x);
  return r;
}

std::optional<SampleRef> Session::next_nonfinite(const Snapshot& snap, int x, int y,
                                                 std::optional<std::uint32_t> sample) const {
  const Layer* counts = find_layer(snap.layers, "nonfinite");
  if (!counts || snap.width <= 0 || snap.height <= 0) return std::nullopt;
  const std::size_t n = static_cast<std::size_t>(snap.width) * snap.height;
  const bool inside = x >= 0 && y >= 0 && x < snap.width && y < snap.height;
  const std::size_t here = inside ? static_cast<std::size_t>(y) * snap.width + x : n - 1;
  // The first bad sample of pixel i at index >= from, by replaying them.
  const auto find = [&](std::size_t i, std::uint32_t from) -> std::optional<SampleRef> {
    const auto px = static_cast<std::uint32_t>(i % snap.width), py = static_cast<std::uint32_t>(i / snap.width);
    for (std::uint32_t s = from; s < static_cast<std::uint32_t>(snap.spp_done); ++s)
      if (!is_finite(tracer_->trace_sample(px, py, s, nullptr).L)) return SampleRef{px, py, s};
    return std::nullopt;
  };
  if (inside && sample && counts->image.pixels[here].x > 0.0f)
    if (auto r = find(here, *sample + 1)) return r;
  for (std::size_t k = 1; k <= n; ++k) {  // the pixels after this one, wrapping around to it
    const std::size_t i = (here + k) % n;
    if (counts->image.pixels[i].x > 0.0f)
      if (auto r = find(i, 0)) return r;
  }
  return std::nullopt;
}

const Retrace& Session::retrace(std::uint32_t x, std::uint32_t y, std::uint32_t sample) {
  const Scene& sc = compiled_->scene();
  if (x >= static_cast<std::uint32_t>(sc.film.width) || y >= static_cast<std::uint32_t>(sc.film.height))
    throw InputError("pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") is outside the " +
                     std::to_string(sc.film.width) + "x" + std::to_string(sc.film.height) + " image");
  Retrace r;
  r.x = x;
  r.y = y;
  r.sample = sample;
  r.seed = render_settings_.seed;
  r.tracer = std::string(tracer_->name());
  // trace_sample runs on the calling thread: the replay is single-threaded
  // and draws the render's numbers (same seed, pixel, sample).
  tracer_->trace_sample(x, y, sample, &r.path);
  if (!r.path.events().empty())
    if (const auto* cam = std::get_if<CameraEvent>(&r.path.events().front())) r.film = cam->film;
  r.lines = path_lines(r.path, sample, 2.0f * compiled_->bounds_radius());
  const TraceHeader header{sc.file.empty() ? "<built-in " + sc.name + ">" : sc.file.string(), r.tracer, x, y, sample,
                           render_settings_, sc.film.width, sc.film.height};
  std::istringstream listing(path_to_text(header, r.path, sc));
  for (std::string line; std::getline(listing, line);) r.text.push_back(line);
  retrace_ = std::move(r);
  return *retrace_;
}

void Session::export_vtk(const std::filesystem::path& file) const {
  if (!retrace_) throw InputError("nothing to export: click a pixel first");
  write_path_vtp(file, retrace_->lines);
}

void Session::save_image(const std::filesystem::path& file, float exposure) const {
  Snapshot snap;
  if (!snapshot(snap)) throw InputError("nothing rendered yet");
  const std::string ext = lower_extension(file);
  if (ext == ".png") {
    write_png(file, snap.beauty, exposure);
    return;
  }
  if (ext != ".exr") throw InputError(file.string() + ": save as .exr or .png");
  // Every layer the viewer shows, under its own name ("beauty": R, G, B).
  std::vector<ExrChannel> channels;
  for (const Layer& l : snap.layers) {
    const std::vector<std::string> names = channel_names(l);
    for (int c = 0; c < std::min(l.count, 3); ++c) {
      ExrChannel& ch = channels.emplace_back();
      ch.name = (l.name == "beauty" ? "" : l.name + ".") + names[static_cast<std::size_t>(c)];
      ch.values.resize(l.image.pixels.size());
      for (std::size_t i = 0; i < l.image.pixels.size(); ++i) ch.values[i] = l.image.pixels[i][c];
    }
  }
  const Scene& sc = compiled_->scene();
  write_exr_channels(file, snap.width, snap.height, channels,
                     {{"scene", sc.file.empty() ? "<built-in " + sc.name + ">" : sc.file.string()},
                      {"tracer", std::string(tracer_->name())},
                      {"strategy", strategy_name(render_settings_.strategy)},
                      {"spp", std::to_string(snap.spp_done)},
                      {"seed", std::to_string(snap.seed)},
                      {"materials", material_override_name(settings_.materials)}});
}

}  // namespace pathlab::debug
