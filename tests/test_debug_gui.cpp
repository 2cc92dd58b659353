// pathlab-debug, tried as a person would: the real binary runs a script under
// Xvfb (CTest label gui) that waits for the render, hovers, switches views,
// clicks a pixel, exports its path as VTK, saves the image and takes
// screenshots; the test then checks the files. Also the pieces behind it
// without a window: the session, the views and the script parser.
#include "core/compiled_scene.h"
#include "core/error.h"
#include "core/image_io.h"
#include "core/scene_loader.h"
#include "debugtools/bounce_aov.h"
#include "debugtools/gui/app.h"
#include "debugtools/gui/script.h"
#include "debugtools/gui/session.h"
#include "debugtools/gui/views.h"
#include "debugtools/projection.h"
#include "reference/reference_tracer.h"
#include "tests/temp_dir.h"

#include <gtest/gtest.h>

#include <vtkCellArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkXMLPolyDataReader.h>

#include <sys/wait.h>

#include <cstdlib>
#include <cmath>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

namespace pathlab::debug {
namespace {

using DebugGui = test::TempDirTest;

SessionSettings small_cornell(int res, int spp) {
  SessionSettings s;
  s.width = s.height = res;
  s.spp = spp;
  return s;
}

// The recorded path of one sample of the built-in Cornell box at res x res,
// traced independently of the GUI.
PathRecorder reference_path(int res, std::uint32_t x, std::uint32_t y, std::uint32_t sample) {
  Scene scene = builtin_cornell_box();
  scene.film.width = scene.film.height = res;
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  PathRecorder rec;
  ReferenceTracer(compiled, settings).trace_sample(x, y, sample, &rec);
  return rec;
}

// The projection inverts the camera: a point on the ray through a film
// position projects back to that position.
TEST(FilmProjection, InvertsTheCameraRays) {
  Scene scene = builtin_cornell_box();
  scene.film.width = 64;
  scene.film.height = 48;
  const Camera camera(scene.camera, 64, 48);
  const FilmProjection proj(scene.camera, 64, 48);
  for (const vec2 film : {vec2(0.5f, 0.5f), vec2(63.2f, 10.0f), vec2(32.0f, 47.9f), vec2(12.25f, 30.5f)}) {
    const Ray ray = camera.generate_ray(film, vec2(0.5f));
    const auto back = proj.project(ray.origin + 3.0f * ray.dir);
    ASSERT_TRUE(back);
    EXPECT_NEAR(back->x, film.x, 1e-3f);
    EXPECT_NEAR(back->y, film.y, 1e-3f);
  }
  EXPECT_FALSE(proj.project(scene.camera.position - camera.forward()));  // behind the camera
}

TEST(DebugScript, ParsesCommandsAndNamesTheLineOfAMistake) {
  const auto cmds = parse_script("# a comment\nwait-spp 8\nclick 3 4  # pick\nview albedo\nexport-vtk a.vtp\nquit\n", "s.txt");
  ASSERT_EQ(cmds.size(), 5u);
  EXPECT_EQ(cmds[0].kind, ScriptCommand::Kind::WaitSpp);
  EXPECT_EQ(cmds[0].x, 8);
  EXPECT_EQ(cmds[1].kind, ScriptCommand::Kind::Click);
  EXPECT_EQ(cmds[1].y, 4);
  EXPECT_EQ(cmds[3].arg, "a.vtp");
  const auto more = parse_script("wheel 10 20 -3\ndrag 5 6 -40 7\nsplit 0.25\nscale log\ncompare tracer\nnext-nan\n", "t.txt");
  ASSERT_EQ(more.size(), 6u);
  EXPECT_EQ(more[0].dx, -3);
  EXPECT_EQ(more[1].dx, -40);
  EXPECT_EQ(more[1].dy, 7);
  EXPECT_FLOAT_EQ(more[2].value, 0.25f);
  const auto layers = parse_script("layers bounces\nlayers stage 3\nlayers none\n", "u.txt");
  ASSERT_EQ(layers.size(), 3u);
  EXPECT_EQ(layers[0].kind, ScriptCommand::Kind::Layers);
  EXPECT_EQ(layers[1].arg, "stage");
  EXPECT_EQ(layers[1].x, 3);
  EXPECT_EQ(layers[2].arg, "none");
  for (const char* bad : {"clik 3 4", "click 3", "scale sideways", "wait-spp -1", "quit now", "wheel 1 2", "split 1.5",
                          "compare nothing", "drag 1 2 3", "layers stage", "layers all", "layers bounces 2"}) {
    try {
      parse_script(std::string("view beauty\n") + bad + "\n", "s.txt");
      ADD_FAILURE() << bad;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("s.txt:2"), std::string::npos) << e.what();
    }
  }
}

TEST(DebugSession, RendersProgressivelyReadsOutAndRetracesTheRendersSample) {
  Session session(small_cornell(24, 8));
  ASSERT_TRUE(session.wait_spp(8, 120.0));
  Snapshot snap;
  ASSERT_TRUE(session.snapshot(snap));
  EXPECT_EQ(snap.spp_done, 8);
  const PixelReadout r = session.readout(snap, 12, 4);
  EXPECT_EQ(r.samples, 8u);
  EXPECT_GT(max_component(r.radiance), 0.0f);
  EXPECT_GT(max_component(r.std_error), 0.0f);
  EXPECT_GE(r.path_length, 1.0f);

  const Retrace& t = session.retrace(12, 4, 3);
  const PathRecorder want = reference_path(24, 12, 4, 3);
  EXPECT_EQ(t.path.events().size(), want.events().size());
  EXPECT_EQ(t.path.result(), want.result());
  EXPECT_FALSE(t.text.empty());
  EXPECT_FALSE(t.lines.empty());

  // The layers are the EXR channels of the film and every AOV (aov_channels),
  // then the NaN/Inf and sample counts; each draws something.
  std::vector<std::string> names;
  for (const Layer& l : snap.layers) names.push_back(l.name);
  EXPECT_EQ(names, (std::vector<std::string>{"beauty", "albedo", "normal", "depth", "material", "variance", "pathlength",
                                             "nonfinite", "samples"}));
  EXPECT_EQ(find_layer(snap.layers, "albedo")->image.pixels, snap.albedo.pixels);
  EXPECT_EQ(find_layer(snap.layers, "beauty")->channels, "R,G,B");
  EXPECT_EQ(find_layer(snap.layers, "depth")->channels, "Z");
  for (const Layer& l : snap.layers) {
    const Mapping m = default_mapping(l);
    const auto rgba = layer_rgba(l, m, 0.0f, auto_range(l, m));
    ASSERT_EQ(rgba.size(), 24u * 24u * 4u);
    std::set<std::uint32_t> colours;
    for (std::size_t i = 0; i < rgba.size(); i += 4) colours.insert(rgba[i] | rgba[i + 1] << 8 | rgba[i + 2] << 16);
    if (l.name != "nonfinite" && l.name != "samples") {
      EXPECT_GT(colours.size(), 2u) << l.name;
    }
  }
  EXPECT_THROW(session.retrace(24, 0, 0), InputError);

  // White Lambert everywhere: the albedo buffer turns white, the light stays.
  SessionSettings white = session.settings();
  white.materials = MaterialOverride::WhiteLambert;
  session.apply(white);
  ASSERT_TRUE(session.wait_spp(1, 120.0));
  Snapshot w;
  ASSERT_TRUE(session.snapshot(w));
  EXPECT_EQ(w.albedo.at(1, 12), vec3(1.0f));  // the red wall
  EXPECT_GT(max_component(w.beauty.at(12, 12)), 0.0f);
}

// The intermediate layers, live: the per-bounce decomposition (which sums to
// the beauty, as `render --aov bounces` does) and the wavefront's stage
// buffers, as layers of the snapshot the views and readout use.
TEST(DebugSession, ShowsThePerBounceLayersAndTheStageBuffersLive) {
  SessionSettings settings = small_cornell(12, 4);
  settings.intermediate = SessionSettings::Intermediate::Bounces;
  Session session(settings);
  ASSERT_TRUE(session.wait_spp(4, 120.0));
  Snapshot snap;
  ASSERT_TRUE(session.snapshot(snap));
  std::vector<std::string> names;
  for (const Layer& l : snap.layers) names.push_back(l.name);
  for (int d = 0; d <= kBounceDepths; ++d)
    for (Technique t : {Technique::Bsdf, Technique::Nee}) {
      const std::string name = bounce_layer_name(d) + "." + technique_name(t);
      EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
    }
  // The built-in box film: each layer is the mean over the pixel's samples,
  // so the layers of a pixel sum to its beauty (float rounding apart).
  for (int y = 0; y < 12; y += 3)
    for (int x = 0; x < 12; x += 3) {
      dvec3 sum(0.0);
      for (const Layer& l : snap.layers)
        if (l.name.size() > 1 && l.name[0] == 'L' && l.name.find('.') != std::string::npos)
          sum += dvec3(l.image.at(x, y));
      const vec3 beauty = snap.beauty.at(x, y);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(sum[c], beauty[c], 1e-5 + 1e-4 * beauty[c]) << x << "," << y;
    }
  EXPECT_GT(max_component(find_layer(snap.layers, "L1.nee")->image.at(6, 6)), 0.0f);

  // Stage buffers are the wavefront's: refused for the reference, the
  // render left as it was.
  SessionSettings stage = session.settings();
  stage.intermediate = SessionSettings::Intermediate::StageBuffers;
  stage.stage_vertex = 1;
  EXPECT_THROW(session.apply(stage), InputError);
  EXPECT_EQ(session.settings().intermediate, SessionSettings::Intermediate::Bounces);
  stage.tracer = "wavefront";
  session.apply(stage);
  ASSERT_TRUE(session.wait_spp(4, 120.0));
  ASSERT_TRUE(session.snapshot(snap));
  for (const char* name : {"stage1.reached", "stage1.throughput", "stage1.direction", "stage1.distance",
                           "stage1.survival", "stage1.light_pdf"})
    EXPECT_NE(find_layer(snap.layers, name), nullptr) << name;
  EXPECT_EQ(find_layer(snap.layers, "L0.bsdf"), nullptr);
  // Every camera ray of the closed box reaches vertex 1 at throughput 1.
  const Layer& reached = *find_layer(snap.layers, "stage1.reached");
  EXPECT_EQ(reached.channels, "Y");
  for (const vec3& v : reached.image.pixels) EXPECT_EQ(v.x, 1.0f);
  EXPECT_EQ(find_layer(snap.layers, "stage1.throughput")->image.at(5, 5), vec3(1.0f));
  EXPECT_GT(find_layer(snap.layers, "stage1.distance")->image.at(5, 5).x, 0.0f);
}

TEST(DebugSession, OpensAnotherSceneAndKeepsTheOldOneOnABadFile) {
  Session session(small_cornell(16, 1));
  SessionSettings next = session.settings();
  next.scene_file = std::string(PATHLAB_SOURCE_DIR) + "/analytic-scenes/furnace-sphere.json";
  next.width.reset();
  next.height.reset();
  session.apply(next);
  EXPECT_EQ(session.scene().name, "furnace-sphere");
  ASSERT_TRUE(session.wait_spp(1, 120.0));
  SessionSettings bad = session.settings();
  bad.scene_file = "no-such-scene.json";
  EXPECT_THROW(session.apply(bad), InputError);
  EXPECT_EQ(session.scene().name, "furnace-sphere");
  EXPECT_EQ(session.settings().scene_file, next.scene_file);
}

// The whole program under Xvfb, as in the issue: open the Cornell box, hover,
// switch views, click a pixel, export VTK, save, screenshot, quit.
TEST_F(DebugGui, ScriptedSessionExportsThePathAndShowsTheImageWithItsOverlay) {
  const int res = 128, px = 64, py = 90;
  const auto vtp = dir_ / "click.vtp", shot = dir_ / "shot.png", albedo = dir_ / "albedo.png",
             exr = dir_ / "image.exr", last = dir_ / "final.png", script = dir_ / "events.txt";
  std::ofstream(script) << "wait-spp 16\nhover 30 60\nview albedo\nscreenshot " << albedo.string()
                        << "\nview beauty\nclick " << px << " " << py << "\nexport-vtk " << vtp.string() << "\nsave "
                        << exr.string() << "\nscreenshot " << shot.string() << "\nquit\n";
  const std::string command = std::string(PATHLAB_DEBUG_BINARY) + " --resolution 128x128 --spp 16 --script " +
                              script.string() + " --screenshot " + last.string() + " 2>" + (dir_ / "err.txt").string();
  const int status = std::system(command.c_str());
  std::ifstream err_file(dir_ / "err.txt");
  const std::string err((std::istreambuf_iterator<char>(err_file)), std::istreambuf_iterator<char>());
  ASSERT_EQ(status, 0) << command << "\n" << err;

  // The VTK file: the clicked sample's path, as an independent replay has it.
  const PathRecorder want = reference_path(res, px, py, 0);
  vtkNew<vtkXMLPolyDataReader> reader;
  reader->SetFileName(vtp.c_str());
  reader->Update();
  vtkPolyData* poly = reader->GetOutput();
  std::size_t lights = 0, path_points = 0;
  for (const PathEvent& e : want.events()) {
    const auto* l = std::get_if<LightEvent>(&e);
    lights += l != nullptr && l->rejected == LightRejection::None;  // a rejected sample has no shadow ray
    path_points += std::holds_alternative<CameraEvent>(e) || std::holds_alternative<HitEvent>(e) ||
                   std::holds_alternative<EscapeEvent>(e);
  }
  EXPECT_EQ(poly->GetNumberOfLines(), static_cast<vtkIdType>(1 + lights));
  EXPECT_EQ(poly->GetNumberOfPoints(), static_cast<vtkIdType>(path_points + 2 * lights));
  for (const char* name : {"depth", "throughput", "radiance_added", "pdf", "lobe", "flags"})
    EXPECT_NE(poly->GetPointData()->GetArray(name), nullptr) << name;

  // The screenshot shows the rendered image: its image area matches the saved
  // beauty image, tone-mapped, almost everywhere (the overlay covers a little).
  // read_image gives a PNG's 8-bit values / 255, still sRGB-encoded.
  const Image beauty = read_image(exr), screen = read_image(shot), before = read_image(albedo);
  ASSERT_EQ(beauty.width, res);
  ASSERT_GE(screen.width, res);
  ASSERT_GE(screen.height, res);
  int matching = 0;
  double sum = 0.0, sum2 = 0.0;
  for (int y = 0; y < res; ++y)
    for (int x = 0; x < res; ++x) {
      const vec3 s = screen.at(x, y);
      bool same = true;
      for (int c = 0; c < 3; ++c)
        same &= std::abs(s[c] - linear_to_srgb(std::min(beauty.at(x, y)[c], 1.0f))) < 3.0f / 255.0f;
      matching += same;
      sum += s.y;
      sum2 += static_cast<double>(s.y) * s.y;
    }
  EXPECT_GT(matching, res * res * 9 / 10) << "the window does not show the rendered image";
  const double n = res * res;
  EXPECT_GT(sum2 / n - (sum / n) * (sum / n), 1e-3) << "the image area is flat";

  // The path overlay: pure path green and vertex yellow near where the
  // path's vertices project; none before the click.
  const FilmProjection proj(builtin_cornell_box().camera, res, res);
  const auto is = [](const vec3& v, const unsigned char (&c)[4]) {
    for (int k = 0; k < 3; ++k)
      if (std::abs(v[k] - static_cast<float>(c[k]) / 255.0f) > 0.1f) return false;
    return true;
  };
  int vertices_seen = 0, vertices_on_image = 0;
  for (const PathEvent& e : want.events()) {
    const auto* h = std::get_if<HitEvent>(&e);
    if (!h) continue;
    const auto f = proj.project(h->p);
    if (!f || f->x < 3 || f->y < 3 || f->x >= res - 3 || f->y >= res - 3) continue;
    ++vertices_on_image;
    bool seen = false;
    for (int dy = -3; dy <= 3; ++dy)
      for (int dx = -3; dx <= 3; ++dx)
        seen |= is(screen.at(static_cast<int>(f->x) + dx, static_cast<int>(f->y) + dy), kVertexColour);
    vertices_seen += seen;
  }
  ASSERT_GT(vertices_on_image, 0);
  // Vertex 1 lies on the clicked pixel's camera ray: its dot is on that pixel,
  // whatever the projection code says.
  bool on_click = false;
  for (int dy = -2; dy <= 2; ++dy)
    for (int dx = -2; dx <= 2; ++dx) on_click |= is(screen.at(px + dx, py + dy), kVertexColour);
  EXPECT_TRUE(on_click) << "no vertex drawn on the clicked pixel";
  EXPECT_EQ(vertices_seen, vertices_on_image);
  int green = 0, green_before = 0;
  for (int y = 0; y < res; ++y)
    for (int x = 0; x < res; ++x) green += is(screen.at(x, y), kPathColour), green_before += is(before.at(x, y), kPathColour);
  EXPECT_GT(green, 10);
  EXPECT_EQ(green_before, 0);

  // The panel beside the image is drawn (text on a background), and the final
  // screenshot exists.
  double panel = 0.0, panel2 = 0.0;
  int count = 0;
  for (int y = 0; y < std::min(screen.height, 300); ++y)
    for (int x = res + 10; x < screen.width; ++x, ++count) panel += screen.at(x, y).y, panel2 += screen.at(x, y).y * screen.at(x, y).y;
  EXPECT_GT(panel2 / count - (panel / count) * (panel / count), 1e-4) << "the panel is blank";
  EXPECT_TRUE(std::filesystem::exists(last));
}

// Layers come from EXR channel names, generically: a layer another part of
// pathlab adds (per-bounce radiance L0, a stage buffer) needs no GUI change.
TEST(DebugLayers, GroupsChannelsIntoLayersInRgbOrder) {
  const std::vector<ExrChannel> channels = {{"B", {3}},      {"G", {2}},       {"R", {1}},       {"L0.B", {6}},
                                            {"L0.G", {5}},   {"L0.R", {4}},    {"depth.Z", {7}}, {"uv.U", {8}},
                                            {"uv.V", {9}},   {"stage_count.Y", {10}}};
  const std::vector<Layer> layers = layers_from_channels(1, 1, channels);
  ASSERT_EQ(layers.size(), 5u);
  EXPECT_EQ(layers[0].name, "beauty");
  EXPECT_EQ(layers[0].channels, "R,G,B");
  EXPECT_EQ(layers[0].image.pixels[0], vec3(1, 2, 3));
  EXPECT_EQ(layers[1].name, "L0");
  EXPECT_EQ(layers[1].image.pixels[0], vec3(4, 5, 6));
  EXPECT_EQ(default_mapping(layers[1]), Mapping::Tone);
  EXPECT_EQ(layers[2].image.pixels[0], vec3(7));
  EXPECT_EQ(default_mapping(layers[2]), Mapping::Linear);
  EXPECT_EQ(layers[3].count, 2);
  EXPECT_EQ(layers[3].image.pixels[0], vec3(8, 9, 0));
  EXPECT_EQ(layers[4].name, "stage_count");
}

// Linear and log views map the auto range onto the ramp; values <= 0 are
// black under log, non-finite values magenta under every mapping.
TEST(DebugViews, LinearAndLogRangesMapOntoTheRamp) {
  Layer l;
  l.name = "variance";
  l.channels = "Y";
  l.count = 1;
  l.image = Image(5, 1);
  const float values[] = {1e-6f, 1e-4f, 1e-2f, 0.0f, NAN};
  for (int i = 0; i < 5; ++i) l.image.pixels[static_cast<std::size_t>(i)] = vec3(values[i]);
  const Range lin = auto_range(l, Mapping::Linear), log = auto_range(l, Mapping::Log);
  EXPECT_EQ(lin.lo, 0.0f);
  EXPECT_EQ(lin.hi, 1e-2f);
  EXPECT_EQ(log.lo, 1e-6f);
  EXPECT_EQ(log.hi, 1e-2f);
  const auto px = [](const std::vector<std::uint8_t>& rgba, int i) {
    return vec3(rgba[4 * static_cast<std::size_t>(i)], rgba[4 * static_cast<std::size_t>(i) + 1],
                rgba[4 * static_cast<std::size_t>(i) + 2]) / 255.0f;
  };
  const auto near = [](vec3 a, vec3 b) { return glm::length(a - b) < 1.5f / 255.0f; };
  const auto lg = layer_rgba(l, Mapping::Log, 0.0f, log);
  EXPECT_TRUE(near(px(lg, 0), ramp_colour(0.0f)));
  EXPECT_TRUE(near(px(lg, 1), ramp_colour(0.5f)));  // 1e-4 is halfway between 1e-6 and 1e-2 in log
  EXPECT_TRUE(near(px(lg, 2), ramp_colour(1.0f)));
  EXPECT_TRUE(near(px(lg, 3), vec3(0.0f)));
  EXPECT_TRUE(near(px(lg, 4), vec3(1, 0, 1)));
  const auto ln = layer_rgba(l, Mapping::Linear, 0.0f, lin);
  EXPECT_TRUE(near(px(ln, 1), ramp_colour(0.01f)));
  EXPECT_TRUE(near(px(ln, 3), ramp_colour(0.0f)));
  EXPECT_FALSE(near(ramp_colour(0.0f), ramp_colour(0.5f)));
}

// A Cornell box whose light is so bright (3e38) that next-event estimates
// overflow: some samples are Inf or NaN.
std::filesystem::path write_nan_scene(const std::filesystem::path& dir, int res) {
  std::ifstream in(std::string(PATHLAB_SOURCE_DIR) + "/scenes/cornell-box.json");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // Radiance near FLT_MAX on the lamp and the white walls: a path that
  // gathers two such contributions overflows to infinity.
  text = std::regex_replace(text, std::regex(R"("radiance": \[17, 12, 4\])"), R"("radiance": [3.4e38, 3.4e38, 3.4e38])");
  text = std::regex_replace(text, std::regex(R"("white": \{ "type": "diffuse", "albedo": (\[[^\]]*\]) \})"),
                            R"("white": { "type": "diffuse", "albedo": $1, "emission": [3.4e38, 3.4e38, 3.4e38] })");
  text = std::regex_replace(text, std::regex(R"(\[512, 512\])"), "[" + std::to_string(res) + ", " + std::to_string(res) + "]");
  const auto file = dir / "nan-box.json";
  std::ofstream(file) << text;
  return file;
}

// Every NaN/Inf sample of the scene at `spp`, in the order next-NaN visits
// them (pixels in scanline order, samples in order), found by replaying
// every sample with the reference tracer.
std::vector<SampleRef> all_nonfinite(const std::filesystem::path& scene_file, int spp) {
  Scene scene = load_scene(scene_file);
  RenderSettings settings = scene.render;
  settings.spp = spp;  // as the render that found them
  const int w = scene.film.width, h = scene.film.height;
  const CompiledScene compiled(std::move(scene));
  const ReferenceTracer tracer(compiled, settings);
  std::vector<SampleRef> out;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int s = 0; s < spp; ++s)
        if (!is_finite(tracer.trace_sample(static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y),
                                           static_cast<std::uint32_t>(s), nullptr).L))
          out.push_back({static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y), static_cast<std::uint32_t>(s)});
  return out;
}

