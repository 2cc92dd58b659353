// Input the documentation allows that used to crash or hang pathlab (issue
// 22, section 3): Embree's limits, non-finite options, sizes, leftover
// temporary files, and messages that echoed input whole. Whatever may abort,
// hang or run out of memory runs as the real binary in a child process with
// a time limit, so that a regression fails the test instead of killing or
// stalling the test runner.
#include "tests/cli_util.h"
#include "tests/temp_dir.h"

#include "apps/cli/interrupt.h"
#include "core/embree_accel.h"
#include "core/messages.h"
#include "core/scene.h"
#include "core/scene_limits.h"
#include "core/temp_files.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace pathlab {
namespace {

namespace fs = std::filesystem;
using test::run_cli;

struct ProcessResult {
  int code = -1;  // the exit status, 128 + the signal that ended it, or -1 if it had to be killed
  std::string err;
};

// Runs the pathlab binary with `args` (and `env` added to the environment),
// its stderr captured; kills it after `limit` (a hang).
ProcessResult run_pathlab(const std::vector<std::string>& args, const std::vector<std::string>& env = {},
                          std::chrono::seconds limit = std::chrono::seconds(120)) {
  const fs::path err_file = fs::temp_directory_path() / ("pathlab-hardening-err-" + std::to_string(::getpid()));
  // PATHLAB_TEST_BINARY runs these against another build (an old one, to
  // see the failures they catch).
  const char* const override_binary = std::getenv("PATHLAB_TEST_BINARY");
  const std::string binary = override_binary != nullptr ? override_binary : PATHLAB_BINARY;
  const pid_t pid = ::fork();
  if (pid == 0) {
    std::FILE* f = std::freopen(err_file.c_str(), "w", stderr);
    if (f == nullptr) ::_exit(126);
    for (const std::string& e : env) ::putenv(const_cast<char*>(e.c_str()));
    std::vector<char*> argv{const_cast<char*>(binary.c_str())};
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(binary.c_str(), argv.data());
    ::_exit(127);
  }
  ProcessResult r;
  const auto deadline = std::chrono::steady_clock::now() + limit;
  int status = 0;
  while (true) {
    if (::waitpid(pid, &status, WNOHANG) == pid) {
      r.code = WIFSIGNALED(status) ? 128 + WTERMSIG(status) : WEXITSTATUS(status);
      break;
    }
    if (std::chrono::steady_clock::now() > deadline) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      ADD_FAILURE() << "pathlab did not finish within " << limit.count() << " s (a hang)";
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  std::ifstream in(err_file);
  std::ostringstream text;
  text << in.rdbuf();
  r.err = text.str();
  fs::remove(err_file);
  return r;
}

std::size_t count(std::string_view text, std::string_view needle) {
  std::size_t n = 0;
  for (std::size_t at = text.find(needle); at != std::string_view::npos; at = text.find(needle, at + 1)) ++n;
  return n;
}

// Exit code 2, one error line (no crash, no "out of memory") holding every one of `words`.
void expect_clean_rejection(int code, const std::string& err, std::initializer_list<std::string_view> words) {
  EXPECT_EQ(code, 2) << err;
  EXPECT_EQ(count(err, "pathlab: error:"), 1u) << err;
  const std::size_t at = err.find("pathlab: error:");
  const std::string line = at == std::string::npos ? err : err.substr(at, err.find('\n', at) - at);
  for (const std::string_view w : words) EXPECT_NE(line.find(w), std::string::npos) << "'" << w << "' not in: " << err;
}

std::string scene_text(const std::string& camera, const std::string& shapes) {
  return "{\n"
         "  \"pathlab_scene\": 1,\n"
         "  \"camera\": " + camera + ",\n"
         "  \"materials\": {\"white\": {\"type\": \"diffuse\", \"albedo\": 0.5},\n"
         "                \"lamp\": {\"type\": \"emissive\", \"radiance\": 2}},\n"
         "  \"shapes\": [\n" + shapes + "\n  ]\n}\n";
}
const std::string kCamera = "{\"position\": [0, 0, 4], \"look_at\": [0, 0, 0]}";
const std::string kLamp = "    {\"type\": \"rectangle\", \"material\": \"lamp\", \"transform\": {\"translate\": [0, 0, -2]}}";
const std::string kSphere = "    {\"type\": \"sphere\", \"material\": \"white\", \"radius\": 0.5}";
std::string mesh_shape(const std::string& file) {
  return "    {\"type\": \"mesh\", \"file\": \"" + file + "\", \"material\": \"white\"},\n" + kLamp;
}

class Hardening : public test::TempDirTest {
 protected:
  std::string file(const std::string& name, const std::string& bytes) { return write(name, bytes).string(); }
  std::string exr() const { return (dir_ / "x.exr").string(); }
  ProcessResult render(const std::string& scene, const std::vector<std::string>& env = {},
                       const std::vector<std::string>& extra = {}) {
    std::vector<std::string> args{"render", scene, "-o", exr(), "--spp", "1", "--resolution", "8x8", "--quiet"};
    args.insert(args.end(), extra.begin(), extra.end());
    return run_pathlab(args, env);
  }
  // The sphere and lamp scene with the lamp's radiance `radiance`, rendered.
  ProcessResult render_with_lamp(const std::string& name, const std::string& radiance) {
    std::string text = scene_text(kCamera, kSphere + ",\n" + kLamp);
    const std::string from = "\"radiance\": 2";
    text.replace(text.find(from), from.size(), "\"radiance\": " + radiance);
    return render(file(name, text));
  }
  // No image, no temporary file: only what the test wrote.
  void expect_no_output() const {
    for (const fs::directory_entry& e : fs::directory_iterator(dir_)) {
      const std::string name = e.path().filename().string();
      EXPECT_EQ(name.find(".tmp-"), std::string::npos) << "left behind: " << name;
      EXPECT_NE(name, "x.exr");
      EXPECT_NE(name, "x.png");
    }
  }
};

// ------------------------------------------------------------ 1. Embree's limits

// Each used to abort inside Embree (SIGABRT, "ray.valid()"); now the scene
// is refused at load with the key that breaks the rule.
TEST_F(Hardening, PositionsBeyondEmbreesRangeAreRefusedAtLoad) {
  const auto refused = [&](const std::string& name, const std::string& text,
                           std::initializer_list<std::string_view> words) {
    SCOPED_TRACE(name);
    const ProcessResult r = render(file(name, text));
    expect_clean_rejection(r.code, r.err, words);
    expect_no_output();
  };
  refused("far-camera.json", scene_text("{\"position\": [0, 0, 1e19], \"look_at\": [0, 0, 0]}", kSphere + ",\n" + kLamp),
          {"far-camera.json:3:", "/camera/position", "beyond the scene coordinate limit 1e16"});
  refused("aperture.json",
          scene_text("{\"position\": [0, 0, 4], \"look_at\": [0, 0, 0], \"aperture_radius\": 1e20}", kSphere + ",\n" + kLamp),
          {"aperture.json:3:", "/camera/aperture_radius", "the aperture reaches beyond"});
  refused("focus.json",
          scene_text("{\"position\": [0, 0, 4], \"look_at\": [0, 0, 0], \"aperture_radius\": 0.1, \"focus_distance\": 1e30}",
                     kSphere + ",\n" + kLamp),
          {"focus.json:3:", "/camera/focus_distance", "exceeds the scene coordinate limit"});
  // Without focus_distance, it is the distance to look_at: look_at is what to
  // change (this once blamed the absent focus_distance).
  refused("look-at.json", scene_text("{\"position\": [0, 0, 4], \"look_at\": [1e16, 0, -1e16]}", kSphere + ",\n" + kLamp),
          {"look-at.json:3:", "/camera/look_at: look_at lies 1.414214e+16 from position, and focus_distance (not given)",
           "move look_at nearer, or give focus_distance"});
  refused("denormal.json",
          scene_text(kCamera, "    {\"type\": \"sphere\", \"material\": \"white\", \"radius\": 1e-45},\n" + kLamp),
          {"denormal.json:7:", "/shapes/0/radius", "radius must lie in [1e-18, 1e16]"});
  refused("scaled.json",
          scene_text(kCamera, "    {\"type\": \"rectangle\", \"material\": \"white\", \"transform\": {\"scale\": 1e30}},\n" + kLamp),
          {"scaled.json:7:", "/shapes/0/transform", "the transform moves vertices beyond the scene coordinate limit"});
  file("far.obj", "v 0 0 0\nv 1e30 0 0\nv 0 1 0\nf 1 2 3\n");
  refused("far-vertex.json", scene_text(kCamera, mesh_shape("far.obj")),
          {"far-vertex.json:7:", "/shapes/0", "a vertex lies beyond the scene coordinate limit"});
  refused("far-sphere.json",
          scene_text(kCamera, "    {\"type\": \"sphere\", \"material\": \"white\", \"center\": [2e16, 0, 0]},\n" + kLamp),
          {"far-sphere.json:7:", "/shapes/0", "the sphere reaches beyond the scene coordinate limit"});
}

// Just inside the rule still renders (1e15 is allowed).
TEST_F(Hardening, PositionsWithinTheRuleRender) {
  const std::string text =
      scene_text("{\"position\": [0, 0, 1e15], \"look_at\": [0, 0, 0], \"aperture_radius\": 1e14}", kSphere + ",\n" + kLamp);
  const ProcessResult r = render(file("far-ok.json", text));
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::is_regular_file(dir_ / "x.exr"));
  // A look_at beyond 1e16 from position, with focus_distance given.
  const std::string focused = scene_text(
      "{\"position\": [0, 0, 4], \"look_at\": [1e16, 0, -1e16], \"focus_distance\": 4}", kSphere + ",\n" + kLamp);
  const ProcessResult f = render(file("focused.json", focused));
  EXPECT_EQ(f.code, 0) << f.err;
}

// A scene lit only by emitters far below the film's fixed-point resolution
// (2^-65 per sample) says so: a lamp of 1e-18 once rendered 28 % dark and one
// of 1e-20 black, without a word. A lamp of 1e-12 does not warn.
TEST_F(Hardening, EmittersTooFaintForTheFilmAreWarnedAbout) {
  for (const char* faint : {"1e-18", "1e-20"}) {
    const ProcessResult r = render_with_lamp(std::string("faint") + faint + ".json", faint);
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("pathlab: warning: the brightest emitter's radiance is " + std::string(faint)), std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("choose a smaller unit of radiance"), std::string::npos) << r.err;
  }
  const ProcessResult dim = render_with_lamp("dim.json", "1e-12");
  EXPECT_EQ(dim.code, 0) << dim.err;
  EXPECT_EQ(dim.err.find("brightest emitter"), std::string::npos) << dim.err;
}

