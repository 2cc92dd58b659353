// Meshes with vertex normals and texture coordinates: the loaders read them
// (and refuse broken ones, naming the file and the vertex), the scene's
// "normals" key, the shading normal a hit gets, and the shading-normal
// policy of docs/ARCHITECTURE.md at its extremes.
#include "core/compiled_scene.h"
#include "core/error.h"
#include "core/geometry.h"
#include "core/material.h"
#include "core/mesh.h"
#include "core/sampling.h"
#include "core/scene_loader.h"
#include "core/surfel.h"
#include "reference/reference_tracer.h"
#include "wavefront/wavefront_tracer.h"

#include "tests/temp_dir.h"
#include "tests/test_scenes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

namespace pathlab {
namespace {

namespace fs = std::filesystem;

class ShadingData : public test::TempDirTest {
 protected:
  void expect_error(const std::string& name, const std::string& bytes, const std::string& message) const {
    try {
      (void)load_mesh(write(name, bytes));
      ADD_FAILURE() << name << ": no error";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  }
};

std::string ply_header(int vertices, const std::string& vertex_properties, int faces = 1) {
  return "ply\nformat ascii 1.0\nelement vertex " + std::to_string(vertices) +
         "\nproperty float x\nproperty float y\nproperty float z\n" + vertex_properties + "element face " +
         std::to_string(faces) + "\nproperty list uchar int vertex_indices\nend_header\n";
}

TEST_F(ShadingData, PlyNormalsAndTextureCoordinates) {
  const std::string props = "property float nx\nproperty float ny\nproperty float nz\nproperty float s\nproperty float t\n"
                            "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  MeshLoadReport report;
  const TriangleMesh m = load_mesh(write("n.ply", ply_header(3, props) +
                                                      "0 0 0  0 0 2  0 0  255 0 0\n"
                                                      "1 0 0  0 3 4  1 0  255 0 0\n"
                                                      "0 1 0  1 0 0  0 1  255 0 0\n3 0 1 2\n"),
                                   &report);
  ASSERT_EQ(m.normals.size(), 3u);
  ASSERT_EQ(m.uvs.size(), 3u);
  EXPECT_EQ(m.normals[0], vec3(0, 0, 1));  // normalised
  EXPECT_NEAR(m.normals[1].y, 0.6f, 1e-7f);
  EXPECT_NEAR(m.normals[1].z, 0.8f, 1e-7f);
  EXPECT_EQ(m.uvs[1], vec2(1, 0));
  EXPECT_EQ(m.uvs[2], vec2(0, 1));
  ASSERT_EQ(report.ignored.size(), 1u);
  EXPECT_EQ(report.ignored[0], "per-vertex colours");
}

TEST_F(ShadingData, PlyBrokenNormalsAreRefusedNamingTheVertex) {
  const std::string props = "property float nx\nproperty float ny\nproperty float nz\n";
  expect_error("nan.ply", ply_header(3, props) + "0 0 0 0 0 1\n1 0 0 nan 0 1\n0 1 0 0 0 1\n3 0 1 2\n",
               "nan.ply: vertex 1's normal is not finite");
  expect_error("zero.ply", ply_header(3, props) + "0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 0\n3 0 1 2\n",
               "zero.ply: vertex 2's normal has zero length");
  expect_error("uv.ply", ply_header(3, "property float u\nproperty float v\n") + "0 0 0 0 0\n1 0 0 inf 0\n0 1 0 0 0\n3 0 1 2\n",
               "uv.ply: vertex 1's texture coordinate is not finite");
}

// OBJ corners index positions, normals and texture coordinates separately:
// one vertex per distinct triple, and a corner without a normal takes its
// face's.
TEST_F(ShadingData, ObjCornersAreWelded) {
  MeshLoadReport report;
  const TriangleMesh m = load_mesh(write("w.obj",
                                         "mtllib none.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                         "vn 0 0 1\nvn 0 1 1\nvt 0 0\nvt 1 1\n"
                                         "f 1/1/1 2/1/1 3/2/2\n"   // two normals at the corners
                                         "f 1/1/1 3/2/2 4/2/1\n"   // shares corners 1 and 3 exactly
                                         "f 1//1 3 4\n"),          // mixed forms
                                   &report);
  ASSERT_EQ(m.triangles.size(), 3u);
  ASSERT_EQ(m.normals.size(), m.positions.size());
  ASSERT_EQ(m.uvs.size(), m.positions.size());
  // Distinct corners: 1/1/1, 2/1/1, 3/2/2, 4/2/1, 1//1, 3 (face normal), 4 (face normal).
  EXPECT_EQ(m.positions.size(), 7u);
  EXPECT_EQ(m.triangles[1][0], m.triangles[0][0]);
  EXPECT_EQ(m.triangles[1][1], m.triangles[0][2]);
  EXPECT_NEAR(m.normals[m.triangles[0][2]].y, std::sqrt(0.5f), 1e-6f);
  EXPECT_EQ(m.normals[m.triangles[2][1]], vec3(0, 0, 1));  // the face's own
  EXPECT_EQ(m.uvs[m.triangles[0][2]], vec2(1, 1));
  // "mtllib" names a file that does not exist and no face uses a material:
  // nothing to warn about.
  EXPECT_TRUE(report.ignored.empty()) << report.ignored.front();
}

// Face materials are used by name; the library's content is not read, and
// the one warning says so (so that a user knows the colours come from the scene).
TEST_F(ShadingData, ObjMaterialLibraryContentIsWarnedAbout) {
  MeshLoadReport report;
  const TriangleMesh m =
      load_mesh(write("m.obj", "mtllib none.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n"), &report);
  ASSERT_EQ(report.ignored.size(), 1u);
  EXPECT_NE(report.ignored[0].find("the material library's content (none.mtl: Kd, Ks, maps; the scene's materials give "
                                   "the colours)"),
            std::string::npos)
      << report.ignored[0];
  ASSERT_EQ(m.material_names, std::vector<std::string>{"red"});
  EXPECT_EQ(m.face_material, std::vector<std::uint16_t>{0});
}

TEST_F(ShadingData, SceneNormalsKey) {
  write("tri.ply", ply_header(4, "property float nx\nproperty float ny\nproperty float nz\n", 2) +
                       "0 0 0 0 0 1\n1 0 0 0 0 1\n1 1 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n3 0 2 3\n");
  const auto scene_with = [&](const std::string& normals) {
    const std::string text = R"({"pathlab_scene": 1, "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0]},
      "materials": {"m": {"type": "diffuse", "albedo": 0.5}},
      "shapes": [{"type": "mesh", "file": "tri.ply", "material": "m", "transform": {"scale": [2, 1, 1]})" +
                             (normals.empty() ? "" : R"(, "normals": ")" + normals + "\"") + "}]}";
    return parse_scene(text, dir_ / "s.json");
  };
  EXPECT_EQ(scene_with("").shapes[0].mesh.normals.size(), 4u);
  EXPECT_TRUE(scene_with("flat").shapes[0].mesh.normals.empty());
  const Scene smooth = scene_with("smooth");
  ASSERT_EQ(smooth.shapes[0].mesh.normals.size(), 4u);
  for (const vec3& n : smooth.shapes[0].mesh.normals) EXPECT_EQ(n, vec3(0, 0, 1));
  try {
    (void)scene_with("soft");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/shapes/0/normals: unknown normals 'soft' (expected file, flat or smooth)"),
              std::string::npos)
        << e.what();
  }
}