TEST_F(DebugGui, NextNonFiniteVisitsEveryNanSampleInScanlineOrder) {
  SessionSettings settings;
  settings.scene_file = write_nan_scene(dir_, 4).string();
  settings.spp = 64;
  Session session(settings);
  ASSERT_TRUE(session.wait_spp(64, 120.0));
  Snapshot snap;
  ASSERT_TRUE(session.snapshot(snap));
  const std::vector<SampleRef> want = all_nonfinite(settings.scene_file, 64);
  ASSERT_GT(want.size(), 1u) << "the scene should give NaN/Inf samples";
  bool two_in_a_pixel = false;  // so that the walk must go on within a pixel too
  for (std::size_t k = 1; k < want.size(); ++k) two_in_a_pixel |= want[k].x == want[k - 1].x && want[k].y == want[k - 1].y;
  ASSERT_TRUE(two_in_a_pixel);
  std::optional<SampleRef> at;
  for (std::size_t k = 0; k <= want.size(); ++k) {  // once round, and back to the first
    at = at ? session.next_nonfinite(snap, static_cast<int>(at->x), static_cast<int>(at->y), at->sample)
            : session.next_nonfinite(snap, -1, -1, std::nullopt);
    ASSERT_TRUE(at);
    const SampleRef& w = want[k % want.size()];
    EXPECT_TRUE(at->x == w.x && at->y == w.y && at->sample == w.sample)
        << k << ": got (" << at->x << ", " << at->y << ") sample " << at->sample << ", want (" << w.x << ", " << w.y
        << ") sample " << w.sample;
  }
  // A finite scene has none.
  Session clean(small_cornell(8, 2));
  ASSERT_TRUE(clean.wait_spp(2, 120.0));
  Snapshot c;
  ASSERT_TRUE(clean.snapshot(c));
  EXPECT_FALSE(clean.next_nonfinite(c, -1, -1, std::nullopt));
}