// An emitter at or beyond the film's range (2^32) is named up front: every
// sample that sees it would be left out as bad, the lamp black in the image.
// A lamp of 1e9 (within range) does not warn.
TEST_F(Hardening, EmittersBeyondTheFilmsRangeAreWarnedAbout) {
  for (const char* bright : {"4294967296", "1e30"}) {
    const ProcessResult r = render_with_lamp(std::string("bright") + bright + ".json", bright);
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("pathlab: warning: material 'lamp' emits radiance "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("choose a larger unit of radiance"), std::string::npos) << r.err;
  }
  const ProcessResult within = render_with_lamp("within.json", "1e9");
  EXPECT_EQ(within.code, 0) << within.err;
  EXPECT_EQ(within.err.find("beyond the film's range"), std::string::npos) << within.err;
}

// The bound counts only emitters in the image: a group's lamp no instance
// places neither hides a faint scene nor raises a false alarm; other lights
// cannot be bounded.
TEST(HardeningFaintEmitters, ThePeakCountsOnlyPlacedConstantEmitters) {
  Scene scene;
  Material lamp;
  lamp.type = MaterialType::Emissive;
  lamp.emission = Spectrum(1e-18f);
  Material bright = lamp;
  bright.emission = Spectrum(2.0f);
  scene.materials = {lamp, bright};
  Shape faint_lamp, grouped_lamp;
  faint_lamp.material = 0;
  grouped_lamp.material = 1;
  grouped_lamp.in_group = true;
  scene.shapes = {faint_lamp, grouped_lamp};
  scene.groups = {ShapeGroup{"g", {1}}};
  ASSERT_TRUE(constant_emitters_peak(scene));
  EXPECT_EQ(*constant_emitters_peak(scene), 1e-18f);
  scene.instances = {Instance{0, mat4(1.0f), "instances[0]"}};
  EXPECT_EQ(*constant_emitters_peak(scene), 2.0f);
  scene.delta_lights.push_back(DeltaLight{});
  EXPECT_FALSE(constant_emitters_peak(scene));
  // The brightest constant emitter stays known beside other lights (a lower
  // bound of the brightest sample, which is all the bright warning needs).
  scene.materials[1].name = "bright";
  ASSERT_TRUE(brightest_constant_emitter(scene));
  EXPECT_EQ(brightest_constant_emitter(scene)->radiance, 2.0f);
  EXPECT_EQ(brightest_constant_emitter(scene)->source, "material 'bright'");
}

