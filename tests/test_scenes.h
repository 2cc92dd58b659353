// Small scenes built in code for the tests.
#pragma once

#include "core/scene.h"
#include "core/scene_loader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

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

// A GoogleTest parameter name for a strategy ("light+bsdf" -> "light_bsdf").
inline std::string strategy_test_name(const testing::TestParamInfo<Strategy>& p) {
  std::string s = strategy_name(p.param);
  for (char& c : s)
    if (c == '+') c = '_';
  return s;
}

using pathlab::kAllStrategies;

}  // namespace pathlab::test
