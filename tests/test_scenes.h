// Small scenes built in code for the tests.
#pragma once

#include "core/scene.h"
#include "core/scene_loader.h"
#include "tests/temp_dir.h"
#include "tests/texture_util.h"

#include <glm/gtc/matrix_transform.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <string>
#include <vector>

namespace pathlab::test {

// Inside a closed sphere of radius 1 (normals facing in) whose surface
// emits `Le` and reflects with Lambert albedo `rho`; camera at the centre.
inline Scene furnace_scene(float Le, float rho, int max_depth, int rr_depth, Strategy strategy, int res = 8) {
  const std::string text = R"({
    "pathlab_scene": 1,
    "camera": {"position": [0, 0, 0], "look_at": [0, 0, 1], "fov_y": 60},
    "film": {"resolution": [)" + std::to_string(res) + ", " + std::to_string(res) + R"(]},
    "materials": {"room": {"type": "diffuse", "albedo": )" + std::to_string(rho) + R"(, "emission": )" +
                           std::to_string(Le) + R"(}},
    "shapes": [{"type": "sphere", "radius": 1, "material": "room", "flip_normals": true}]
  })";
  Scene scene = parse_scene(text, "furnace.json");
  scene.render.max_depth = max_depth;
  scene.render.rr_depth = rr_depth;
  scene.render.strategy = strategy;
  return scene;
}

inline Scene small_cornell(int res, int spp, FilterKind filter) {
  Scene scene = builtin_cornell_box();
  scene.film.width = res;
  scene.film.height = res;
  scene.film.filter = filter;
  scene.render.spp = spp;
  return scene;
}

// A UV sphere of `rings` x 2 `rings` quads (two triangles each) about
// `center`, with its exact unit normals as vertex normals (or none when
// `normals` is false): the smooth-shading test object.
inline TriangleMesh uv_sphere(vec3 center, float radius, int rings, bool normals = true) {
  TriangleMesh m;
  const int segments = 2 * rings;
  for (int i = 0; i <= rings; ++i) {
    const double theta = 3.141592653589793 * i / rings;
    for (int j = 0; j <= segments; ++j) {
      const double phi = 2.0 * 3.141592653589793 * j / segments;
      const dvec3 n(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
      m.positions.push_back(center + radius * vec3(n));
      if (normals) m.normals.push_back(vec3(n));
    }
  }
  const auto at = [&](int i, int j) { return static_cast<unsigned>(i * (segments + 1) + j); };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      // Counter-clockwise seen from outside.
      if (i > 0) m.triangles.push_back({at(i, j), at(i, j + 1), at(i + 1, j)});
      if (i + 1 < rings) m.triangles.push_back({at(i, j + 1), at(i + 1, j + 1), at(i + 1, j)});
    }
  return m;
}

// The tessellation angle of a mesh inscribed in the sphere about `c`: the
// largest angle between a face normal and the exact normal (p - c) / |p - c|
// of one of its vertices (the bound of test_tessellated_sphere.cpp).
inline double tessellation_angle(const TriangleMesh& mesh, const dvec3& c) {
  double cos_min = 1.0;
  for (const glm::uvec3& t : mesh.triangles) {
    const dvec3 p0(mesh.positions[t.x]), p1(mesh.positions[t.y]), p2(mesh.positions[t.z]);
    const dvec3 g = glm::normalize(glm::cross(p1 - p0, p2 - p0));
    for (const dvec3& p : {p0, p1, p2}) cos_min = std::min(cos_min, glm::dot(g, glm::normalize(p - c)));
  }
  return std::acos(cos_min);
}

// The built-in Cornell box with a smooth-shaded UV sphere on its floor
// (material "white", 24 rings): the smooth scene of the same-path tests.
inline Scene cornell_with_smooth_sphere() {
  Scene scene = builtin_cornell_box();
  Shape sphere;
  sphere.description = "smooth UV sphere";
  sphere.material = scene.shapes.front().material;
  sphere.mesh = uv_sphere(vec3(-0.3f, -0.6f, 0.2f), 0.4f, 24);
  scene.shapes.push_back(std::move(sphere));
  return scene;
}

