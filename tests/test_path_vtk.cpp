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
#include "debugtools/scene_geometry.h"
#include "tests/test_scenes.h"
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
#include <vtkIdTypeArray.h>
#include <vtkMultiBlockDataSet.h>
#include <vtkXMLMultiBlockDataReader.h>
#include <vtkXMLPolyDataReader.h>

#include <map>
#include <set>
#include <tuple>

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

// --vtk-geometry: the scene's triangles beside the paths.

vtkIdType field_value(vtkPolyData* poly, const char* name) {
  auto* a = vtkIdTypeArray::SafeDownCast(poly->GetFieldData()->GetArray(name));
  return a ? a->GetValue(0) : -12345;
}

// Runs trace-pixel on the 32x32 Cornell box with --vtk-geometry; returns the exit code.
int trace_with_geometry(const std::filesystem::path& vtp, const char* scope, const std::string& limit, std::string* err_text) {
  const std::string path = vtp.string();
  std::vector<const char*> argv = {"pathlab", "trace-pixel", "--pixel", "16,12", "--samples", "0..7", "--resolution",
                                   "32x32", "--vtk", path.c_str(), "--vtk-geometry", scope};
  if (!limit.empty()) argv.insert(argv.end(), {"--vtk-max-triangles", limit.c_str()});
  std::ostringstream out, err;
  const int code = cli::run(static_cast<int>(argv.size()), argv.data(), out, err);
  *err_text = err.str();
  return code;
}

std::size_t cornell_triangles() {
  std::size_t n = 0;
  for (const Shape& s : builtin_cornell_box().shapes) n += s.mesh.triangles.size();
  return n;
}

// Every triangle a recorded path hit is in the file, with the scene mesh's
// own vertex coordinates (read from the Scene here, not through
// scene_geometry), the hit point on it, and the number of hits.
TEST_F(PathVtk, GeometryHasTheTrianglesThePathsHitWithTheirCoordinates) {
  const auto vtp = dir_ / "paths.vtp";
  std::string err;
  ASSERT_EQ(trace_with_geometry(vtp, "hit", "", &err), 0) << err;
  EXPECT_NE(err.find("paths.geometry.vtp"), std::string::npos) << err;
  const auto poly = read_vtp(dir_ / "paths.geometry.vtp");
  ASSERT_NE(poly, nullptr);
  vtkDataArray* shape = poly->GetCellData()->GetArray("shape");
  vtkDataArray* prim = poly->GetCellData()->GetArray("prim");
  vtkDataArray* hits = poly->GetCellData()->GetArray("hits");
  ASSERT_TRUE(shape && prim && hits && poly->GetCellData()->GetArray("instance") && poly->GetCellData()->GetArray("material"));
  std::map<std::pair<int, int>, vtkIdType> cell_of;
  for (vtkIdType c = 0; c < poly->GetNumberOfCells(); ++c)
    cell_of[{static_cast<int>(shape->GetTuple1(c)), static_cast<int>(prim->GetTuple1(c))}] = c;

  const Expected expected = record("reference", 16, 12, 8);
  Scene scene = builtin_cornell_box();
  std::map<std::pair<int, int>, int> hit_count;
  for (const PathRecorder& p : expected.paths)
    for (const PathEvent& e : p.events())
      if (const auto* h = std::get_if<HitEvent>(&e)) ++hit_count[{static_cast<int>(h->shape), static_cast<int>(h->prim)}];
  ASSERT_GT(hit_count.size(), 2u);
  EXPECT_EQ(poly->GetNumberOfPolys(), static_cast<vtkIdType>(hit_count.size()));
  for (const auto& [key, count] : hit_count) {
    const auto it = cell_of.find(key);
    ASSERT_NE(it, cell_of.end()) << "shape " << key.first << " triangle " << key.second << " is missing";
    EXPECT_EQ(hits->GetTuple1(it->second), count);
    const TriangleMesh& mesh = scene.shapes[static_cast<std::size_t>(key.first)].mesh;
    const glm::uvec3 v = mesh.triangles[static_cast<std::size_t>(key.second)];
    vtkIdType n = 0;
    const vtkIdType* ids = nullptr;
    poly->GetPolys()->GetCellAtId(it->second, n, ids);
    ASSERT_EQ(n, 3);
    const unsigned corner[3] = {v.x, v.y, v.z};
    for (int k = 0; k < 3; ++k) {
      double p[3];
      poly->GetPoint(ids[k], p);
      for (int c = 0; c < 3; ++c) EXPECT_EQ(static_cast<float>(p[c]), mesh.positions[corner[k]][c]) << "corner " << k;
    }
  }
  // Each hit point lies on its triangle (barycentrics in [0,1], off the plane by rounding only).
  for (const PathRecorder& p : expected.paths)
    for (const PathEvent& e : p.events())
      if (const auto* h = std::get_if<HitEvent>(&e)) {
        const vtkIdType c = cell_of.at({static_cast<int>(h->shape), static_cast<int>(h->prim)});
        vtkIdType n = 0;
        const vtkIdType* ids = nullptr;
        poly->GetPolys()->GetCellAtId(c, n, ids);
        vec3 q[3];
        for (int k = 0; k < 3; ++k) {
          double d[3];
          poly->GetPoint(ids[k], d);
          q[k] = vec3(d[0], d[1], d[2]);
        }
        const vec3 e1 = q[1] - q[0], e2 = q[2] - q[0], nrm = glm::cross(e1, e2), w = h->p - q[0];
        const float area2 = glm::dot(nrm, nrm);
        const float b1 = glm::dot(glm::cross(w, e2), nrm) / area2, b2 = glm::dot(glm::cross(e1, w), nrm) / area2;
        EXPECT_GE(b1, -1e-4f);
        EXPECT_GE(b2, -1e-4f);
        EXPECT_LE(b1 + b2, 1.0f + 1e-4f);
        EXPECT_LT(std::abs(glm::dot(w, glm::normalize(nrm))), 1e-4f);
      }
  EXPECT_EQ(field_value(poly, "scene_triangles"), static_cast<vtkIdType>(cornell_triangles()));
  EXPECT_EQ(field_value(poly, "complete"), 0);
}

