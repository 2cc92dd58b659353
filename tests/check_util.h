// Running `pathlab check` at library level, for tests.
#pragma once

#include "analytic-scenes/analytic_model.h"
#include "analytic-scenes/check.h"
#include "analytic-scenes/expected_image.h"
#include "core/compiled_scene.h"
#include "core/render.h"
#include "core/scene_loader.h"
#include "reference/reference_tracer.h"

#include <filesystem>
#include <optional>

namespace pathlab::test {

inline std::filesystem::path analytic_scene(const std::string& name) {
  return std::filesystem::path(PATHLAB_SOURCE_DIR) / "analytic-scenes" / name;
}

inline std::vector<std::string> analytic_scene_names() {
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(std::filesystem::path(PATHLAB_SOURCE_DIR) / "analytic-scenes"))
    if (e.path().extension() == ".json") names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// Renders `scene` with the reference tracer and checks it against its model.
inline CheckResult run_check(Scene scene) {
  const auto model = make_analytic_model(scene);
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  const ReferenceTracer tracer(compiled, settings);
  Film film(compiled.scene().film.width, compiled.scene().film.height, compiled.scene().film.filter);
  render(tracer, film);
  return check_against_expected(film, expected_image(*model, compiled.camera(), compiled.scene().film));
}

inline CheckResult run_check(const std::string& name, Strategy strategy, std::optional<int> spp = {}) {
  Scene scene = load_scene(analytic_scene(name));
  scene.render.strategy = strategy;
  if (spp) scene.render.spp = *spp;
  return run_check(std::move(scene));
}

}  // namespace pathlab::test