std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

int run_gui(const std::filesystem::path& dir, const std::string& args, const std::string& script_text, std::string* err) {
  const auto script = dir / "script.txt";
  std::ofstream(script) << script_text;
  const std::string command = std::string(PATHLAB_DEBUG_BINARY) + " " + args + " --script " + script.string() + " 2>" +
                              (dir / "err.txt").string();
  const int status = std::system(command.c_str());
  *err = command + "\n" + read_text(dir / "err.txt");
  return status;
}

// The channel values a readout line shows for `layer`: "layer: R a  G b  B c".
std::vector<double> readout_values(const std::string& text, const std::string& layer) {
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind(layer + ": ", 0) != 0) continue;
    std::istringstream in(line.substr(layer.size() + 2));
    std::vector<double> v;
    std::string name;
    double x = 0;
    while (in >> name >> x) v.push_back(x);
    return v;
  }
  return {};
}

std::string str(const vec3& v) {
  std::ostringstream o;
  o << "(" << v.x << ", " << v.y << ", " << v.z << ")";
  return o.str();
}

vec3 screen_at(const Image& shot, double x, double y) { return shot.at(static_cast<int>(x), static_cast<int>(y)); }

// As a person would: zoom with the wheel about a point, pan by dragging,
// point at a window position and read the buffer values there (checked
// against the saved film and AOVs at the pixel the zoom and pan put under
// it), switch variance to a log scale (checked against the ramp colour the
// range gives), then jump to the next NaN/Inf sample from the NaN view.
TEST_F(DebugGui, ZoomPanReadoutLogScaleAndNextNan) {
  const int res = 64, spp = 8;
  const auto scene = write_nan_scene(dir_, res);
  const auto exr = dir_ / "image.exr", logshot = dir_ / "log.png", nanshot = dir_ / "nan.png";
  // Wheel 4 notches in at (20, 20), then drag by (-50, -20): screen = origin + pixel * zoom.
  const double zoom = std::pow(1.25, 4), ox = 20.0 - 20.0 * zoom - 50.0, oy = 20.0 - 20.0 * zoom - 20.0;
  const int mx = 40, my = 40;
  const int px = static_cast<int>(std::floor((mx - ox) / zoom)), py = static_cast<int>(std::floor((my - oy) / zoom));
  // The Cornell box for the buffers, then the NaN scene for the jump.
  std::ostringstream script;
  script << "wait-spp " << spp << "\nwheel 20 20 4\ndrag 300 300 -50 -20\nmouse " << mx << " " << my
         << "\nview albedo\nreadout " << (dir_ / "albedo.txt").string() << "\nview variance\nscale log\nreadout "
         << (dir_ / "variance.txt").string() << "\nscreenshot " << logshot.string() << "\nsave " << exr.string()
         << "\nopen " << scene.string() << "\nwait-spp " << spp << "\nview nan\nnext-nan\nreadout "
         << (dir_ / "nan.txt").string() << "\nscreenshot " << nanshot.string() << "\nquit\n";
  std::string err;
  ASSERT_EQ(run_gui(dir_, "--resolution 64x64 --spp " + std::to_string(spp), script.str(), &err), 0) << err;

  const std::vector<Layer> saved = read_image_layers(exr);
  const Layer* albedo = find_layer(saved, "albedo");
  const Layer* variance = find_layer(saved, "variance");
  ASSERT_TRUE(albedo && variance && find_layer(saved, "nonfinite"));
  ASSERT_GE(px, 0);
  ASSERT_LT(px, res);
  ASSERT_GE(py, 0);
  ASSERT_LT(py, res);
  const std::string albedo_text = read_text(dir_ / "albedo.txt");
  EXPECT_NE(albedo_text.find("pixel (" + std::to_string(px) + ", " + std::to_string(py) + ")"), std::string::npos)
      << "the zoom and pan put another pixel under the mouse: " << albedo_text;
  for (const auto& [text, layer] : {std::pair(albedo_text, albedo), std::pair(read_text(dir_ / "variance.txt"), variance)}) {
    const std::vector<double> shown = readout_values(text, layer->name);
    ASSERT_EQ(shown.size(), 3u) << text;
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(shown[static_cast<std::size_t>(c)], layer->image.at(px, py)[c], 1e-6 * std::abs(layer->image.at(px, py)[c]))
          << layer->name << " channel " << c << "\n" << text;
  }

  // The log view of variance: the pixel under the mouse has the ramp colour of
  // its log value within the layer's positive range (computed here from the saved layer).
  double lo = INFINITY, hi = -INFINITY;
  for (const vec3& v : variance->image.pixels) {
    const double m = (static_cast<double>(v.x) + v.y + v.z) / 3.0;
    if (std::isfinite(m) && m > 0) lo = std::min(lo, m), hi = std::max(hi, m);
  }
  const vec3 v = variance->image.at(px, py);
  const double m = (static_cast<double>(v.x) + v.y + v.z) / 3.0;
  ASSERT_GT(m, 0.0);
  const vec3 want = ramp_colour(static_cast<float>((std::log10(m) - std::log10(lo)) / (std::log10(hi) - std::log10(lo))));
  const Image shot = read_image(logshot);
  EXPECT_LT(glm::length(screen_at(shot, mx, my) - want), 3.0f / 255.0f)
      << "log view colour at the mouse; linear would be " << str(ramp_colour(static_cast<float>((m - lo) / (hi - lo))));

  // Next NaN/Inf: the first NaN/Inf sample in scanline order, found by
  // replaying every sample here; the view is centred on it and its path drawn.
  const std::vector<SampleRef> bad = all_nonfinite(scene, spp);
  ASSERT_FALSE(bad.empty());
  const std::string nan_text = read_text(dir_ / "nan.txt");
  const std::string retraced = "retraced: pixel (" + std::to_string(bad[0].x) + ", " + std::to_string(bad[0].y) +
                               ") sample " + std::to_string(bad[0].sample);
  EXPECT_NE(nan_text.find(retraced), std::string::npos) << "want " << retraced << "\n" << nan_text;
  EXPECT_EQ(nan_text.find("NaN/Inf samples 0"), std::string::npos) << nan_text;
  const Image nan_shot = read_image(nanshot);
  const auto is = [](const vec3& c, const unsigned char (&k)[4]) {
    return std::abs(c.x - k[0] / 255.0f) < 0.1f && std::abs(c.y - k[1] / 255.0f) < 0.1f && std::abs(c.z - k[2] / 255.0f) < 0.1f;
  };
  // Zoomed in (at least 8x) and centred above the events window; the first
  // vertex of the retraced path lies on the pixel's camera ray. Where the pixel
  // is drawn comes from the readout's zoom and origin.
  double z = 0, ox2 = 0, oy2 = 0;
  {
    const auto at = nan_text.find("zoom ");
    ASSERT_NE(at, std::string::npos) << nan_text;
    std::istringstream in(nan_text.substr(at + 5));
    std::string word;
    in >> z >> word >> ox2 >> oy2;
  }
  EXPECT_GE(z, 8.0);
  const double cx = ox2 + (bad[0].x + 0.5) * z, cy = oy2 + (bad[0].y + 0.5) * z;
  EXPECT_NEAR(cx, 400.0, 1.0);
  EXPECT_NEAR(cy, 0.5 * 0.62 * 720.0, 1.0);
  bool vertex_at_centre = false;
  for (int dy = -3; dy <= 3; ++dy)
    for (int dx = -3; dx <= 3; ++dx)
      vertex_at_centre |= is(nan_shot.at(static_cast<int>(cx) + dx, static_cast<int>(cy) + dy), kVertexColour);
  EXPECT_TRUE(vertex_at_centre) << "the jump does not centre the NaN pixel with its path";
  int red = 0;
  for (int y = 0; y < 720; ++y)
    for (int x = 0; x < 800; ++x) red += nan_shot.at(x, y).x > 0.95f && nan_shot.at(x, y).y < 0.05f && nan_shot.at(x, y).z < 0.05f;
  EXPECT_GT(red, 0) << "no red NaN pixel in the NaN view";
}

