// A scene made ready to trace: the BVH, the light sampler, the camera and the
// set of lobes its materials use. Built once, then shared read-only by every
// thread of every tracer.
#pragma once

#include "core/alpha.h"
#include "core/camera.h"
#include "core/embree_accel.h"
#include "core/geometry.h"
#include "core/huge_pages.h"
#include "core/light_sampler.h"
#include "core/ray_cone.h"
#include "core/scene.h"
#include "core/surfel.h"
#include "core/texture.h"

#include <memory>
#include <span>
#include <vector>

namespace pathlab {

class CompiledScene {
 public:
  // Throws SystemError if Embree fails.
  explicit CompiledScene(Scene scene);
  // The light sampler points into scene_: neither copy nor move.
  CompiledScene(const CompiledScene&) = delete;
  CompiledScene& operator=(const CompiledScene&) = delete;

  const Scene& scene() const { return scene_; }
  const Camera& camera() const { return camera_; }
  const LightSampler& lights() const { return *lights_; }
  // Every lobe any material of the scene uses ("model only what a scene
  // requires": shading may skip the rest).
  LobeMask lobes() const { return lobes_; }
  // True if some shape's material has alpha (Material::has_alpha).
  bool has_alpha() const { return has_alpha_; }
  // The alpha key of the rays leaving `vertex` of the sample `rng` draws for
  // (core/alpha.h), the one both tracers give their camera, continuation and
  // shadow rays; 0 in a scene without alpha, where no filter reads it.
  std::uint32_t alpha_key(const SampleStream& rng, int vertex) const {
    return has_alpha_ ? pathlab::alpha_key(rng, static_cast<std::uint32_t>(vertex)) : 0u;
  }
  // Centre and radius of a sphere bounding all finite geometry.
  vec3 bounds_center() const { return bounds_center_; }
  float bounds_radius() const { return bounds_radius_; }

  // The scene's textures, or null for a scene that reads none (then no
  // texture system exists and no hit pays for one).
  const Textures* textures() const { return textures_.get(); }
  bool has_textures() const { return textures_ != nullptr; }
  // The cone a camera ray starts with (core/ray_cone.h): one pixel's spread
  // when the scene has textures and `filter` is cone; zero otherwise (the
  // finest level, and no cone arithmetic).
  RayCone camera_cone(TextureFilter filter) const {
    if (!textures_ || filter != TextureFilter::Cone) return {};
    return {0.0f, pixel_spread_angle(scene_.camera.fov_y_degrees, scene_.film.height)};
  }

  // The first surface along `ray`, resolved into a Surfel. False if the ray
  // escapes. `cone` and `params`: see resolve().
  bool intersect(const Ray& ray, Surfel* surfel, const RayCone& cone = {}, SurfaceParams* params = nullptr) const;
  bool occluded(const Ray& ray) const { return accel_->occluded(ray); }

  // Many rays at once (see EmbreeAccel::intersect_batch for `mode` and
  // `coherent`); the results equal those of intersect() / occluded() ray by
  // ray. Hits come back unresolved: resolve() turns the ones a caller needs
  // into Surfels.
  void intersect_batch(std::span<const Ray> rays, std::span<RayHit> hits, std::span<std::uint8_t> found,
                       RayBatchMode mode, bool coherent = false) const {
    accel_->intersect_batch(rays, hits, found, mode, coherent);
  }
  void occluded_batch(std::span<const Ray> rays, std::span<std::uint8_t> occluded, RayBatchMode mode,
                      bool coherent = false) const {
    accel_->occluded_batch(rays, occluded, mode, coherent);
  }
  void intersect_arrays(const RayArrays& rays, std::size_t n, const HitArrays& hits, RayBatchMode mode,
                        bool coherent = false) const {
    accel_->intersect_arrays(rays, n, hits, mode, coherent);
  }
  void occluded_arrays(const RayArrays& rays, std::size_t n, std::uint8_t* occluded, RayBatchMode mode,
                       bool coherent = false) const {
    accel_->occluded_arrays(rays, n, occluded, mode, coherent);
  }
  // The Surfel of a hit `ray` found, in world space (a hit on a shape in a
  // group is resolved in the group's space, then placed by its instance).
  // A hit on a material that reads textures reads them here, with the
  // footprint of `cone` (the cone `ray` carries from its origin; a zero cone
  // reads the finest level): a normal map tilts the shading frame, and
  // textured parameters are evaluated into `*params`, which the Surfel then
  // points to (Surfel::params; the caller keeps it alive as long as the
  // Surfel). Without `params` the Surfel reads the material's constants.
  void resolve(const Ray& ray, const RayHit& hit, Surfel* surfel, const RayCone& cone = {},
               SurfaceParams* params = nullptr) const;
  // resolve() of a hit on a shape placed in world space (no instance) whose
  // point, error bound and geometric normal `surfel` already holds, as
  // resolve() computes them (the wavefront's lanes make them): the rest - its
  // texture coordinates, shading frame, material - but no texture read.
  void resolve_shading(const RayHit& hit, Surfel* surfel) const;
  // Every shape's triangles as resolve() reads them, one shape after the
  // other: triangle k of shape s is triangles()[first_triangle(s) + k]
  // (a sphere has none). A shape in a group has its triangles in the
  // group's space, stored once however many instances place it.
  std::span<const Triangle> triangles() const { return triangles_; }
  std::size_t first_triangle(std::uint32_t shape) const { return first_triangle_[shape]; }
  // Starts loading what resolve() will read for a hit on triangle `prim`
  // of shape `shape` into the cache (both lines a Triangle may straddle).
  void prefetch(std::uint32_t shape, std::uint32_t prim) const {
    const std::size_t t = first_triangle_[shape] + prim;
    if (t >= first_triangle_[shape + 1]) return;
    __builtin_prefetch(&triangles_[t].p0);
    __builtin_prefetch(&triangles_[t].n);
  }
  void prefetch(const RayHit& hit) const { prefetch(hit.shape, hit.prim); }
  // An instance's transforms, as resolve() applies them.
  struct Placement {
    mat4 to_world;
    mat4 to_local;     // its inverse
    mat3 to_normal;    // the inverse transpose of to_world's linear part
    bool mirrors;      // to_world's linear part has a negative determinant (a mesh's tangents' handedness turns)
  };
  // Per instance (Scene::instances), in order.
  std::span<const Placement> placements() const { return placements_; }

 private:
  // The shading frame, shading_normal, material and hit identity of a Surfel
  // whose point and geometric normal are placed in world space (the generic
  // surface_frame, core/simd/shading_frame-inl.h, at width 1).
  void shading_frame(const Shape& shape, const RayHit& hit, Surfel* s) const;
  // resolve()'s texture reads for a material with textures or a normal map.
  void read_textures(const Shape& shape, const Ray& ray, const RayHit& hit, const RayCone& cone,
                     SurfaceParams* params, Surfel* s) const;

  Scene scene_;
  std::vector<Placement> placements_;  // per instance
  Camera camera_;
  std::unique_ptr<EmbreeAccel> accel_;
  std::unique_ptr<Textures> textures_;  // before lights_, which reads emission textures
  std::unique_ptr<LightSampler> lights_;
  HugePageVector<Triangle> triangles_;        // every shape's, in shape order (read at random: huge pages)
  std::vector<std::size_t> first_triangle_;  // per shape, and one past the last
  LobeMask lobes_ = 0;
  bool has_alpha_ = false;
  vec3 bounds_center_{0.0f};
  float bounds_radius_ = 1.0f;
};

}  // namespace pathlab
