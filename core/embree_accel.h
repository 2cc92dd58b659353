// The Embree 3 BVH over a scene's shapes: triangle meshes as Embree
// triangles, spheres as Embree's true (analytic) spheres. Embree geometry ID
// equals the shape index. This is the only file that includes Embree.
#pragma once

#include "core/ray.h"
#include "core/scene.h"

#include <cstdint>
#include <memory>
#include <string>

namespace pathlab {

struct RayHit {
  float t = 0.0f;
  std::uint32_t shape = 0;
  std::uint32_t prim = 0;
  vec2 uv{0.0f};  // Embree's barycentrics (b1, b2) for a triangle
};

class EmbreeAccel {
 public:
  // Builds the BVH. Throws SystemError with Embree's message if the device
  // or the build fails. `shapes` must outlive nothing: data is copied.
  explicit EmbreeAccel(const std::vector<Shape>& shapes);
  ~EmbreeAccel();
  EmbreeAccel(const EmbreeAccel&) = delete;
  EmbreeAccel& operator=(const EmbreeAccel&) = delete;

  // Closest hit with t in (0, ray.tmax).
  bool intersect(const Ray& ray, RayHit* hit) const;
  // True if anything lies on the ray with t in (0, ray.tmax).
  bool occluded(const Ray& ray) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pathlab