// The split view: this render against an image file whose beauty is a flat
// grey and which has a layer the render lacks (a stage buffer), and against
// the other tracer; the divider dragged to a new place.
TEST_F(DebugGui, SplitViewComparesAnImageFileAndTheOtherTracer) {
  const int res = 64, spp = 4;
  const auto other = dir_ / "other.exr", exr = dir_ / "image.exr";
  std::vector<ExrChannel> channels;
  for (const char* c : {"R", "G", "B"}) channels.push_back({c, std::vector<float>(res * res, 0.5f)});
  ExrChannel stage{"stage_count.Y", std::vector<float>(res * res)};
  for (int y = 0; y < res; ++y)
    for (int x = 0; x < res; ++x) stage.values[static_cast<std::size_t>(y * res + x)] = static_cast<float>(x);
  channels.push_back(stage);
  write_exr_channels(other, res, res, channels, {});
  const auto a = dir_ / "file.png", b = dir_ / "stage.png", c = dir_ / "tracer.png";
  // Fit: zoom min(800, 720) / 64 = 11.25, the image from x = 40 to 760; the divider from 400 to 200.
  std::ostringstream script;
  script << "wait-spp " << spp << "\nfit\ncompare-image " << other.string() << "\ndrag 400 300 -200 0\nscreenshot "
         << a.string() << "\nview stage_count\nmouse 600 300\nreadout " << (dir_ / "stage.txt").string()
         << "\nscreenshot " << b.string() << "\nview beauty\ncompare tracer\nwait-spp " << spp << "\nscreenshot "
         << c.string() << "\nsave " << exr.string() << "\nquit\n";
  std::string err;
  ASSERT_EQ(run_gui(dir_, "--resolution 64x64 --spp " + std::to_string(spp), script.str(), &err), 0) << err;

  const std::vector<Layer> saved = read_image_layers(exr);
  const Layer* beauty = find_layer(saved, "beauty");
  ASSERT_NE(beauty, nullptr);
  const double zoom = 11.25, ox = 40.0;
  const auto tone = [&](double sx, double sy) {
    const vec3 v = beauty->image.at(static_cast<int>((sx - ox) / zoom), static_cast<int>(sy / zoom));
    return vec3(linear_to_srgb(v.x), linear_to_srgb(v.y), linear_to_srgb(v.z));
  };
  const auto near = [](vec3 p, vec3 q) { return glm::length(p - q) < 4.0f / 255.0f; };
  const Image file_shot = read_image(a);
  const vec3 white(1.0f), grey(linear_to_srgb(0.5f));
  EXPECT_TRUE(near(screen_at(file_shot, 200, 100), white)) << "no divider at x = 200 after the drag";
  EXPECT_FALSE(near(screen_at(file_shot, 400, 100), white)) << "the divider stayed at 400";
  int left = 0, right = 0, n = 0;
  for (double y = 100; y < 700; y += 50, ++n) {
    left += near(screen_at(file_shot, 120, y), tone(120, y));
    right += near(screen_at(file_shot, 600, y), grey);
  }
  EXPECT_EQ(right, n) << "the right side does not show the image file";
  EXPECT_GE(left, n - 2) << "the left side does not show the render: at (120, 300) " << str(screen_at(file_shot, 120, 300))
                         << ", want " << str(tone(120, 300));

  // The file's own layer: the right side on the ramp (x = pixel column, range 0..63), the left empty.
  const Image stage_shot = read_image(b);
  const double col = std::floor((600 - ox) / zoom);
  EXPECT_TRUE(near(screen_at(stage_shot, 600, 300), ramp_colour(static_cast<float>(col / 63.0))));
  EXPECT_TRUE(near(screen_at(stage_shot, 120, 300), vec3(0.1f, 0.1f, 0.12f)))
      << str(screen_at(stage_shot, 120, 300));
  const std::vector<double> shown = readout_values(read_text(dir_ / "stage.txt"), "other.exr stage_count");
  ASSERT_EQ(shown.size(), 1u) << read_text(dir_ / "stage.txt");
  EXPECT_EQ(shown[0], col);

  // The other tracer, same scene and seed: both sides show the same image.
  const Image tracer_shot = read_image(c);
  int same = 0;
  n = 0;
  for (double y = 100; y < 700; y += 50)
    for (double x : {120.0, 600.0}) same += near(screen_at(tracer_shot, x, y), tone(x, y)), ++n;
  EXPECT_GE(same, n - 2) << "reference | wavefront split does not show the render on both sides: at (600, 300) "
                         << str(screen_at(tracer_shot, 600, 300)) << ", want " << str(tone(600, 300));
}

TEST_F(DebugGui, AFailingScriptCommandNamesItsLineAndExitsWithTwo) {
  const auto script = dir_ / "bad.txt";
  std::ofstream(script) << "wait-spp 1\nexport-vtk " << (dir_ / "x.vtp").string() << "\n";  // nothing clicked yet
  const std::string command = std::string(PATHLAB_DEBUG_BINARY) + " --resolution 16x16 --spp 1 --script " +
                              script.string() + " 2>" + (dir_ / "err.txt").string();
  const int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 2);
  std::ifstream err_file(dir_ / "err.txt");
  const std::string err((std::istreambuf_iterator<char>(err_file)), std::istreambuf_iterator<char>());
  EXPECT_NE(err.find("bad.txt:2"), std::string::npos) << err;
  EXPECT_NE(err.find("click a pixel first"), std::string::npos) << err;
}

}  // namespace
}  // namespace pathlab::debug
