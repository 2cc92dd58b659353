// The Embree 3 BVH over a scene's shapes: triangle meshes as Embree
// triangles, spheres as Embree user geometry whose every ray is decided by
// sphere_crossing (core/geometry.h), so that one-ray, packet and stream
// queries give a ray the same hit, bit for bit. Embree geometry ID
// equals the shape index. A group (Scene::groups) is a scene of its own,
// built once (its shapes numbered 0, 1, ... there; hits are given the
// scene's shape index), and each of the scene's instances places it through
// an Embree instance (geometry ID shapes.size() + instance index in the top
// scene).
// Shapes whose material has alpha (Material::has_alpha) get intersection
// and occlusion filters that let a ray through with probability 1 - alpha,
// decided by the ray's alpha_key and the surface (core/alpha.h); every other
// geometry has none, so a scene without alpha traces as before.
// This is the only file that includes Embree.
#pragma once

#include "core/ray.h"
#include "core/scene.h"

#include <cstdint>
#include <memory>
#include <span>
#include <string>

namespace pathlab {

class Textures;

struct RayHit {
  float t = 0.0f;
  std::uint32_t shape = 0;
  std::uint32_t prim = 0;
  vec2 uv{0.0f};  // Embree's barycentrics (b1, b2) for a triangle
  std::uint32_t instance = kNoInstance;  // index into Scene::instances, for a shape in a group
};

// How a batch of rays reaches Embree.
enum class RayBatchMode : std::uint8_t {
  Single,    // one rtcIntersect1 / rtcOccluded1 per ray
  Packet16,  // rtcIntersect16 / rtcOccluded16 over consecutive groups of 16 rays
  Stream,    // one rtcIntersect1M / rtcOccluded1M over the whole batch
};
const char* ray_batch_mode_name(RayBatchMode mode);
inline constexpr RayBatchMode kAllRayBatchModes[] = {RayBatchMode::Single, RayBatchMode::Packet16,
                                                     RayBatchMode::Stream};

// Rays and hits as one array per scalar (structure of arrays), the layout
// the wavefront's vectorised stages keep their paths in.
struct RayArrays {
  const float *ox, *oy, *oz, *dx, *dy, *dz, *tmax;
  const std::uint32_t* alpha_key = nullptr;  // as Ray::alpha_key; null: every key 0
};
struct HitArrays {
  float *t, *u, *v;               // distance; Embree's barycentrics (b1, b2) for a triangle
  std::uint32_t *shape, *prim;
  std::uint8_t* found;
  std::uint32_t* instance = nullptr;  // as RayHit::instance; may be null for a scene without instances
};

// How the BVH is built and how triangles are intersected: the scene's
// RenderSettings::compact_bvh and RenderSettings::intersection.
struct BvhOptions {
  bool compact = false;
  Intersection intersection = Intersection::Robust;
};

class EmbreeAccel {
 public:
  // Builds the BVH. Throws SystemError with Embree's message if the device
  // or the build fails. Embree reads the meshes' index arrays in place, and
  // their vertex arrays too where they have capacity for one more vertex
  // (CompiledScene reserves it): `shapes` must outlive the accel and keep
  // those arrays unchanged. Groups and instances are copied.
  // `options`: compact or not, robust or fast. `materials`: the table
  // Shape::material indexes, read for alpha (empty: every shape opaque);
  // throws InputError for alpha on a sphere, whose two crossings of one
  // ray would share a decision. `textures`: the scene's images, which
  // alpha textures read (must outlive the accel; null if it has none).
  explicit EmbreeAccel(const std::vector<Shape>& shapes, std::span<const ShapeGroup> groups = {},
                       std::span<const Instance> instances = {}, BvhOptions options = {},
                       std::span<const Material> materials = {}, const Textures* textures = nullptr);
  ~EmbreeAccel();
  EmbreeAccel(const EmbreeAccel&) = delete;
  EmbreeAccel& operator=(const EmbreeAccel&) = delete;

  // Closest hit with t in (0, ray.tmax).
  bool intersect(const Ray& ray, RayHit* hit) const;
  // True if anything lies on the ray with t in (0, ray.tmax).
  bool occluded(const Ray& ray) const;

  // The same queries for many rays at once: found[i] / occluded[i] is 0 or 1,
  // and every result equals the one-ray query's. `mode` says how the batch
  // reaches Embree (the wavefront tracer picks one per kind of ray, by
  // measurement: bench/bench_tracers.cpp); `coherent` tells Embree the rays
  // are neighbours (camera rays of adjacent pixels). These two functions are
  // the one place to change for Embree 4, which has packets but no streams.
  void intersect_batch(std::span<const Ray> rays, std::span<RayHit> hits, std::span<std::uint8_t> found,
                       RayBatchMode mode, bool coherent = false) const;
  void occluded_batch(std::span<const Ray> rays, std::span<std::uint8_t> occluded, RayBatchMode mode,
                      bool coherent = false) const;
  // The same again for n rays in arrays; a hit's fields mean something only
  // where found[i] is 1 (elsewhere they are overwritten with unspecified
  // values). Streams go to Embree without a copy
  // (rtcIntersectNp / rtcOccludedNp), packets as 16 consecutive lanes.
  void intersect_arrays(const RayArrays& rays, std::size_t n, const HitArrays& hits, RayBatchMode mode,
                        bool coherent = false) const;
  void occluded_arrays(const RayArrays& rays, std::size_t n, std::uint8_t* occluded, RayBatchMode mode,
                       bool coherent = false) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pathlab