// scope scene: the whole scene when it fits under the limit; one triangle
// over the limit, only the hit triangles, and the message and the file say so.
TEST_F(PathVtk, GeometryOfTheWholeSceneHonoursTheTriangleLimit) {
  const std::size_t total = cornell_triangles();
  std::string err;
  const auto all = dir_ / "all.vtp";
  ASSERT_EQ(trace_with_geometry(all, "scene", std::to_string(total), &err), 0) << err;
  const auto whole = read_vtp(dir_ / "all.geometry.vtp");
  EXPECT_EQ(whole->GetNumberOfPolys(), static_cast<vtkIdType>(total));
  EXPECT_EQ(field_value(whole, "complete"), 1);
  EXPECT_EQ(field_value(whole, "limit"), static_cast<vtkIdType>(total));
  const std::string hit_err = err;

  // The multiblock file opens both: block 0 the paths, block 1 the geometry.
  vtkNew<vtkXMLMultiBlockDataReader> mb;
  mb->SetFileName((dir_ / "all.vtm").c_str());
  mb->Update();
  auto* blocks = vtkMultiBlockDataSet::SafeDownCast(mb->GetOutput());
  ASSERT_NE(blocks, nullptr);
  ASSERT_EQ(blocks->GetNumberOfBlocks(), 2u);
  auto* paths = vtkPolyData::SafeDownCast(blocks->GetBlock(0));
  auto* geometry = vtkPolyData::SafeDownCast(blocks->GetBlock(1));
  ASSERT_TRUE(paths && geometry);
  EXPECT_EQ(paths->GetNumberOfLines(), read_vtp(all)->GetNumberOfLines());
  EXPECT_EQ(geometry->GetNumberOfPolys(), static_cast<vtkIdType>(total));

  const auto capped = dir_ / "capped.vtp";
  ASSERT_EQ(trace_with_geometry(capped, "scene", std::to_string(total - 1), &err), 0) << err;
  const auto part = read_vtp(dir_ / "capped.geometry.vtp");
  const auto hit_only = dir_ / "hit.vtp";
  std::string err2;
  ASSERT_EQ(trace_with_geometry(hit_only, "hit", "", &err2), 0) << err2;
  EXPECT_EQ(part->GetNumberOfPolys(), read_vtp(dir_ / "hit.geometry.vtp")->GetNumberOfPolys());
  EXPECT_LT(part->GetNumberOfPolys(), static_cast<vtkIdType>(total));
  EXPECT_EQ(field_value(part, "complete"), 0);
  EXPECT_EQ(field_value(part, "limit"), static_cast<vtkIdType>(total - 1));
  EXPECT_EQ(field_value(part, "scene_triangles"), static_cast<vtkIdType>(total));
  EXPECT_NE(err.find("over --vtk-max-triangles " + std::to_string(total - 1)), std::string::npos) << err;
  EXPECT_NE(err.find("of the scene's " + std::to_string(total) + " triangles"), std::string::npos) << err;
  EXPECT_EQ(hit_err.find("over --vtk-max-triangles"), std::string::npos) << hit_err;

  // Without --vtk the option is refused.
  const char* argv[] = {"pathlab", "trace-pixel", "--pixel", "3,3", "--resolution", "8x8", "--vtk-geometry", "hit"};
  std::ostringstream out, e;
  EXPECT_EQ(cli::run(static_cast<int>(std::size(argv)), argv, out, e), 2);
}