// Normals go through the inverse transpose: under a shear and a non-uniform
// scale, a plane's file normals stay perpendicular to the transformed plane
// (the transformed normal itself would not).
TEST_F(ShadingData, TransformKeepsNormalsPerpendicular) {
  const float c = std::sqrt(1.0f / 3.0f);
  write("plane.ply", ply_header(3, "property float nx\nproperty float ny\nproperty float nz\n") +
                         "1 0 0 " + std::to_string(c) + " " + std::to_string(c) + " " + std::to_string(c) + "\n" +
                         "0 1 0 " + std::to_string(c) + " " + std::to_string(c) + " " + std::to_string(c) + "\n" +
                         "0 0 1 " + std::to_string(c) + " " + std::to_string(c) + " " + std::to_string(c) + "\n3 0 1 2\n");
  const std::string text = R"({"pathlab_scene": 1, "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0]},
    "materials": {"m": {"type": "diffuse", "albedo": 0.5}},
    "shapes": [{"type": "mesh", "file": "plane.ply", "material": "m",
                "transform": {"matrix": [1, 0.7, 0, 0,  0, 1, 0, 0,  0, 0, 3, 0,  0, 0, 0, 1]}}]})";
  const Scene scene = parse_scene(text, dir_ / "s.json");
  const TriangleMesh& m = scene.shapes[0].mesh;
  ASSERT_EQ(m.normals.size(), 3u);
  const glm::uvec3 t = m.triangles[0];
  const vec3 face = glm::normalize(glm::cross(m.positions[t.y] - m.positions[t.x], m.positions[t.z] - m.positions[t.x]));
  for (const vec3& n : m.normals) {
    EXPECT_NEAR(glm::length(n), 1.0f, 1e-6f);
    EXPECT_NEAR(glm::dot(n, face), 1.0f, 1e-6f);
  }
}