// The built-in Cornell box (open towards the camera at +z) lit also by a
// point, a spot and a directional light that comes in through the opening.
inline Scene cornell_with_delta_lights() {
  Scene scene = builtin_cornell_box();
  scene.delta_lights.push_back({vec3(0.4f, 0.7f, 0.3f), Spectrum(0.3f, 0.2f, 0.1f)});
  DeltaLight spot{vec3(-0.5f, 0.8f, 0.5f), Spectrum(2.0f)};
  spot.kind = DeltaLight::Kind::Spot;
  spot.direction = glm::normalize(vec3(0.3f, -1.0f, -0.4f));
  spot.cos_outer = std::cos(0.6f);
  spot.cos_inner = std::cos(0.3f);
  scene.delta_lights.push_back(spot);
  DeltaLight sun{vec3(0.0f), Spectrum(1.0f, 0.9f, 0.7f)};
  sun.kind = DeltaLight::Kind::Directional;
  sun.direction = glm::normalize(vec3(0.2f, -0.6f, -1.0f));
  scene.delta_lights.push_back(sun);
  return scene;
}

// An emitting triangle with its own emissive material (radiance `Le`,
// `two_sided`), front side counter-clockwise, appended to `scene`.
inline void add_light_triangle(Scene& scene, const vec3& p0, const vec3& p1, const vec3& p2, float Le,
                               bool two_sided = false) {
  Material m{"lamp" + std::to_string(scene.materials.size()), MaterialType::Emissive, Spectrum(0.0f),
             Spectrum(Le, 0.8f * Le, 0.6f * Le), two_sided};
  scene.materials.push_back(m);
  Shape s;
  s.description = "shapes[" + std::to_string(scene.shapes.size()) + "] (light triangle)";
  s.material = static_cast<std::uint32_t>(scene.materials.size() - 1);
  s.mesh = TriangleMesh({p0, p1, p2}, {glm::uvec3(0, 1, 2)});
  scene.shapes.push_back(std::move(s));
}

// The built-in Cornell box lit by many small lights of unequal power and
// orientation (for the light BVH, render.light_sampler bvh): a 5 x 5 grid
// of triangles under the ceiling facing down, every third two-sided, and
// four more: on the left wall facing the wall, on the right wall facing in, on
// the floor facing up, on the back wall two-sided; besides the box's own lamp.
inline Scene cornell_with_many_lights() {
  Scene scene = builtin_cornell_box();
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j) {
      const float x = -0.8f + 0.4f * static_cast<float>(i), z = -0.8f + 0.4f * static_cast<float>(j);
      const float Le = 2.0f + 6.0f * static_cast<float>((3 * i + 7 * j) % 5);
      const vec3 c(x, 0.9f, z);
      add_light_triangle(scene, c, c + vec3(0.06f, 0.0f, 0.0f), c + vec3(0.0f, 0.0f, 0.06f), Le, (i + j) % 3 == 0);
    }
  add_light_triangle(scene, vec3(-0.99f, 0.2f, 0.0f), vec3(-0.99f, 0.2f, 0.15f), vec3(-0.99f, 0.35f, 0.0f), 12.0f);
  add_light_triangle(scene, vec3(0.99f, -0.3f, 0.2f), vec3(0.99f, -0.3f, 0.35f), vec3(0.99f, -0.15f, 0.2f), 8.0f);
  add_light_triangle(scene, vec3(0.2f, -0.98f, 0.6f), vec3(0.35f, -0.98f, 0.6f), vec3(0.2f, -0.98f, 0.45f), 5.0f);
  add_light_triangle(scene, vec3(-0.5f, 0.3f, -0.99f), vec3(-0.35f, 0.3f, -0.99f), vec3(-0.5f, 0.45f, -0.99f), 9.0f, true);
  return scene;
}

// Three placements that exercise every part of an instance transform:
// rotated and moved; mirrored with a non-uniform scale; sheared. They put a
// unit-sized group inside the built-in Cornell box ([-1, 1]^3).
inline std::vector<mat4> instance_placements() {
  const mat4 turned = glm::translate(mat4(1.0f), vec3(-0.45f, -0.7f, 0.35f)) *
                      glm::rotate(mat4(1.0f), 0.6f, glm::normalize(vec3(0.3f, 1.0f, 0.2f))) *
                      glm::scale(mat4(1.0f), vec3(0.22f));
  const mat4 mirrored = glm::translate(mat4(1.0f), vec3(0.45f, -0.55f, -0.25f)) *
                        glm::scale(mat4(1.0f), vec3(-0.3f, 0.18f, 0.24f));
  mat4 sheared = glm::scale(mat4(1.0f), vec3(0.16f));
  sheared[1][0] = 0.08f;  // x += 0.5 y (column-major: column 1, row 0)
  sheared[3] = vec4(0.1f, 0.25f, 0.3f, 1.0f);
  return {turned, mirrored, sheared};
}