// A ray Embree would abort on never reaches it, through any of the accel's
// entry points and batch modes: run in a child, so that a regression shows as
// the child's SIGABRT rather than the end of this test program.
TEST(HardeningAccel, RaysEmbreeRejectsNeverReachIt) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    Shape sphere;
    sphere.kind = Shape::Kind::Sphere;
    sphere.center = vec3(0.0f, 0.0f, 0.0f);
    sphere.radius = 1.0f;
    sphere.description = "sphere";
    const std::vector<Shape> shapes{sphere};
    const EmbreeAccel accel(shapes);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const Ray good{vec3(0.0f, 0.0f, 5.0f), vec3(0.0f, 0.0f, -1.0f)};
    const std::vector<Ray> bad_rays{
        {vec3(0.0f, 0.0f, 1e19f), vec3(0.0f, 0.0f, -1.0f)},  // beyond 1.844e18
        {vec3(nan, 0.0f, 5.0f), vec3(0.0f, 0.0f, -1.0f)},
        {vec3(0.0f, 0.0f, 5.0f), vec3(0.0f, nan, -1.0f)},
        {vec3(0.0f, 0.0f, 5.0f), vec3(0.0f, 0.0f, -1.0f), nan},
    };
    int failures = 0;
    const std::uint64_t before = embree_rejected_rays();
    for (const Ray& bad : bad_rays) {
      RayHit hit;
      if (accel.intersect(bad, &hit) || !std::isnan(hit.t)) ++failures;
      if (!accel.occluded(bad)) ++failures;
    }
    // Batches of 20 with the bad rays among good ones, in every mode.
    std::vector<Ray> batch(20, good);
    for (std::size_t i = 0; i < bad_rays.size(); ++i) batch[3 + 4 * i] = bad_rays[i];
    std::vector<float> ox, oy, oz, dx, dy, dz, tmax;
    for (const Ray& r : batch) {
      ox.push_back(r.origin.x), oy.push_back(r.origin.y), oz.push_back(r.origin.z);
      dx.push_back(r.dir.x), dy.push_back(r.dir.y), dz.push_back(r.dir.z), tmax.push_back(r.tmax);
    }
    const RayArrays arrays{ox.data(), oy.data(), oz.data(), dx.data(), dy.data(), dz.data(), tmax.data()};
    for (const RayBatchMode mode : kAllRayBatchModes) {
      std::vector<RayHit> hits(batch.size());
      std::vector<std::uint8_t> found(batch.size()), occluded(batch.size());
      accel.intersect_batch(batch, hits, found, mode);
      accel.occluded_batch(batch, occluded, mode);
      std::vector<float> t(batch.size()), u(batch.size()), v(batch.size());
      std::vector<std::uint32_t> shape(batch.size()), prim(batch.size());
      std::vector<std::uint8_t> found_a(batch.size()), occluded_a(batch.size());
      accel.intersect_arrays(arrays, batch.size(), {t.data(), u.data(), v.data(), shape.data(), prim.data(), found_a.data()}, mode);
      accel.occluded_arrays(arrays, batch.size(), occluded_a.data(), mode);
      for (std::size_t i = 0; i < batch.size(); ++i) {
        const bool is_bad = i % 4 == 3 && i < 3 + 4 * bad_rays.size();
        if (is_bad) {
          failures += found[i] != 0 || !std::isnan(hits[i].t) || occluded[i] != 1;
          failures += found_a[i] != 0 || !std::isnan(t[i]) || occluded_a[i] != 1;
        } else {  // the good rays are answered as ever: the sphere at t = 4
          failures += found[i] != 1 || std::abs(hits[i].t - 4.0f) > 1e-4f || occluded[i] != 1;
          failures += found_a[i] != 1 || std::abs(t[i] - 4.0f) > 1e-4f || occluded_a[i] != 1;
        }
      }
    }
    // 4 rays x 2 queries, then 4 bad rays x 4 queries x 3 modes.
    if (embree_rejected_rays() - before != 4 * 2 + 4 * 4 * 3) ++failures;
    ::_exit(failures == 0 ? 0 : 1);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_FALSE(WIFSIGNALED(status)) << "the child died of signal " << WTERMSIG(status) << " (Embree's assertion?)";
  EXPECT_EQ(WEXITSTATUS(status), 0) << "a rejected ray was answered wrongly, or a good one";
}

