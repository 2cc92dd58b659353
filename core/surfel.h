// A surface hit, resolved: where it is, which way it faces, what it is made
// of. Every tracer talks to materials only through this interface:
//   emitted(wo)        radiance emitted towards wo
//   eval(wi, wo)       f(wi, wo) |cos theta_i|           (0 for impulses)
//   pdf(wi, wo)        solid-angle density of scatter()  (0 for impulses)
//   scatter(wo, u)     a sampled wi with weight = f |cos theta_i| / pdf
// Directions point away from the surface, are unit length and in world space.
#pragma once

#include "core/material.h"
#include "core/math.h"
#include "core/ray.h"
#include "core/scene.h"

#include <cstdint>
#include <optional>

namespace pathlab {

struct BsdfSample {
  vec3 wi;
  Spectrum weight;     // f |cos| / pdf, or reflectance / probability for an impulse
  float pdf = 0.0f;    // solid-angle density; for an impulse, its discrete probability
  Lobe lobe = Lobe::Lambert;
  bool impulse = false;
};

struct Surfel {
  vec3 p;                       // position
  vec3 p_error{0.0f};           // bound on |computed p - true p|, per axis
  vec3 n;                       // unit geometric normal of the front (emitting) side
  Frame frame;                  // shading frame: about n or the interpolated vertex normal; s along the mesh's tangent if it has tangents
  vec2 uv{0.0f};                // the mesh's texture coordinates where it has them, else the barycentrics (b1, b2)
  // True when frame.n is a shading normal that differs from n. Then the
  // shading-normal policy of docs/ARCHITECTURE.md applies: a reflection
  // exists only between directions on the same side of the geometric
  // surface, a transmission only across it; sampled directions on the wrong
  // side are absorbed, and eval() is 0 there.
  bool shading_normal = false;
  const Material* material = nullptr;
  // The material's parameters at this point when it reads textures
  // (CompiledScene::resolve evaluates them into storage the caller owns);
  // null: the material's own constants.
  const SurfaceParams* params = nullptr;
  std::uint32_t shape = 0;      // index into Scene::shapes
  std::uint32_t prim = 0;       // triangle index within the shape (0 for a sphere)
  std::uint32_t instance = kNoInstance;  // index into Scene::instances for a shape in a group

  Spectrum emitted(const vec3& wo) const;
  Spectrum eval(const vec3& wi, const vec3& wo) const;
  float pdf(const vec3& wi, const vec3& wo) const;
  // `u_lobe` chooses among lobes and impulses (and absorption, for an impulse
  // whose reflectance is below 1); `u` samples the direction. Returns nothing
  // if the path is absorbed here (always, on the back of a one-sided
  // material, where eval() and pdf() are 0 too).
  std::optional<BsdfSample> scatter(const vec3& wo, float u_lobe, vec2 u) const;
  // Cosine-weighted sampling of the hemisphere on wo's side, whatever the
  // material (strategy "cosine"); weight = eval / pdf.
  std::optional<BsdfSample> scatter_cosine(const vec3& wo, vec2 u) const;
  // scatter() in the shading frame, before the shading-normal policy.
  std::optional<BsdfSample> scatter_in_frame(const vec3& wo, float u_lobe, vec2 u) const;

  // True if `w` leaves the front side of the geometric surface (a one-sided
  // material reflects only between such directions).
  bool on_front(const vec3& w) const { return glm::dot(w, n) > 0.0f; }

  // A ray leaving this surface in direction `dir`, robustly offset.
  Ray spawn(const vec3& dir) const;
  // A ray from this surface towards `target` (on a surface with normal
  // `target_n` and position error `target_error`), ending just before it.
  Ray spawn_to(const vec3& target, const vec3& target_error, const vec3& target_n) const;
};

}  // namespace pathlab
