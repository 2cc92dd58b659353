// trace-pixel --vtk: the .vtp file read back with VTK's own reader has one
// polyline per path and one two-point line per shadow ray, with the point
// arrays of docs/path-vtk.md holding the recorded events' values.
#include "apps/cli/cli.h"
#include "debugtools/tracers.h"
#include "core/compiled_scene.h"
#include "core/scene_loader.h"
#include "core/tracer.h"
#include "debugtools/path_geometry.h"
#include "debugtools/path_recorder.h"
#include "tests/temp_dir.h"

#include <gtest/gtest.h>

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkStringArray.h>
#include <vtkXMLPolyDataReader.h>

#include <sstream>

namespace pathlab {
namespace {

class PathVtk : public test::TempDirTest, public ::testing::WithParamInterface<const char*> {};

// Every recorded path of samples 0..7 of one Cornell pixel, as the test sees them.
struct Expected {
  std::vector<PathRecorder> paths;
  float escape_length = 0.0f;
};

Expected record(const std::string& tracer, std::uint32_t x, std::uint32_t y, std::uint32_t samples) {
  Scene scene = builtin_cornell_box();
  scene.film.width = scene.film.height = 32;
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  Expected e;
  e.escape_length = 2.0f * compiled.bounds_radius();
  const auto t = make_tracer(tracer, compiled, settings);
  for (std::uint32_t s = 0; s < samples; ++s) t->trace_sample(x, y, s, &e.paths.emplace_back());
  return e;
}

vtkSmartPointer<vtkPolyData> read_vtp(const std::filesystem::path& file) {
  vtkNew<vtkXMLPolyDataReader> reader;
  reader->SetFileName(file.c_str());
  reader->Update();
  return reader->GetOutput();
}

TEST_P(PathVtk, ReadsBackWithPointsLinesAndArrays) {
  const std::string tracer = GetParam();
  const auto file = dir_ / "paths.vtp";
  const std::string path = file.string();
  const char* argv[] = {"pathlab", "trace-pixel", "--pixel", "16,12", "--samples", "0..7", "--resolution", "32x32",
                        "--tracer", tracer.c_str(), "--vtk", path.c_str()};
  std::ostringstream out, err;
  ASSERT_EQ(cli::run(static_cast<int>(std::size(argv)), argv, out, err), 0) << err.str();
  const Expected expected = record(tracer, 16, 12, 8);

  const auto poly = read_vtp(file);
  ASSERT_NE(poly, nullptr);
  vtkPointData* pd = poly->GetPointData();
  for (const auto& [name, components] : std::vector<std::pair<std::string, int>>{
           {"depth", 1}, {"throughput", 3}, {"radiance_added", 3}, {"pdf", 1}, {"lobe", 1}, {"flags", 1}}) {
    vtkDataArray* a = pd->GetArray(name.c_str());
    ASSERT_NE(a, nullptr) << name;
    EXPECT_EQ(a->GetNumberOfComponents(), components) << name;
    EXPECT_EQ(a->GetNumberOfTuples(), poly->GetNumberOfPoints()) << name;
  }
  ASSERT_NE(poly->GetCellData()->GetArray("kind"), nullptr);
  ASSERT_NE(poly->GetCellData()->GetArray("sample"), nullptr);
  auto* lobe_names = vtkStringArray::SafeDownCast(poly->GetFieldData()->GetAbstractArray("lobe_names"));
  ASSERT_NE(lobe_names, nullptr);
  EXPECT_EQ(lobe_names->GetValue(static_cast<vtkIdType>(Lobe::Lambert)), "lambert");

  // Count lines and points from the recorded events alone.
  vtkIdType lines = 0, points = 0;
  for (const PathRecorder& p : expected.paths) {
    vtkIdType path_points = 0;
    for (const PathEvent& e : p.events()) {
      const auto* l = std::get_if<LightEvent>(&e);
      const bool light = l != nullptr && l->rejected == LightRejection::None;  // a rejected sample has no shadow ray
      lines += light;
      points += light ? 2 : 0;
      path_points += std::holds_alternative<CameraEvent>(e) || std::holds_alternative<HitEvent>(e) ||
                     std::holds_alternative<EscapeEvent>(e);
    }
    ++lines;
    points += path_points;
  }
  EXPECT_EQ(poly->GetNumberOfLines(), lines);
  EXPECT_EQ(poly->GetNumberOfPoints(), points);

  // Walk the cells: path polyline, then its shadow rays, sample by sample.
  vtkCellArray* cells = poly->GetLines();
  vtkDataArray* depth = pd->GetArray("depth");
  vtkDataArray* throughput = pd->GetArray("throughput");
  vtkDataArray* added = pd->GetArray("radiance_added");
  vtkDataArray* flags = pd->GetArray("flags");
  vtkDataArray* kind = poly->GetCellData()->GetArray("kind");
  vtkDataArray* sample = poly->GetCellData()->GetArray("sample");
  vtkIdType cell = 0;
  int shadow_rays = 0, escapes = 0;
  for (std::uint32_t s = 0; s < expected.paths.size(); ++s) {
    const PathRecorder& rec = expected.paths[s];
    vtkIdType n = 0;
    const vtkIdType* ids = nullptr;
    cells->GetCellAtId(cell, n, ids);
    EXPECT_EQ(kind->GetTuple1(cell), 0.0);
    EXPECT_EQ(sample->GetTuple1(cell), static_cast<double>(s));
    ++cell;
    // Point by point along the path: camera, the hits, the escape point.
    vtkIdType i = 0;
    double sum[3] = {0, 0, 0};
    vec3 last(0.0f);
    for (const PathEvent& e : rec.events()) {
      vec3 want;
      int want_depth = 0;
      if (const auto* c = std::get_if<CameraEvent>(&e)) want = c->origin, want_depth = 0;
      else if (const auto* h = std::get_if<HitEvent>(&e)) want = h->p, want_depth = h->vertex;
      else if (const auto* x = std::get_if<EscapeEvent>(&e)) want = vec3(NAN), want_depth = x->vertex;
      else continue;
      ASSERT_LT(i, n) << "sample " << s;
      double p[3];
      poly->GetPoint(ids[i], p);
      if (std::isnan(want.x)) {  // escape: a finite distance from the last point
        ++escapes;
        EXPECT_NEAR(glm::length(vec3(p[0], p[1], p[2]) - last), expected.escape_length, 1e-3f);
        EXPECT_TRUE(static_cast<int>(flags->GetTuple1(ids[i])) & kPointEscape);
      } else {
        for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(static_cast<float>(p[c]), want[c]) << "sample " << s;
        last = want;
      }
      if (const auto* h = std::get_if<HitEvent>(&e)) {
        for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(static_cast<float>(throughput->GetComponent(ids[i], c)), h->throughput[c]);
      }
      EXPECT_EQ(depth->GetTuple1(ids[i]), want_depth);
      for (int c = 0; c < 3; ++c) sum[c] += added->GetComponent(ids[i], c);
      ++i;
    }
    EXPECT_EQ(i, n) << "sample " << s;
    // radiance_added along the path adds up to the sample's radiance.
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(sum[c], rec.result()[c], 1e-4 * (1.0 + rec.result()[c])) << "sample " << s;
    // Then its shadow rays: from the shading vertex to the light point.
    for (const PathEvent& e : rec.events()) {
      const auto* l = std::get_if<LightEvent>(&e);
      if (l == nullptr || l->rejected != LightRejection::None) continue;  // no shadow ray was traced
      cells->GetCellAtId(cell, n, ids);
      ASSERT_EQ(n, 2);
      EXPECT_EQ(kind->GetTuple1(cell), 1.0);
      ++cell;
      ++shadow_rays;
      double p[3];
      poly->GetPoint(ids[1], p);
      if (!l->infinite) {
        for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(static_cast<float>(p[c]), l->point[c]);
      }
      EXPECT_EQ(depth->GetTuple1(ids[0]), l->vertex);
      EXPECT_EQ((static_cast<int>(flags->GetTuple1(ids[0])) & kPointNeeVisible) != 0, l->visible);
      EXPECT_TRUE(static_cast<int>(flags->GetTuple1(ids[1])) & kPointLight);
      EXPECT_FLOAT_EQ(static_cast<float>(pd->GetArray("pdf")->GetTuple1(ids[0])), l->pdf);
    }
  }
  EXPECT_EQ(cell, lines);
  EXPECT_GT(shadow_rays, 0) << "pick a pixel whose paths sample the light";
  EXPECT_GT(escapes, 0) << "pick a pixel with an escaping path";
}

INSTANTIATE_TEST_SUITE_P(Tracers, PathVtk, ::testing::Values("reference", "wavefront"));

TEST_F(PathVtk, UnwritablePathIsOneClearErrorAndNoFile) {
  const char* argv[] = {"pathlab", "trace-pixel", "--pixel", "3,3", "--resolution", "8x8", "--vtk", "/proc/paths.vtp"};
  std::ostringstream out, err;
  EXPECT_EQ(cli::run(static_cast<int>(std::size(argv)), argv, out, err), 2);
  EXPECT_NE(err.str().find("/proc/paths.vtp"), std::string::npos) << err.str();
  EXPECT_FALSE(std::filesystem::exists("/proc/paths.vtp"));
}

TEST_F(PathVtk, RefusesBadRangesAndBothTracers) {
  const std::string path = (dir_ / "x.vtp").string();
  for (const std::vector<const char*>& extra : std::vector<std::vector<const char*>>{
           {"--samples", "5..2"}, {"--samples", "1-3"}, {"--samples", "0..3", "--json"}, {"--tracer", "both", "--vtk", path.c_str()}}) {
    std::vector<const char*> argv = {"pathlab", "trace-pixel", "--pixel", "3,3", "--resolution", "8x8"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    std::ostringstream out, err;
    EXPECT_EQ(cli::run(static_cast<int>(argv.size()), argv.data(), out, err), 2) << extra[0] << " " << extra[1];
  }
  EXPECT_FALSE(std::filesystem::exists(path));
}

}  // namespace
}  // namespace pathlab