TEST(HardeningAccel, EmbreeAcceptsMatchesEmbreesRule) {
  EXPECT_TRUE(embree_accepts(vec3(1.8e18f), vec3(1.0f), kInfinity));
  EXPECT_FALSE(embree_accepts(vec3(0.0f, 1.9e18f, 0.0f), vec3(1.0f), 1.0f));
  EXPECT_FALSE(embree_accepts(vec3(0.0f), vec3(0.0f, 0.0f, -kInfinity), 1.0f));
  EXPECT_FALSE(embree_accepts(vec3(0.0f), vec3(1.0f), std::numeric_limits<float>::quiet_NaN()));
  // The scene rule leaves room: a point at the limit plus a unit direction.
  EXPECT_TRUE(within_scene_range(vec3(kMaxSceneCoordinate)));
  EXPECT_FALSE(within_scene_range(vec3(std::numeric_limits<float>::quiet_NaN())));
  EXPECT_LT(kMaxSceneCoordinate * 100.0f, kEmbreeLargest * 1.01f);
}

// ------------------------------------------------------------ 2. non-finite options

// Every floating-point option of every subcommand, found in the help text
// (CLI11 prints FLOAT after it), refuses nan and inf by name: nothing renders
// for ever and no black PNG is written.
TEST_F(Hardening, EveryFloatOptionOfEverySubcommandMustBeFinite) {
  std::size_t checked = 0;
  for (const std::string sub : {"render", "merge", "check", "diff", "trace-pixel", "converge"}) {
    const auto help = run_cli({sub, "--help"});
    ASSERT_EQ(help.code, 0) << sub;
    std::istringstream lines(help.out);
    for (std::string line; std::getline(lines, line);) {
      const std::size_t dash = line.find("--");
      if (dash == std::string::npos || line.find(" FLOAT") == std::string::npos) continue;
      const std::string option = line.substr(dash, line.find_first_of(" ,", dash) - dash);
      for (const std::string value : {"nan", "inf", "-inf", "1e39"}) {
        SCOPED_TRACE(sub + " " + option + " " + value);
        // The output goes under dir_: a run that got through would leave files there.
        std::vector<std::string> args{sub, option, value};
        // A regression would render: briefly, into dir_ (and fail below).
        if (sub == "render") args.insert(args.end(), {"--spp", "1", "--resolution", "8x8"});
        if (sub == "render" || sub == "merge") args.insert(args.end(), {"-o", exr()});
        const auto r = run_cli(args);
        EXPECT_EQ(r.code, 2) << r.err;
        EXPECT_NE(r.err.find(option), std::string::npos) << r.err;
        EXPECT_TRUE(r.err.find("finite") != std::string::npos || r.err.find("too large") != std::string::npos ||
                    r.err.find("not in [") != std::string::npos)
            << r.err;
      }
      ++checked;
    }
  }
  // --clamp --min-pdf --texture-cache-mb (x3), --exposure (x2), --time,
  // --target-relmse, --checkpoint-every, --alpha, --tolerance, --target-rmse ...
  EXPECT_GE(checked, 15u);
  expect_no_output();
}