// Instanced shapes are placed by their instance, and spheres tessellated onto
// the sphere: every hit on an instanced mesh lies on its written triangle,
// and every facet corner of a sphere lies at the radius from the placed centre.
TEST(SceneGeometry, PlacesInstancesAndTessellatesSpheres) {
  const CompiledScene compiled(test::cornell_with_instances());
  const Scene& scene = compiled.scene();
  const auto tracer = make_tracer("reference", compiled, scene.render);
  std::vector<PathRecorder> paths;
  for (std::uint32_t y = 0; y < static_cast<std::uint32_t>(scene.film.height); y += 16)
    for (std::uint32_t x = 0; x < static_cast<std::uint32_t>(scene.film.width); x += 16)
      tracer->trace_sample(x, y, 0, &paths.emplace_back());
  const SceneGeometry g = scene_geometry(scene, paths, GeometryScope::Hit, 0);
  int instanced_mesh_hits = 0, sphere_hits = 0;
  for (const PathRecorder& p : paths)
    for (const PathEvent& e : p.events()) {
      const auto* h = std::get_if<HitEvent>(&e);
      if (!h || h->instance == kNoInstance) continue;
      const bool sphere = scene.shapes[h->shape].kind == Shape::Kind::Sphere;
      std::vector<const GeometryTriangle*> mine;
      for (const GeometryTriangle& t : g.triangles)
        if (t.shape == h->shape && t.instance == static_cast<std::int64_t>(h->instance) &&
            (sphere || t.prim == static_cast<std::int64_t>(h->prim)))
          mine.push_back(&t);
      if (sphere) {
        ++sphere_hits;
        ASSERT_EQ(mine.size(), kSphereTriangles);
        // Back in the group's space (the placement may scale unevenly), on the sphere.
        const mat4 to_local = glm::inverse(scene.instances[h->instance].to_world);
        const Shape& s = scene.shapes[h->shape];
        for (const GeometryTriangle* t : mine)
          for (const vec3& corner : t->p)
            EXPECT_NEAR(glm::length(vec3(to_local * vec4(corner, 1.0f)) - s.center), s.radius, 1e-4f * (1.0f + s.radius));
      } else {
        ++instanced_mesh_hits;
        ASSERT_EQ(mine.size(), 1u);
        const vec3 e1 = mine[0]->p[1] - mine[0]->p[0], e2 = mine[0]->p[2] - mine[0]->p[0];
        const vec3 n = glm::normalize(glm::cross(e1, e2));
        EXPECT_LT(std::abs(glm::dot(h->p - mine[0]->p[0], n)), 1e-3f);
        EXPECT_LT(glm::length(h->p - mine[0]->p[0]), glm::length(e1) + glm::length(e2));
      }
    }
  EXPECT_GT(instanced_mesh_hits, 0);
  EXPECT_GT(sphere_hits, 0);
  EXPECT_EQ(tessellate_sphere(vec3(0.0f), 1.0f).size(), kSphereTriangles);
}

}  // namespace
}  // namespace pathlab
