// Running `pathlab check` at library level, for tests.
#pragma once

#include "analytic-scenes/analytic_model.h"
#include "analytic-scenes/check.h"
#include "analytic-scenes/expected_image.h"
#include "core/compiled_scene.h"
#include "core/render.h"
#include "core/scene_loader.h"
#include "reference/reference_tracer.h"

#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <optional>

namespace pathlab::test {

inline std::filesystem::path analytic_scene(const std::string& name) {
  return std::filesystem::path(PATHLAB_SOURCE_DIR) / "analytic-scenes" / name;
}

// A gtest parameter name for an analytic check: "penumbra_box_mis_wavefront",
// "..._solid_angle" under solid-angle light sampling.
inline std::string analytic_case_name(const std::string& scene, Strategy strategy, bool wavefront,
                                      LightSampling light_sampling) {
  std::string s = scene.substr(0, scene.size() - 5) + "_" + strategy_name(strategy) +
                  (wavefront ? "_wavefront" : "_reference") +
                  (light_sampling == LightSampling::SolidAngle ? "_solid_angle" : "");
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return s;
}

inline std::vector<std::string> analytic_scene_names() {
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(std::filesystem::path(PATHLAB_SOURCE_DIR) / "analytic-scenes"))
    if (e.path().extension() == ".json") names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// Renders `scene` with the reference tracer (or `TracerT`) and checks it
// against its model (or against `expected`, an expected image of the same
// model, camera and film computed before); on failure, writes the check's
// images into `failure_dir` if given.
template <typename TracerT = ReferenceTracer>
CheckResult run_check(Scene scene, const std::filesystem::path& failure_dir = {},
                      const ExpectedImage* expected = nullptr) {
  const auto model = make_analytic_model(scene);
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  const TracerT tracer(compiled, settings);
  Film film(compiled.scene().film.width, compiled.scene().film.height, compiled.scene().film.filter);
  render(tracer, film);
  const ExpectedImage computed =
      expected ? ExpectedImage{} : expected_image(*model, compiled.camera(), compiled.scene().film);
  const ExpectedImage& e = expected ? *expected : computed;
  CheckResult r = check_against_expected(film, e);
  if (!r.pass && !failure_dir.empty()) write_check_images(failure_dir, film, e, r, {});
  return r;
}

// The expected image `run_check` would compute for `scene`.
inline ExpectedImage expected_image_of(const Scene& scene) {
  const auto model = make_analytic_model(scene);
  const CompiledScene compiled{Scene(scene)};
  return expected_image(*model, compiled.camera(), compiled.scene().film);
}

// PATHLAB_STAT_SCALE multiplies the scenes' sample counts (1 in CI; the
// "long" tests run at 16).
inline int stat_scale() {
  const char* s = std::getenv("PATHLAB_STAT_SCALE");
  return s ? std::max(1, std::atoi(s)) : 1;
}

inline Scene load_with_strategy(const std::string& name, Strategy strategy) {
  Scene scene = load_scene(analytic_scene(name));
  scene.render.strategy = strategy;
  scene.render.spp *= stat_scale();
  return scene;
}

inline CheckResult run_check(const std::string& name, Strategy strategy,
                             const std::filesystem::path& failure_dir = {}) {
  return run_check(load_with_strategy(name, strategy), failure_dir);
}

}  // namespace pathlab::test