TEST_F(Hardening, TheCasesOfTheIssue) {
  for (const std::vector<std::string>& args : std::vector<std::vector<std::string>>{
           {"render", "--time", "nan"}, {"render", "--target-relmse", "nan"}, {"render", "--exposure", "nan"},
           {"render", "--exposure", "inf"}, {"merge", "a.pfilm", "-o", "m.exr", "--exposure", "nan"}}) {
    std::vector<std::string> with_out = args;
    if (args[0] == "render") with_out.insert(with_out.end(), {"-o", exr(), "--spp", "1", "--resolution", "8x8"});
    const auto r = run_cli(with_out);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find(args[args.size() - 2] + ": "), std::string::npos) << r.err;
  }
  expect_no_output();
}

// Range errors print their bounds %g-style, not CLI11's 39 digits.
TEST(HardeningMessages, RangeErrorsPrintShortNumbers) {
  const auto r = run_cli({"render", "--clamp", "-1"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--clamp: the value '-1' is not in [0, 3.4e+38]"), std::string::npos) << r.err;
  const auto a = run_cli({"check", "--alpha", "0.9"});
  EXPECT_NE(a.err.find("not in [1e-12, 0.5]"), std::string::npos) << a.err;
  EXPECT_EQ(format_number(1e308), "1e+308");
  EXPECT_EQ(format_number(0.25), "0.25");
}

// ------------------------------------------------------------ 3. sizes and special files

TEST_F(Hardening, SpecialFilesAreRefusedByName) {
  const auto expect_refused = [&](const std::string& name, const std::string& text,
                                  std::initializer_list<std::string_view> words) {
    SCOPED_TRACE(name);
    const ProcessResult r = render(file(name, text));
    expect_clean_rejection(r.code, r.err, words);
    expect_no_output();
  };
  ASSERT_EQ(::symlink("/dev/zero", (dir_ / "zero.ply").c_str()), 0);
  expect_refused("zero-link.json", scene_text(kCamera, mesh_shape("zero.ply")),
                 {"zero-link.json:7:", "zero.ply", "must be a regular file, not a character device"});
  ASSERT_EQ(::mkfifo((dir_ / "fifo.obj").c_str(), 0600), 0);
  expect_refused("fifo.json", scene_text(kCamera, mesh_shape("fifo.obj")),
                 {"fifo.json:7:", "fifo.obj", "must be a regular file, not a FIFO"});
  fs::create_directory(dir_ / "folder.ply");
  expect_refused("folder.json", scene_text(kCamera, mesh_shape("folder.ply")),
                 {"folder.json:7:", "folder.ply", "must be a regular file, not a folder"});
  expect_refused("zero-texture.json",
                 "{\"pathlab_scene\": 1, \"camera\": " + kCamera +
                     ", \"materials\": {\"t\": {\"type\": \"diffuse\", \"albedo\": {\"texture\": \"/dev/zero\"}},"
                     " \"lamp\": {\"type\": \"emissive\", \"radiance\": 1}},"
                     " \"shapes\": [{\"type\": \"rectangle\", \"material\": \"t\"}]}",
                 {"zero-texture.json:1:", "/dev/zero", "must be a regular file, not a character device"});
  const ProcessResult scene = run_pathlab({"render", "/dev/zero", "-o", exr()});
  expect_clean_rejection(scene.code, scene.err, {"/dev/zero: cannot read scene: it is a character device"});
}

// A gzip bomb: 64 MB of zeros in a few kB, under a 16 MB limit. The
// message names the file and the limit, and how to raise it.
TEST_F(Hardening, GzipBombIsStoppedWhileInflating) {
  const fs::path bomb = dir_ / "bomb.ply.gz";
  {
    gzFile gz = gzopen(bomb.c_str(), "wb9");
    ASSERT_NE(gz, nullptr);
    const std::string header = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n";
    gzwrite(gz, header.data(), static_cast<unsigned>(header.size()));
    const std::vector<char> zeros(1 << 20, '0');
    for (int i = 0; i < 64; ++i) gzwrite(gz, zeros.data(), static_cast<unsigned>(zeros.size()));
    gzclose(gz);
  }
  ASSERT_LT(fs::file_size(bomb), 1u << 20);
  const ProcessResult r = render(file("bomb.json", scene_text(kCamera, mesh_shape("bomb.ply.gz"))), {"PATHLAB_MAX_MEMORY_MB=16"});
  expect_clean_rejection(r.code, r.err, {"bomb.json:7:", "bomb.ply.gz", "decompresses to more than 16 MB", "PATHLAB_MAX_MEMORY_MB"});
  expect_no_output();
  // The same file under a raised limit gets as far as its content.
  const ProcessResult raised =
      render(file("bomb2.json", scene_text(kCamera, mesh_shape("bomb.ply.gz"))), {"PATHLAB_MAX_MEMORY_MB=256"});
  EXPECT_EQ(raised.code, 2);
  EXPECT_EQ(raised.err.find("decompresses"), std::string::npos) << raised.err;
}

TEST_F(Hardening, MeshFileAboveTheLimitAndBadLimit) {
  file("big.obj", std::string(3 << 20, '#'));
  const ProcessResult r = render(file("big.json", scene_text(kCamera, mesh_shape("big.obj"))), {"PATHLAB_MAX_MEMORY_MB=2"});
  expect_clean_rejection(r.code, r.err, {"big.json:7:", "big.obj", "the file has 3 MB", "the limit is 2 MB"});
  const ProcessResult bad = render(file("ok.json", scene_text(kCamera, kSphere + ",\n" + kLamp)), {"PATHLAB_MAX_MEMORY_MB=lots"});
  expect_clean_rejection(bad.code, bad.err, {"PATHLAB_MAX_MEMORY_MB='lots'", "whole number"});
  expect_no_output();
}

// The memory estimate counts what `--aov bounces` keeps per pixel (about
// 1.7 kB: every layer's sums and images), not the 64 bytes of another AOV:
// at 1024^2 it needs about 1.8 GB, which a 1000 MB limit refuses (it used to
// estimate 135 MB and allocate 1.7 GB).
TEST_F(Hardening, BouncesAovCountsItsLayersAgainstTheLimit) {
  const std::string scene = file("ok.json", scene_text(kCamera, kSphere + ",\n" + kLamp));
  const ProcessResult r = run_pathlab({"render", scene, "-o", exr(), "--spp", "1", "--resolution", "1024x1024", "--aov",
                                       "bounces", "--quiet"},
                                      {"PATHLAB_MAX_MEMORY_MB=1000"});
  expect_clean_rejection(r.code, r.err, {"1024x1024 film with 1 AOV(s) needs", "the limit is 1000 MB"});
  expect_no_output();
}

TEST_F(Hardening, PlyElementCountsBeyondTheBody) {
  file("count.ply",
       "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\n"
       "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n" +
           std::string(64, '\0'));
  const ProcessResult r = render(file("count.json", scene_text(kCamera, mesh_shape("count.ply"))));
  expect_clean_rejection(r.code, r.err, {"count.ply", "the header declares 4000000000 vertices, more than the 64 bytes"});
}

// A 65536^2 film (the documented maximum) is refused before anything is
// allocated, and its output folder is never made.
TEST_F(Hardening, HugeFilmIsRefusedBeforeTheFolderIsMade) {
  const std::string out = (dir_ / "new" / "folder" / "x.exr").string();
  const ProcessResult r = run_pathlab({"render", file("ok.json", scene_text(kCamera, kSphere + ",\n" + kLamp)), "-o",
                                       out, "--resolution", "65536x65536", "--aov", "albedo,normal"},
                                      {"PATHLAB_MAX_MEMORY_MB=65536"});
  expect_clean_rejection(r.code, r.err, {"the 65536x65536 film with 2 AOV(s) needs", "the limit is 65536 MB"});
  EXPECT_FALSE(fs::exists(dir_ / "new"));
  // A good render still makes the folder when it writes.
  const ProcessResult good = run_pathlab({"render", (dir_ / "ok.json").string(), "-o", out, "--spp", "1", "--resolution", "8x8", "--quiet"});
  EXPECT_EQ(good.code, 0) << good.err;
  EXPECT_TRUE(fs::is_regular_file(out));
}

// ------------------------------------------------------------ 4. temporary files

// The signal path itself, in a child: a registered temporary file is removed
// by SIGTERM outside a guard, and by the second SIGTERM inside one.
TEST_F(Hardening, SignalsRemoveRegisteredTemporaryFiles) {
  for (const bool guarded : {false, true}) {
    SCOPED_TRACE(guarded ? "inside an InterruptGuard" : "outside");
    const fs::path temp = dir_ / ".x.tmp-1-0.exr";
    const fs::path kept = dir_ / "kept.exr";
    std::ofstream(temp) << "half an image";
    std::ofstream(kept) << "not registered";
    const pid_t pid = ::fork();
    if (pid == 0) {
      cli::remove_temp_files_on_signals();
      const TempFileRegistration registered(temp);
      if (guarded) {
        const cli::InterruptGuard guard;
        std::raise(SIGTERM);  // recorded only
        if (!fs::exists(temp)) ::_exit(3);
        std::raise(SIGTERM);
      } else {
        std::raise(SIGTERM);
      }
      ::_exit(4);  // not reached: the signal ends the process
    }
    int status = 0;
    ::waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status)) << "exit " << WEXITSTATUS(status);
    EXPECT_EQ(WTERMSIG(status), SIGTERM);
    EXPECT_FALSE(fs::exists(temp)) << "the signal left the temporary file";
    EXPECT_TRUE(fs::exists(kept));
    fs::remove(kept);
  }
}