// The built-in Cornell box with a group - a smooth UV sphere (unit radius,
// 16 rings) and a true sphere beside it - placed by instance_placements():
// the instanced scene of the same-path tests.
inline Scene cornell_with_instances() {
  Scene scene = builtin_cornell_box();
  const std::uint32_t white = scene.shapes.front().material;
  ShapeGroup group{"pair", {}};
  Shape ball;
  ball.description = "groups/pair[0] (smooth UV sphere)";
  ball.material = white;
  ball.mesh = uv_sphere(vec3(0.0f), 1.0f, 16);
  Shape bead;
  bead.kind = Shape::Kind::Sphere;
  bead.description = "groups/pair[1] (sphere)";
  bead.material = white;
  bead.center = vec3(1.6f, -0.5f, 0.0f);
  bead.radius = 0.5f;
  for (Shape* s : {&ball, &bead}) {
    s->in_group = true;
    group.shapes.push_back(static_cast<std::uint32_t>(scene.shapes.size()));
    scene.shapes.push_back(std::move(*s));
  }
  scene.groups.push_back(std::move(group));
  int k = 0;
  for (const mat4& m : instance_placements())
    scene.instances.push_back({0, m, "instances[" + std::to_string(k++) + "] (pair)"});
  return scene;
}

// cornell_with_instances() with partial coverage (core/alpha.h): the
// group's UV sphere at alpha 0.5 (so inside three instances) and the tall
// box, placed in world space, at alpha 0.3; the group's true sphere stays
// opaque (spheres take no alpha). The alpha scene of the same-path tests.
inline Scene cornell_with_alpha() {
  Scene scene = cornell_with_instances();
  const auto add = [&](const char* name, float alpha) {
    Material m = scene.materials[scene.shapes.front().material];
    m.name = name;
    m.alpha = alpha;
    scene.materials.push_back(m);
    return static_cast<std::uint32_t>(scene.materials.size() - 1);
  };
  scene.shapes[scene.groups[0].shapes[0]].material = add("leaf", 0.5f);
  scene.shapes[6].material = add("lace", 0.3f);  // the tall box
  return scene;
}

// A GoogleTest parameter name for a strategy ("light+bsdf" -> "light_bsdf").
inline std::string strategy_test_name(const testing::TestParamInfo<Strategy>& p) {
  std::string s = strategy_name(p.param);
  for (char& c : s)
    if (c == '+') c = '_';
  return s;
}

using pathlab::kAllStrategies;

// A Cornell box that reads textures everywhere it can: sRGB noise on the
// walls (cone-filtered, wrapped), a Disney box with textured base colour,
// roughness and metallic, a normal-mapped floor, a textured mirror, a
// textured emissive light and a textured diffuse sphere. Its images live in
// a folder that lasts as long as the test process.
// With textured_impulses, the mirror has a normal map too and the ball is
// glass whose tints are textures, under a normal map.
// The folder of the textured scenes' images (written once per test process).
inline const std::filesystem::path& textured_scene_dir() {
  static const ScopedTempDir dir("textured-scenes");
  const std::filesystem::path& d = dir.path();
  if (!std::filesystem::exists(d / "noise.png")) {
    std::mt19937 gen(3);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<float> noise(64 * 64 * 3), data(32 * 32 * 4), normals(32 * 32 * 3), light(8 * 8 * 3);
    for (float& v : noise) v = u(gen);
    for (float& v : data) v = u(gen);
    for (std::size_t i = 0; i < 32 * 32; ++i) {  // tilts up to ~35 degrees
      const float x = 0.3f * (u(gen) - 0.5f), y = 0.3f * (u(gen) - 0.5f);
      normals[3 * i] = 0.5f + x, normals[3 * i + 1] = 0.5f + y, normals[3 * i + 2] = 0.5f + 0.5f * std::sqrt(1.0f - 4.0f * (x * x + y * y));
    }
    for (float& v : light) v = 0.2f + u(gen);
    write_image(d / "noise.png", 64, 64, 3, noise, OIIO::TypeDesc::UINT8);
    write_image(d / "data.png", 32, 32, 4, data, OIIO::TypeDesc::UINT8);
    write_image(d / "normals.exr", 32, 32, 3, normals);
    write_image(d / "light.exr", 8, 8, 3, light);
  }
  return d;
}

// The textured scenes' camera, film, render settings and textured walls.
inline constexpr const char* kTexturedCornellHead = R"({"pathlab_scene": 1,
  "camera": {"position": [0, 0, 3.75], "look_at": [0, 0, 0], "fov_y": 40},
  "film": {"resolution": [32, 32]},
  "render": {"spp": 4, "max_depth": 6, "rr_depth": 3},
  "materials": {
    "walls": {"type": "diffuse", "albedo": {"texture": "noise.png", "scale": 0.9, "wrap": "mirror"}},)";