TEST(ShadingNormals, ShadingNormalFollowsTheGeometricSide) {
  const vec3 ng(0, 0, 1);
  EXPECT_EQ(shading_normal(ng, vec3(0.0f)), ng);                              // vanished
  EXPECT_EQ(shading_normal(ng, vec3(std::nanf(""), 0, 1)), ng);                // not finite
  EXPECT_EQ(shading_normal(ng, vec3(0, 0, 3)), ng);                            // equal
  EXPECT_EQ(shading_normal(ng, vec3(1e-4f, 0, 1)), ng);                        // within 0.08 degrees
  const vec3 tilted = shading_normal(ng, vec3(0, -1, -1));                     // opposite side: turned over
  EXPECT_NEAR(tilted.y, std::sqrt(0.5f), 1e-6f);
  EXPECT_NEAR(tilted.z, std::sqrt(0.5f), 1e-6f);
}

// A surfel with shading normal `ns` on the plane z = 0.
Surfel tilted_surfel(const Material& m, float degrees) {
  Surfel s;
  s.p = vec3(0.0f);
  s.n = vec3(0, 0, 1);
  const float a = degrees * kPi / 180.0f;
  s.frame = Frame(vec3(std::sin(a), 0.0f, std::cos(a)));
  s.shading_normal = true;
  s.material = &m;
  return s;
}

// At the extremes (a shading normal 60, 89 and 89.9 degrees from the
// geometric one; wo from overhead to grazing, on either side) no sampled
// direction crosses the geometric surface for a reflection, weights are
// finite and non-negative, eval is 0 exactly where the policy says, and a
// direction with f > 0 has a density (so MIS weights exist).
TEST(ShadingNormals, PolicyAtTheExtremes) {
  Material lambert = diffuse_material(Spectrum(0.8f));
  DisneyParams dp;
  dp.roughness = 0.3f;
  dp.metallic = 0.5f;
  Material disney = disney_material(dp);
  Material glass = dielectric_material(DielectricParams{});
  for (const Material* m : {&lambert, &disney, &glass}) {
    for (float degrees : {60.0f, 89.0f, 89.9f}) {
      const Surfel s = tilted_surfel(*m, degrees);
      std::uint64_t state = 12345;
      const auto u01 = [&] {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return static_cast<float>(state >> 40) * 0x1p-24f;
      };
      int kept = 0;
      for (int i = 0; i < 4000; ++i) {
        const vec3 wo = square_to_uniform_sphere(vec2(u01(), u01()));
        if (wo.z == 0.0f) continue;
        const std::optional<BsdfSample> b = s.scatter(wo, u01(), vec2(u01(), u01()));
        if (!b) continue;
        ++kept;
        const bool transmits = b->lobe == Lobe::DielectricTransmission;
        ASSERT_EQ((b->wi.z > 0.0f) == (wo.z > 0.0f), !transmits) << degrees << " degrees, wo " << wo.z;
        for (int c = 0; c < 3; ++c) ASSERT_TRUE(std::isfinite(b->weight[c]) && b->weight[c] >= 0.0f);
        if (b->impulse) continue;
        const Spectrum f = s.eval(b->wi, wo);
        EXPECT_GT(s.pdf(b->wi, wo), 0.0f);
        for (int c = 0; c < 3; ++c) ASSERT_TRUE(std::isfinite(f[c]) && f[c] >= 0.0f);
        // Through the geometric surface, never.
        const vec3 through(b->wi.x, b->wi.y, -b->wi.z);
        EXPECT_EQ(s.eval(through, wo), Spectrum(0.0f));
      }
      EXPECT_GT(kept, 100) << degrees << " degrees";
    }
  }
}