// What a kill -9 left (a temporary file of a process that no longer runs) is
// removed by the next write of the same file; a live process's is not.
TEST_F(Hardening, StaleTemporaryFilesOfDeadProcessesAreRemoved) {
  const pid_t dead = ::fork();
  if (dead == 0) ::_exit(0);
  ::waitpid(dead, nullptr, 0);
  const std::string d = std::to_string(dead);
  const std::string live = std::to_string(::getppid());
  for (const std::string& name : {".x.tmp-" + d + "-0.exr", ".x.tmp-" + d + "-7.png", ".x.tmp-" + live + "-0.exr",
                                  "part.pfilm.tmp-" + d, ".other.tmp-" + d + "-0.exr"})
    std::ofstream(dir_ / name) << "left by a killed writer";
  const std::string scene = file("ok.json", scene_text(kCamera, kSphere + ",\n" + kLamp));
  const ProcessResult r = run_pathlab({"render", scene, "-o", exr(), "--spp", "1", "--resolution", "8x8", "--quiet"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / (".x.tmp-" + d + "-0.exr")));
  EXPECT_FALSE(fs::exists(dir_ / (".x.tmp-" + d + "-7.png")));
  EXPECT_TRUE(fs::exists(dir_ / (".x.tmp-" + live + "-0.exr"))) << "a live process's file was removed";
  EXPECT_TRUE(fs::exists(dir_ / (".other.tmp-" + d + "-0.exr"))) << "another file's temporary was removed";
  const ProcessResult p = run_pathlab({"render", scene, "-o", (dir_ / "part.pfilm").string(), "--spp", "1",
                                       "--resolution", "8x8", "--passes", "0..1", "--quiet"});
  ASSERT_EQ(p.code, 0) << p.err;
  EXPECT_FALSE(fs::exists(dir_ / ("part.pfilm.tmp-" + d)));
}

