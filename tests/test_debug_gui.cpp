// pathlab-debug, tried as a person would: the real binary runs a script under
// Xvfb (CTest label gui) that waits for the render, hovers, switches views,
// clicks a pixel, exports its path as VTK, saves the image and takes
// screenshots; the test then checks the files. Also the pieces behind it
// without a window: the session, the views and the script parser.
#include "core/compiled_scene.h"
#include "core/error.h"
#include "core/image_io.h"
#include "core/scene_loader.h"
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
#include <fstream>
#include <set>

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
  for (const char* bad : {"clik 3 4", "click 3", "view sideways", "wait-spp -1", "quit now"}) {
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

  // Every view draws something; a bad pixel request is an error, not a crash.
  for (View v : kAllViews) {
    const auto rgba = view_rgba(snap, v, 0.0f);
    ASSERT_EQ(rgba.size(), 24u * 24u * 4u);
    std::set<std::uint32_t> colours;
    for (std::size_t i = 0; i < rgba.size(); i += 4) colours.insert(rgba[i] | rgba[i + 1] << 8 | rgba[i + 2] << 16);
    if (v != View::NonFinite) {
      EXPECT_GT(colours.size(), 2u) << view_name(v);
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
    lights += std::holds_alternative<LightEvent>(e);
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
