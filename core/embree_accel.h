// The Embree 3 BVH over a scene's shapes: triangle meshes as Embree
// triangles, spheres as Embree's true (analytic) spheres. Embree geometry ID
// equals the shape index. This is the only file that includes Embree.
#pragma once

#include "core/ray.h"
#include "core/scene.h"

#include <cstdint>
#include <memory>
#include <span>
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

  // The same queries for many rays at once, through Embree's ray streams
  // (rtcIntersect1M / rtcOccluded1M): found[i] / occluded[i] is 0 or 1.
  // This pair is the one place to change for Embree 4, which has no streams.
  void intersect_stream(std::span<const Ray> rays, std::span<RayHit> hits, std::span<std::uint8_t> found) const;
  void occluded_stream(std::span<const Ray> rays, std::span<std::uint8_t> occluded) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pathlab
