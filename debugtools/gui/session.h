// What pathlab-debug shows, without any window: a progressive render on a
// worker thread (one batch of samples at a time through Tracer::render_batch
// into a Film and the AOVs), restarted when a setting changes, snapshots of
// its buffers for display, the per-pixel readout, and the replay of one
// clicked sample with its events, polylines, VTK export and image saving.
// app.cpp draws it; the tests drive it directly too.
#pragma once

#include "core/image_io.h"
#include "core/scene.h"
#include "debugtools/gui/layers.h"
#include "debugtools/material_override.h"
#include "debugtools/path_geometry.h"
#include "debugtools/path_recorder.h"
#include "debugtools/projection.h"

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace pathlab {
class CompiledScene;
class Tracer;
}  // namespace pathlab

namespace pathlab::debug {

struct SessionSettings {
  std::string scene_file;  // empty: the built-in Cornell box
  std::string tracer = "reference";
  // Unset: the scene's own value.
  std::optional<Strategy> strategy;
  std::optional<int> max_depth, spp, width, height;
  std::optional<std::uint64_t> seed;
  bool freeze_seed = true;   // false: every restart draws with a new seed
  bool all_threads = true;   // false: one thread
  MaterialOverride materials = MaterialOverride::Authored;
  // Intermediate layers, live (docs/aov.md): the per-bounce decomposition
  // L0 .. L7, Lrest by technique (every sample through an observer: slower),
  // or the wavefront's stage buffers at vertex `stage_vertex` (its scalar
  // stages). One or the other.
  enum class Intermediate : std::uint8_t { None, Bounces, StageBuffers };
  Intermediate intermediate = Intermediate::None;
  int stage_vertex = 1;
};

// The buffers of the render so far, copied for display.
struct Snapshot {
  std::uint64_t version = 0;  // grows with every batch and restart
  int width = 0, height = 0;
  int spp_done = 0, spp_target = 0;
  std::uint64_t seed = 0;     // the seed the render draws with
  double seconds = 0.0;       // since the (re)start
  Image beauty, variance, albedo, normal, depth, material, path_length, nonfinite;
  std::vector<std::uint32_t> samples;  // own samples per pixel
  // Every buffer as a named layer: the channels aov_channels() gives for the
  // film and all AOVs (beauty, albedo, normal, depth, material, variance,
  // pathlength, and whatever is added there later), then "nonfinite" (NaN/Inf
  // samples per pixel) and "samples" (own samples per pixel), then the
  // intermediate layers asked for: "L0.bsdf" ... "Lrest.nee", or
  // "stage<K>.reached", ".throughput", ".direction", ".distance", ".survival",
  // ".light_pdf". The views and the readout are generic over this list.
  std::vector<Layer> layers;
};

// A sample whose radiance was NaN or infinite.
struct SampleRef {
  std::uint32_t x = 0, y = 0, sample = 0;
};

struct PixelReadout {
  int x = 0, y = 0;
  Spectrum radiance{0.0f}, std_error{0.0f};
  std::uint32_t samples = 0;
  float path_length = 0.0f;
  std::uint32_t nonfinite = 0;
};

// One replayed sample.
struct Retrace {
  std::uint32_t x = 0, y = 0, sample = 0;
  std::uint64_t seed = 0;
  std::string tracer;
  vec2 film{0.0f};             // where the camera ray crosses the film
  PathRecorder path;
  std::vector<PathLine> lines;
  std::vector<std::string> text;  // the trace-pixel listing, one line per entry
};

class Session {
 public:
  // Loads and compiles the scene and starts rendering. Throws InputError.
  explicit Session(SessionSettings settings);
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  const SessionSettings& settings() const { return settings_; }
  // Applies new settings: reloads the scene if its file changed, recompiles
  // if the materials override changed, and restarts the render. Throws
  // InputError (the old scene and render stay).
  void apply(const SessionSettings& settings);
  void restart() { apply(settings_); }

  // The scene as rendered (after overrides), its resolution and settings.
  const Scene& scene() const;
  const RenderSettings& render_settings() const { return render_settings_; }
  const FilmProjection& projection() const { return *projection_; }

  // Copies the latest buffers into `out` if they changed since out.version.
  bool snapshot(Snapshot& out) const;
  int spp_done() const;
  bool finished() const;  // reached the spp target
  // Blocks until `spp` samples per pixel (or the target) are done, or
  // `timeout_seconds` pass; false on timeout.
  bool wait_spp(int spp, double timeout_seconds) const;

  PixelReadout readout(const Snapshot& snap, int x, int y) const;

  // The next NaN/Inf sample after sample `sample` of pixel (x, y), in
  // scanline order of the pixels whose "nonfinite" count in `snap` is
  // positive (wrapping around; the same pixel's later samples first). Its
  // index is found by replaying the pixel's samples 0..spp_done-1 on this
  // thread. Empty when the snapshot has no NaN/Inf sample.
  std::optional<SampleRef> next_nonfinite(const Snapshot& snap, int x, int y, std::optional<std::uint32_t> sample) const;

  // Replays sample `sample` of pixel (x, y) on this thread with the render's
  // seed and settings; the result is kept as the current retrace.
  const Retrace& retrace(std::uint32_t x, std::uint32_t y, std::uint32_t sample);
  const std::optional<Retrace>& current_retrace() const { return retrace_; }
  // Writes the current retrace's polylines (docs/path-vtk.md). Throws
  // InputError when nothing was retraced or the file cannot be written.
  void export_vtk(const std::filesystem::path& file) const;
  // Saves the image: .exr (every layer of the snapshot, beauty as R, G, B) or .png
  // (tone-mapped with `exposure` stops). Throws InputError / SystemError.
  void save_image(const std::filesystem::path& file, float exposure) const;

 private:
  void stop();
  void start();
  void worker(std::uint64_t generation);

  SessionSettings settings_;
  std::string loaded_file_;
  MaterialOverride compiled_materials_ = MaterialOverride::Authored;
  std::unique_ptr<Scene> authored_;           // as loaded, with resolution overrides
  std::unique_ptr<CompiledScene> compiled_;   // after the materials override
  std::unique_ptr<Tracer> tracer_;
  std::unique_ptr<FilmProjection> projection_;
  RenderSettings render_settings_;
  std::uint64_t restarts_ = 0;
  std::optional<Retrace> retrace_;

  mutable std::mutex mutex_;
  mutable std::condition_variable progress_;
  std::shared_ptr<const Snapshot> latest_;  // guarded by mutex_
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace pathlab::debug