// A one-sided material is black from behind (eval, pdf 0; scatter and
// scatter_cosine absorb) and, on its front, exactly the two-sided material:
// Lambert, mirror and Disney, flat and with a shading normal tilted 60 degrees.
TEST(OneSided, BackIsBlackFrontIsTheTwoSidedMaterial) {
  DisneyParams dp;
  dp.roughness = 0.3f;
  dp.metallic = 0.5f;
  Material mirror = diffuse_material(Spectrum(0.9f));
  mirror.type = MaterialType::Mirror;
  for (const Material& two : {diffuse_material(Spectrum(0.8f)), mirror, disney_material(dp)}) {
    Material one = two;
    one.one_sided = true;
    for (float degrees : {0.0f, 60.0f}) {
      Surfel s2 = tilted_surfel(two, degrees), s1 = tilted_surfel(one, degrees);
      s2.shading_normal = s1.shading_normal = degrees != 0.0f;
      std::uint64_t state = 777;
      const auto u01 = [&] {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return static_cast<float>(state >> 40) * 0x1p-24f;
      };
      int front = 0, back = 0;
      for (int i = 0; i < 2000; ++i) {
        const vec3 wo = square_to_uniform_sphere(vec2(u01(), u01()));
        const vec3 wi = square_to_uniform_sphere(vec2(u01(), u01()));
        const float ul = u01();
        const vec2 u(u01(), u01());
        if (wo.z <= 0.0f) {
          ++back;
          ASSERT_EQ(s1.eval(wi, wo), Spectrum(0.0f));
          ASSERT_EQ(s1.pdf(wi, wo), 0.0f);
          ASSERT_FALSE(s1.scatter(wo, ul, u).has_value());
          ASSERT_FALSE(s1.scatter_cosine(wo, u).has_value());
          continue;
        }
        ++front;
        // Light from behind is not reflected.
        ASSERT_EQ(s1.eval(wi, wo), wi.z > 0.0f ? s2.eval(wi, wo) : Spectrum(0.0f));
        ASSERT_EQ(s1.pdf(wi, wo), s2.pdf(wi, wo));
        const auto b1 = s1.scatter(wo, ul, u), b2 = s2.scatter(wo, ul, u);
        ASSERT_EQ(b1.has_value(), b2.has_value());
        if (b1) {
          ASSERT_EQ(b1->wi, b2->wi);
          ASSERT_EQ(b1->weight, b2->weight);
        }
      }
      EXPECT_GT(front, 900);
      EXPECT_GT(back, 900);
    }
  }
}

// A mesh whose vertex normals are its face normals shades exactly as the
// flat mesh: same bits, both tracers.
TEST(ShadingNormals, FaceNormalsAsVertexNormalsRenderTheFlatBits) {
  Scene flat = test::small_cornell(12, 2, FilterKind::Box);
  Scene with_normals = flat;
  for (Shape& shape : with_normals.shapes) {
    if (shape.kind != Shape::Kind::Triangles) continue;
    shape.mesh.normals = smooth_vertex_normals(shape.mesh);  // planar faces: the face normal
    ASSERT_TRUE(shape.mesh.has_normals());
  }
  const RenderSettings settings = flat.render;
  const CompiledScene a(std::move(flat)), b(std::move(with_normals));
  const std::size_t n = 12 * 12 * 2;
  for (int tracer = 0; tracer < 2; ++tracer) {
    std::vector<FilmSample> sa(n), sb(n);
    if (tracer == 0) {
      ReferenceTracer(a, settings).render_batch(0, 2, sa);
      ReferenceTracer(b, settings).render_batch(0, 2, sb);
    } else {
      WavefrontTracer(a, settings, 97, {}, WavefrontStages::Scalar).render_batch(0, 2, sa);
      WavefrontTracer(b, settings, 97, {}, WavefrontStages::Scalar).render_batch(0, 2, sb);
    }
    for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(std::memcmp(&sa[i].L, &sb[i].L, sizeof(Spectrum)), 0) << i;
  }
}

// The smooth sphere looks smooth: across one of its facets the shading
// normal turns continuously (resolve interpolates it), where flat shading
// keeps one normal.
TEST(ShadingNormals, ResolveInterpolatesTheVertexNormals) {
  const CompiledScene compiled(test::cornell_with_smooth_sphere());
  const std::uint32_t shape = static_cast<std::uint32_t>(compiled.scene().shapes.size() - 1);
  const TriangleMesh& m = compiled.scene().shapes[shape].mesh;
  const std::uint32_t prim = static_cast<std::uint32_t>(m.triangles.size() / 2);
  const glm::uvec3 t = m.triangles[prim];
  for (const vec2 b : {vec2(0.0f), vec2(1.0f, 0.0f), vec2(0.0f, 1.0f), vec2(0.3f, 0.3f)}) {
    Surfel s;
    const Ray ray{vec3(0.0f), vec3(0, 0, 1), kInfinity};
    compiled.resolve(ray, RayHit{1.0f, shape, prim, b}, &s);
    const vec3 expected = glm::normalize((1 - b.x - b.y) * m.normals[t.x] + b.x * m.normals[t.y] + b.y * m.normals[t.z]);
    EXPECT_TRUE(s.shading_normal);
    EXPECT_NEAR(glm::dot(s.frame.n, expected), 1.0f, 1e-6f);
    EXPECT_GT(glm::dot(s.frame.n, s.n), 0.9f);
  }
}

}  // namespace
}  // namespace pathlab