inline Scene cornell_with_textures(bool textured_impulses = false) {
  const std::filesystem::path& d = textured_scene_dir();
  const std::string text = std::string(kTexturedCornellHead) + R"(
    "floor": {"type": "diffuse", "albedo": [0.7, 0.7, 0.6], "normal_map": {"texture": "normals.exr", "scale": 0.8}},
    "red": {"type": "diffuse", "albedo": {"texture": "noise.png", "scale": [0.8, 0.1, 0.1]}},
    "disney": {"type": "disney", "base_color": {"texture": "noise.png"}, "roughness": {"texture": "data.png", "channel": 1},
               "metallic": {"texture": "data.png", "channel": 2}, "clearcoat": {"texture": "data.png", "channel": 3, "scale": 0.5}},
    "mirror": {"type": "mirror", "reflectance": {"texture": "noise.png", "offset": 0.2, "scale": 0.7}},
    "ball": {"type": "diffuse", "albedo": {"texture": "noise.png", "wrap": "clamp"}},
    "light": {"type": "emissive", "radiance": {"texture": "light.exr", "scale": [17, 12, 4], "colorspace": "linear"}}
  },
  "shapes": [
    {"type": "rectangle", "material": "floor", "transform": [{"rotate": {"axis": [1, 0, 0], "angle": -90}}, {"translate": [0, -1, 0]}]},
    {"type": "rectangle", "material": "walls", "transform": [{"rotate": {"axis": [1, 0, 0], "angle": 90}}, {"translate": [0, 1, 0]}]},
    {"type": "rectangle", "material": "walls", "transform": [{"scale": 1.0}, {"translate": [0, 0, -1]}]},
    {"type": "rectangle", "material": "red", "transform": [{"rotate": {"axis": [0, 1, 0], "angle": 90}}, {"translate": [-1, 0, 0]}]},
    {"type": "rectangle", "material": "mirror", "transform": [{"rotate": {"axis": [0, 1, 0], "angle": -90}}, {"translate": [1, 0, 0]}]},
    {"type": "box", "material": "disney", "transform": [{"scale": 0.3}, {"rotate": {"axis": [0, 1, 0], "angle": -17}}, {"translate": [0.35, -0.7, 0.35]}]},
    {"type": "sphere", "material": "ball", "center": [-0.4, -0.5, -0.2], "radius": 0.45},
    {"type": "rectangle", "material": "light", "transform": [{"scale": [0.25, 0.2, 1]}, {"rotate": {"axis": [1, 0, 0], "angle": 90}}, {"translate": [0, 0.998, 0]}]}
  ]})";
  if (!textured_impulses) return parse_scene(text, d / "textured-cornell.json");
  std::string impulses = text;
  const auto replace = [&](const std::string& from, const std::string& to) {
    impulses.replace(impulses.find(from), from.size(), to);
  };
  replace(R"("offset": 0.2, "scale": 0.7}},)",
          R"("offset": 0.2, "scale": 0.7}, "normal_map": {"texture": "normals.exr"}},)");
  replace(R"("ball": {"type": "diffuse", "albedo": {"texture": "noise.png", "wrap": "clamp"}},)",
          R"("ball": {"type": "dielectric", "ior": 1.4, "reflectance": {"texture": "noise.png", "offset": 0.5, "scale": 0.5},
               "transmittance": {"texture": "data.png", "scale": 0.8, "offset": 0.2}, "normal_map": {"texture": "normals.exr"}},)");
  return parse_scene(impulses, d / "textured-impulses-cornell.json");
}

