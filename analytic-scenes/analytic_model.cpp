#include "analytic-scenes/analytic_model.h"

#include "analytic-scenes/models.h"
#include "analytic-scenes/room.h"
#include "core/error.h"
#include "core/json_document.h"

namespace pathlab {
namespace {

using Factory = std::unique_ptr<AnalyticModel> (*)(const Scene&);
struct Entry {
  std::string_view name;
  Factory make;
};
constexpr Entry kModels[] = {
    {"furnace", analytic::make_furnace},
    {"sphere-in-uniform-light", analytic::make_sphere_in_uniform_light},
    {"penumbra", analytic::make_penumbra},
    {"rough-sphere-in-environment", analytic::make_rough_sphere_in_environment},
    {"glass-sphere-in-environment", analytic::make_glass_sphere_in_environment},
    {"textured-room", analytic::make_textured_room},
};

}  // namespace

std::vector<std::string_view> analytic_model_names() {
  std::vector<std::string_view> names;
  for (const Entry& e : kModels) names.push_back(e.name);
  return names;
}

std::unique_ptr<AnalyticModel> make_analytic_model(const Scene& scene) {
  if (scene.analytic.empty())
    analytic::refuse(scene, "(none)", "the scene names no analytic model (add \"analytic\": \"<model>\")");
  for (const Entry& e : kModels)
    if (scene.analytic == e.name) {
      if (scene.camera.aperture_radius > 0.0f)
        analytic::refuse(scene, e.name, "the expected image is computed for a pinhole camera; set aperture_radius 0");
      // The models read the shapes in world space.
      if (!scene.groups.empty() || !scene.instances.empty())
        analytic::refuse(scene, e.name, "the models read shapes placed in world space; remove \"groups\" and \"instances\"");
      return e.make(scene);
    }
  const auto names = analytic_model_names();
  const std::string near = nearest_name(scene.analytic, names);
  std::string list;
  for (std::string_view n : names) list += (list.empty() ? "" : ", ") + std::string(n);
  analytic::refuse(scene, scene.analytic,
                   "unknown model" + (near.empty() ? " (known: " + list + ")" : " (did you mean '" + near + "'?)"));
}

}  // namespace pathlab
