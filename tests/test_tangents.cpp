// Tangents (core/tangents.h): computed from texture coordinates in closed
// form cases, carried by transform_mesh, turned into the shading frame by
// CompiledScene::resolve (world and instanced hits), computed by the scene
// loader only where an anisotropic material needs them, and orienting an
// anisotropic Disney highlight.
#include "core/compiled_scene.h"
#include "core/geometry.h"
#include "core/material.h"
#include "core/mesh.h"
#include "core/scene_loader.h"
#include "core/surfel.h"
#include "core/tangents.h"

#include "tests/temp_dir.h"
#include "tests/test_scenes.h"

#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <fstream>
#include <string>

namespace pathlab {
namespace {

constexpr double kPiD = 3.141592653589793;

// The quad origin + a u + b v for (u, v) in [0, 1]^2, two triangles wound
// counter-clockwise about cross(a, b), with that normal at its vertices
// (unless `normals` is false) and (u, v) as texture coordinates, or (1 - u,
// v) when `mirror_u`.
TriangleMesh quad(vec3 origin, vec3 a, vec3 b, bool normals = true, bool mirror_u = false) {
  TriangleMesh m;
  const vec3 n = glm::normalize(glm::cross(a, b));
  for (const vec2 c : {vec2(0, 0), vec2(1, 0), vec2(1, 1), vec2(0, 1)}) {
    m.positions.push_back(origin + c.x * a + c.y * b);
    m.uvs.push_back(mirror_u ? vec2(1.0f - c.x, c.y) : c);
    if (normals) m.normals.push_back(n);
  }
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

// test::uv_sphere (unit, exact normals, its vertices row by row from the
// north pole, the seam's doubled as a loader would split them) with u = phi /
// 2 pi and v = 1 - theta / pi (v grows northwards, +y).
TriangleMesh uv_sphere_with_uvs(int rings) {
  TriangleMesh m = test::uv_sphere(vec3(0.0f), 1.0f, rings);
  const int segments = 2 * rings;
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j <= segments; ++j)
      m.uvs.push_back(vec2(static_cast<float>(j) / segments, 1.0f - static_cast<float>(i) / rings));
  return m;
}

void expect_near(const vec3& a, const vec3& b, float tol, const std::string& what = "") {
  EXPECT_LT(glm::distance(a, b), tol) << what << ": (" << a.x << ", " << a.y << ", " << a.z << ") vs (" << b.x << ", "
                                      << b.y << ", " << b.z << ")";
}

void expect_orthonormal(const Frame& f) {
  EXPECT_NEAR(glm::length(f.s), 1.0f, 1e-5f);
  EXPECT_NEAR(glm::length(f.t), 1.0f, 1e-5f);
  EXPECT_NEAR(glm::length(f.n), 1.0f, 1e-5f);
  EXPECT_NEAR(glm::dot(f.s, f.t), 0.0f, 1e-5f);
  EXPECT_NEAR(glm::dot(f.s, f.n), 0.0f, 1e-5f);
  EXPECT_NEAR(glm::dot(f.t, f.n), 0.0f, 1e-5f);
}

TEST(Tangents, PlanarQuadIsDpDuInClosedForm) {
  // Skewed, non-unit edges: the tangent is a's direction (P = o + a u + b v,
  // so dP/du = a), the bitangent b's side of it: w = +1.
  const vec3 a(2.0f, 0.5f, 0.0f), b(0.7f, 1.5f, 0.0f);
  for (const bool normals : {true, false}) {
    const std::vector<vec4> t = compute_tangents(quad(vec3(1, 2, 3), a, b, normals));
    ASSERT_EQ(t.size(), 4u);
    for (const vec4& v : t) {
      expect_near(vec3(v), glm::normalize(a), 1e-6f, normals ? "normals" : "flat");
      EXPECT_EQ(v.w, 1.0f);
    }
  }
}

TEST(Tangents, MirroredUvLayoutIsLeftHanded) {
  // u runs against a: dP/du = -a, while dP/dv = b stays, so the bitangent is
  // -cross(n, t).
  const vec3 a(1.0f, 0.0f, 0.3f), b(0.0f, 1.0f, 0.0f);
  for (const vec4& v : compute_tangents(quad(vec3(0.0f), a, b, true, true))) {
    expect_near(vec3(v), -glm::normalize(a), 1e-6f);
    EXPECT_EQ(v.w, -1.0f);
  }
}

TEST(Tangents, SphereTangentsFollowPhi) {
  const int rings = 16, segments = 2 * rings;
  const TriangleMesh m = uv_sphere_with_uvs(rings);
  const std::vector<vec4> t = compute_tangents(m);
  // Each triangle's dP/du is a chord of its ring, turned by half a segment
  // from the vertex's +phi; the corners either side of a vertex cancel that,
  // but a seam vertex (j = 0 or segments, split as a loader splits a UV
  // seam) has one side only: allow it the half segment.
  const float half_segment = std::cos(static_cast<float>(kPiD / segments));
  for (std::size_t v = 0; v < t.size(); ++v) {
    const int i = static_cast<int>(v) / (segments + 1), j = static_cast<int>(v) % (segments + 1);
    if (i == 0 || i == rings) continue;  // the poles have no phi direction
    const double phi = 2.0 * kPiD * j / segments;
    const vec3 along_phi(static_cast<float>(-std::sin(phi)), 0.0f, static_cast<float>(std::cos(phi)));
    EXPECT_GT(glm::dot(vec3(t[v]), along_phi), half_segment) << "vertex " << v;
    if (j != 0 && j != segments) {
      EXPECT_GT(glm::dot(vec3(t[v]), along_phi), 0.9999f) << "vertex " << v;
    }
    EXPECT_NEAR(glm::dot(vec3(t[v]), m.normals[v]), 0.0f, 1e-6f);
    // v grows northwards (+y), and cross(outward n, +phi) points south.
    EXPECT_EQ(t[v].w, -1.0f) << "vertex " << v;
  }
}

TEST(Tangents, DegenerateUvTrianglesContributeNothing) {
  // Every UV equal: no direction anywhere; the tangent is Frame(n).s, w = +1.
  TriangleMesh m = quad(vec3(0.0f), vec3(1, 0, 0), vec3(0, 0, -1));
  for (vec2& uv : m.uvs) uv = vec2(0.25f);
  const std::vector<vec4> flat = compute_tangents(m);
  for (std::size_t v = 0; v < 4; ++v) {
    EXPECT_EQ(vec3(flat[v]), Frame(m.normals[v]).s);
    EXPECT_EQ(flat[v].w, 1.0f);
  }
  // Triangle {0, 2, 3} collapsed in UV (corners 2 and 3 on the line u = v):
  // the shared vertices keep triangle {0, 1, 2}'s tangent, and vertex 3,
  // only in the degenerate one, falls back.
  m = quad(vec3(0.0f), vec3(0, 1, 0), vec3(-1, 0, 0));
  m.uvs[3] = vec2(0.5f, 0.5f);
  const std::vector<vec4> half = compute_tangents(m);
  for (const std::size_t v : {0u, 1u, 2u}) expect_near(vec3(half[v]), vec3(0, 1, 0), 1e-6f);
  EXPECT_EQ(vec3(half[3]), Frame(m.normals[3]).s);
  EXPECT_EQ(half[3].w, 1.0f);
}

TEST(Tangents, TransformMeshCarriesThemAsTheyWouldBeRecomputed) {
  // For an affine map the derivatives map by the matrix, so transforming
  // the tangents must give what computing them on the moved mesh gives: the
  // direction by the matrix, w flipped by a mirror.
  const mat4 rotate = glm::rotate(mat4(1.0f), 0.7f, vec3(1, 2, 3));
  const mat4 squash = glm::scale(mat4(1.0f), vec3(3.0f, 0.5f, 2.0f));
  const mat4 mirror = glm::scale(mat4(1.0f), vec3(-1.0f, 1.0f, 1.0f));
  for (const mat4& xf : {rotate * squash, rotate * squash * mirror}) {
    TriangleMesh m = quad(vec3(0.2f, 0.0f, 0.1f), vec3(1.0f, 0.2f, 0.0f), vec3(0.3f, 1.0f, 0.5f));
    m.tangents = compute_tangents(m);
    const float w = m.tangents[0].w;
    transform_mesh(&m, xf);
    const std::vector<vec4> again = compute_tangents(m);
    for (std::size_t v = 0; v < 4; ++v) {
      expect_near(vec3(m.tangents[v]), vec3(again[v]), 1e-5f);
      EXPECT_EQ(m.tangents[v].w, again[v].w);
    }
    EXPECT_EQ(m.tangents[0].w, glm::determinant(mat3(xf)) < 0.0f ? -w : w);
  }
}

// A scene for resolve(): the built-in Cornell box plus `mesh` (grey
// Lambert), with tangents computed.
Scene scene_with(TriangleMesh mesh, bool flip_normals = false) {
  Scene scene = builtin_cornell_box();
  scene.materials.push_back(diffuse_material(Spectrum(0.5f)));
  mesh.tangents = compute_tangents(mesh);
  Shape shape;
  shape.description = "test mesh";
  shape.material = static_cast<std::uint32_t>(scene.materials.size() - 1);
  shape.mesh = std::move(mesh);
  shape.flip_normals = flip_normals;
  scene.shapes.push_back(std::move(shape));
  return scene;
}

Surfel resolve_at(const CompiledScene& compiled, std::uint32_t shape, std::uint32_t prim, vec2 b,
                  std::uint32_t instance = kNoInstance) {
  Surfel s;
  compiled.resolve(Ray{vec3(0.0f), vec3(0, 0, 1), kInfinity}, RayHit{1.0f, shape, prim, b, instance}, &s);
  return s;
}

TEST(TangentFrame, ResolveOrientsTheFrameByTheInterpolatedTangent) {
  const CompiledScene compiled(scene_with(uv_sphere_with_uvs(12)));
  const auto shape = static_cast<std::uint32_t>(compiled.scene().shapes.size() - 1);
  const TriangleMesh& m = compiled.scene().shapes[shape].mesh;
  for (const std::uint32_t prim : {30u, 100u, 211u})
    for (const vec2 b : {vec2(0.0f), vec2(0.2f, 0.5f), vec2(0.6f, 0.1f)}) {
      const Surfel s = resolve_at(compiled, shape, prim, b);
      expect_orthonormal(s.frame);
      const glm::uvec3 v = m.triangles[prim];
      const vec3 t = vec3((1 - b.x - b.y) * m.tangents[v.x] + b.x * m.tangents[v.y] + b.y * m.tangents[v.z]);
      const vec3 expected = glm::normalize(t - glm::dot(t, s.frame.n) * s.frame.n);
      EXPECT_GT(glm::dot(s.frame.s, expected), 1.0f - 1e-6f) << prim;
      // The t axis is the mesh's bitangent: northwards, as v grows.
      EXPECT_GT(s.frame.t.y, 0.0f) << prim;
    }
}

// Whatever side the shading normal ends on (flip_normals, file normals
// against the winding) and whatever the placement (mirrors included), the
// frame's s is dP/du and its t is dP/dv.
TEST(TangentFrame, SIsDpDuAndTIsDpDvOnEverySide) {
  const vec3 a(1, 0, 0), b(0, 1, 0);
  struct Case {
    const char* name;
    bool normals, flip, reversed_normals;
  };
  for (const Case c : {Case{"flat", false, false, false}, Case{"flat, flipped", false, true, false},
                       Case{"normals", true, false, false}, Case{"normals, flipped", true, true, false},
                       Case{"normals against the winding", true, false, true}}) {
    TriangleMesh m = quad(vec3(-0.5f, -0.5f, 0.0f), a, b, c.normals);
    if (c.reversed_normals)
      for (vec3& n : m.normals) n = -n;
    Scene scene = scene_with(std::move(m), c.flip);
    const auto shape = static_cast<std::uint32_t>(scene.shapes.size() - 1);
    // The same shape once more, in a group placed by a mirroring, shearing
    // free (axis scales, then a rotation) transform.
    Shape grouped = scene.shapes[shape];
    grouped.in_group = true;
    scene.shapes.push_back(grouped);
    scene.groups.push_back({"g", {shape + 1}});
    const mat4 place = glm::translate(mat4(1.0f), vec3(0.1f, 0.2f, 0.3f)) *
                       glm::rotate(mat4(1.0f), 0.9f, vec3(0.3f, 1.0f, -0.2f)) *
                       glm::scale(mat4(1.0f), vec3(-2.0f, 0.5f, 1.5f));
    scene.instances.push_back({0, place, "mirrored"});
    const CompiledScene compiled(std::move(scene));
    const vec2 bary(0.3f, 0.2f);
    const Surfel world = resolve_at(compiled, shape, 0, bary);
    expect_orthonormal(world.frame);
    expect_near(world.frame.s, a, 1e-6f, std::string(c.name) + ": s");
    expect_near(world.frame.t, b, 1e-6f, std::string(c.name) + ": t");
    const Surfel placed = resolve_at(compiled, shape + 1, 0, bary, 0);
    expect_orthonormal(placed.frame);
    expect_near(placed.frame.s, glm::normalize(mat3(place) * a), 1e-5f, std::string(c.name) + ", placed: s");
    expect_near(placed.frame.t, glm::normalize(mat3(place) * b), 1e-5f, std::string(c.name) + ", placed: t");
  }
}

TEST(TangentFrame, VanishingTangentFallsBackToTheNormalsFrame) {
  Scene scene = scene_with(quad(vec3(0.0f), vec3(1, 0, 0), vec3(0, 1, 0)));
  for (vec4& t : scene.shapes.back().mesh.tangents) t = vec4(0.0f, 0.0f, 1.0f, 1.0f);  // along the normal
  const CompiledScene compiled(std::move(scene));
  const Surfel s = resolve_at(compiled, static_cast<std::uint32_t>(compiled.scene().shapes.size() - 1), 0,
                              vec2(0.2f, 0.3f));
  const Frame expected(s.frame.n);
  EXPECT_EQ(s.frame.s, expected.s);
  EXPECT_EQ(s.frame.t, expected.t);
}

// The same anisotropic metal on two copies of a quad whose texture
// coordinates differ by a 90-degree turn: the highlight turns with them.
TEST(TangentFrame, AnisotropicHighlightTurnsWithTheUvs) {
  TriangleMesh plain = quad(vec3(-1, -1, 0), vec3(2, 0, 0), vec3(0, 2, 0));
  TriangleMesh turned = plain;
  // (u, v) -> (v, 1 - u): dP/du becomes +y and dP/dv -x, the first frame
  // turned by 90 degrees about +z.
  for (vec2& uv : turned.uvs) uv = vec2(uv.y, 1.0f - uv.x);
  Scene scene = builtin_cornell_box();
  DisneyParams brushed;
  brushed.metallic = 1.0f;
  brushed.roughness = 0.4f;
  brushed.anisotropic = 0.9f;
  scene.materials.push_back(disney_material(brushed));
  for (TriangleMesh* m : {&plain, &turned}) {
    Shape shape;
    shape.description = "brushed quad";
    shape.material = static_cast<std::uint32_t>(scene.materials.size() - 1);
    shape.mesh = std::move(*m);
    scene.shapes.push_back(std::move(shape));
  }
  add_needed_tangents(&scene);  // what the scene loader does
  const auto first = static_cast<std::uint32_t>(scene.shapes.size() - 2);
  ASSERT_FALSE(scene.shapes[first].mesh.tangents.empty());
  const CompiledScene compiled(std::move(scene));
  const Surfel sa = resolve_at(compiled, first, 0, vec2(0.3f, 0.3f));
  const Surfel sb = resolve_at(compiled, first + 1, 0, vec2(0.3f, 0.3f));
  const mat3 turn(glm::rotate(mat4(1.0f), 0.5f * kPi, vec3(0, 0, 1)));
  float largest_change = 0.0f;
  for (const float phi_o : {0.0f, 0.4f, 1.3f})
    for (const float phi_i : {0.2f, 2.0f, 3.3f, 4.5f}) {
      const vec3 wo(0.6f * std::cos(phi_o), 0.6f * std::sin(phi_o), 0.8f);
      const vec3 wi(0.8f * std::cos(phi_i), 0.8f * std::sin(phi_i), 0.6f);
      const Spectrum fa = sa.eval(wi, wo), fb_turned = sb.eval(turn * wi, turn * wo), fb = sb.eval(wi, wo);
      ASSERT_GT(fa.x, 0.0f);
      EXPECT_NEAR(fb_turned.x / fa.x, 1.0f, 1e-4f) << phi_o << " " << phi_i;
      largest_change = std::max(largest_change, std::abs(fb.x / fa.x - 1.0f));
    }
  EXPECT_GT(largest_change, 0.5f) << "the highlight did not turn with the texture coordinates";
}

class TangentLoading : public test::TempDirTest {};

TEST_F(TangentLoading, ComputedOnlyForUvMeshesWithAnAnisotropicMaterial) {
  std::ofstream(dir_ / "quad.ply") << "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                                      "property float z\nproperty float u\nproperty float v\nelement face 2\n"
                                      "property list uchar int vertex_indices\nend_header\n"
                                      "0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 1\n3 0 1 2\n3 0 2 3\n";
  std::ofstream(dir_ / "scene.json") << R"({
    "pathlab_scene": 1,
    "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "fov_y": 40},
    "materials": {
      "brushed": {"type": "disney", "metallic": 1, "anisotropic": 0.5},
      "polished": {"type": "disney", "metallic": 1},
      "lamp": {"type": "emissive", "radiance": [1, 1, 1]}
    },
    "shapes": [
      {"type": "mesh", "file": "quad.ply", "material": "brushed", "transform": {"rotate": {"axis": [1, 0, 0], "angle": 90}}},
      {"type": "mesh", "file": "quad.ply", "material": "polished"},
      {"type": "rectangle", "material": "brushed"},
      {"type": "rectangle", "material": "lamp", "transform": {"translate": [0, 0, 3]}}
    ]
  })";
  const Scene scene = load_scene(dir_ / "scene.json");
  ASSERT_EQ(scene.shapes[0].mesh.tangents.size(), 4u);
  // Computed after the transform: dP/du is still +x, in the moved mesh.
  for (const vec4& t : scene.shapes[0].mesh.tangents) expect_near(vec3(t), vec3(1, 0, 0), 1e-6f);
  EXPECT_TRUE(scene.shapes[1].mesh.tangents.empty());  // isotropic: nothing needs them
  EXPECT_TRUE(scene.shapes[2].mesh.tangents.empty());  // no texture coordinates: Frame(n) as before
}

}  // namespace
}  // namespace pathlab