// ------------------------------------------------------------ 5. messages

TEST(HardeningMessages, UnknownCommandIsNamedWithTheNearest) {
  const auto r = run_cli({"rendr", "scene.json"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("pathlab: error: unknown command 'rendr' (did you mean 'render'?)"), std::string::npos) << r.err;
  const auto far = run_cli({"xyzzy"});
  EXPECT_EQ(far.code, 2);
  EXPECT_NE(far.err.find("unknown command 'xyzzy' (the commands: render, merge, check, diff, trace-pixel, converge, compare)"),
            std::string::npos)
      << far.err;
}

TEST_F(Hardening, AHugeUnknownKeyIsCutInTheMessage) {
  const std::string key(5 << 20, 'k');
  const std::string text = scene_text(kCamera, "    {\"type\": \"sphere\", \"material\": \"white\", \"" + key + "\": 1},\n" + kLamp);
  const auto r = run_cli({"render", file("key.json", text), "-o", exr()});
  EXPECT_EQ(r.code, 2);
  EXPECT_LT(r.err.size(), 600u) << r.err.substr(0, 600);
  EXPECT_NE(r.err.find("key.json:7:"), std::string::npos) << r.err.substr(0, 600);
  EXPECT_NE(r.err.find("unknown key '" + key.substr(0, 60) + "...' (" + std::to_string(key.size()) + " bytes)"),
            std::string::npos)
      << r.err.substr(0, 600);
  EXPECT_EQ(quote_input("a\nb"), "'a?b'");
}

TEST_F(Hardening, ObjFaceIndicesAreReportedAsWritten) {
  const auto expect_obj = [&](const std::string& name, const std::string& obj, std::initializer_list<std::string_view> words) {
    SCOPED_TRACE(name);
    file(name + ".obj", obj);
    const auto r = run_cli({"render", file(name + ".json", scene_text(kCamera, mesh_shape(name + ".obj"))), "-o", exr()});
    expect_clean_rejection(r.code, r.err, words);
  };
  const std::string square = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";
  expect_obj("letters", square + "f a b c\n",
             {"letters.obj:5:", "face token 'a'", "vertex index 'a' is not a non-zero integer", "(valid: 1..4 or -4..-1)"});
  expect_obj("back", square + "f 1 2 -100\n",
             {"back.obj:5:", "face token '-100'", "vertex index -100 counts back past the 4 vertex(s)", "-4..-1"});
  expect_obj("beyond", square + "f 1 2 9\n", {"beyond.obj:5:", "face token '9'", "vertex index 9 is beyond the 4"});
  expect_obj("normal", square + "vn 0 0 1\nf 1//1 2//2 3//1\n",
             {"normal.obj:6:", "face token '2//2'", "normal index 2 is beyond the 1 normal(s)"});
  expect_obj("zero", square + "f 0 1 2\n", {"zero.obj:5:", "face token '0'", "vertex index '0' is not a non-zero integer"});
}

}  // namespace
}  // namespace pathlab