// Textured shapes of every kind whose hits the wavefront's lanes resolve
// themselves (ShapeField kTexturedHits), core reading only the texels: a tent without texture coordinates (the
// barycentrics are), a smooth octahedron with vertex normals and its own
// coordinates in world space, and the same octahedron and a normal-mapped
// sphere in a group placed twice (turned; mirrored with a non-uniform
// scale), in Lambert and Disney materials under a textured light and an
// environment (so that paths a shading normal sends below a surface still
// carry light); normal maps on the floor (a flat rectangle), the red wall
// and the world-space octahedron (vertex normals); a glowing sphere that
// scatters and emits, both by textures; and a small octahedron of the
// textured light (vertex normals on an emitter that scatters nothing).
inline Scene cornell_with_textured_meshes() {
  const std::filesystem::path& d = textured_scene_dir();
  if (!std::filesystem::exists(d / "gem.obj")) {
    std::ofstream tent(d / "tent.obj");
    tent << "v -0.9 -1 0.2\nv -0.1 -1 0.2\nv -0.5 -0.2 -0.3\nv -0.5 -1 -0.8\nf 1 2 3\nf 2 4 3\nf 4 1 3\n";
    std::ofstream gem(d / "gem.obj");
    gem << "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n";
    gem << "vn 0.9 0.3 0.3\nvn -0.9 0.3 -0.3\nvn 0.3 0.9 0.3\nvn -0.3 -0.9 0.3\nvn 0.3 0.3 0.9\nvn -0.3 0.3 -0.9\n";
    gem << "vt 0.1 0.2\nvt 0.9 0.1\nvt 0.5 0.95\nvt 0.4 0.05\nvt 0.7 0.6\nvt 0.2 0.7\n";
    for (const char* f : {"1 3 5", "3 2 5", "2 4 5", "4 1 5", "3 1 6", "2 3 6", "4 2 6", "1 4 6"}) {
      int a, b, c;
      std::sscanf(f, "%d %d %d", &a, &b, &c);
      gem << "f " << a << "/" << a << "/" << a << " " << b << "/" << b << "/" << b << " " << c << "/" << c << "/" << c << "\n";
    }
  }
  const std::string text = std::string(kTexturedCornellHead) + R"(
    "red": {"type": "diffuse", "albedo": {"texture": "noise.png", "scale": [0.8, 0.1, 0.1], "wrap": "clamp"},
            "normal_map": {"texture": "normals.exr", "scale": 1.3}},
    "disney": {"type": "disney", "base_color": {"texture": "noise.png"}, "roughness": {"texture": "data.png", "channel": 1},
               "metallic": {"texture": "data.png", "channel": 2}, "sheen": {"texture": "data.png", "channel": 0}},
    "bumps": {"type": "diffuse", "albedo": [0.6, 0.6, 0.5], "normal_map": {"texture": "normals.exr", "scale": 0.9}},
    "glow": {"type": "diffuse", "albedo": {"texture": "noise.png", "scale": 0.6},
             "emission": {"texture": "light.exr", "scale": [1.5, 0.8, 0.3], "colorspace": "linear"}},
    "light": {"type": "emissive", "radiance": {"texture": "light.exr", "scale": [17, 12, 4], "colorspace": "linear"}}
  },
  "shapes": [
    {"type": "rectangle", "material": "bumps", "transform": [{"rotate": {"axis": [1, 0, 0], "angle": -90}}, {"translate": [0, -1, 0]}]},
    {"type": "rectangle", "material": "walls", "transform": [{"scale": 1.0}, {"translate": [0, 0, -1]}]},
    {"type": "rectangle", "material": "red", "transform": [{"rotate": {"axis": [0, 1, 0], "angle": 90}}, {"translate": [-1, 0, 0]}]},
    {"type": "mesh", "file": "tent.obj", "material": "disney"},
    {"type": "mesh", "file": "gem.obj", "material": "red", "transform": [{"scale": 0.3}, {"translate": [0.5, 0.4, 0.0]}]},
    {"type": "sphere", "material": "glow", "center": [0.55, -0.75, 0.45], "radius": 0.2},
    {"type": "mesh", "file": "gem.obj", "material": "light", "transform": [{"scale": 0.12}, {"translate": [-0.6, 0.45, -0.5]}]},
    {"type": "rectangle", "material": "light", "transform": [{"scale": [0.25, 0.2, 1]}, {"rotate": {"axis": [1, 0, 0], "angle": 90}}, {"translate": [0, 0.998, 0]}]}
  ],
  "lights": [{"type": "environment", "radiance": [0.3, 0.35, 0.4]}],
  "groups": {"gems": [{"type": "mesh", "file": "gem.obj", "material": "disney"},
                      {"type": "sphere", "material": "red", "center": [0, 2.2, 0], "radius": 0.9}]},
  "instances": [
    {"group": "gems", "transform": [{"scale": 0.22}, {"rotate": {"axis": [0.3, 1, 0.2], "angle": 34}}, {"translate": [-0.45, -0.7, 0.35]}]},
    {"group": "gems", "transform": [{"scale": [-0.3, 0.18, 0.24]}, {"translate": [0.45, -0.55, -0.25]}]}
  ]})";
  return parse_scene(text, d / "textured-meshes-cornell.json");
}

}  // namespace pathlab::test
