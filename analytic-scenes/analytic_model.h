// Scenes whose right answer is known in closed form. A model reads its
// parameters from the scene itself (materials, shapes, lights, the depth
// cap), refuses a scene that breaks its assumptions, and returns the
// expected radiance along any camera ray. expected_image.h integrates that
// over each pixel's footprint; check.h compares a render with it.
//
// The scene names its model in the top-level key "analytic" (see
// docs/analytic-scenes.md for each model's assumptions).
#pragma once

#include "analytic-scenes/edges.h"
#include "core/math.h"
#include "core/ray.h"
#include "core/scene.h"

#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace pathlab {

class AnalyticModel {
 public:
  virtual ~AnalyticModel() = default;
  virtual std::string_view name() const = 0;
  // Expected radiance arriving at the camera along `ray` (a camera ray of
  // the scene: unit direction, starting at the camera).
  virtual Spectrum radiance(const Ray& ray) const = 0;
  // Every curve across which radiance() may jump, seen from out.eye()
  // (edges.h): expected_image() refines the pixel footprints they cross.
  // Where radiance() is continuous (a penumbra, a bilinear texture) nothing
  // need be listed; what a model cannot list it names with note_unlisted().
  virtual void edges(EdgeList& out) const = 0;
  // One line describing the model's parameters as read from the scene.
  virtual std::string describe() const = 0;
};

// The model named by scene.analytic, built from the scene with its final
// render settings. Throws InputError naming the scene and the broken
// assumption if the scene does not fit the model, or if it names no model
// or an unknown one.
std::unique_ptr<AnalyticModel> make_analytic_model(const Scene& scene);

// Names of the available models.
std::vector<std::string_view> analytic_model_names();

}  // namespace pathlab
