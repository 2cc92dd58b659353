// Small scenes built in code for the tests.
#pragma once

#include "core/scene.h"
#include "core/scene_loader.h"

#include <gtest/gtest.h>

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

// A GoogleTest parameter name for a strategy ("light+bsdf" -> "light_bsdf").
inline std::string strategy_test_name(const testing::TestParamInfo<Strategy>& p) {
  std::string s = strategy_name(p.param);
  for (char& c : s)
    if (c == '+') c = '_';
  return s;
}

using pathlab::kAllStrategies;

}  // namespace pathlab::test
