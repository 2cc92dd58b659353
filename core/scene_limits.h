// What Embree 3.13 accepts, and the limits of a scene that keep every ray
// the tracers make within it. Implemented in geometry.cpp (the scene checks)
// and embree_accel.cpp (the count of refused rays).
#pragma once

#include "core/geometry.h"
#include "core/ray.h"

#include <cmath>
#include <cstdint>

namespace pathlab {

// Embree 3.13 asserts that every ray it is given is valid, and Debian's build
// keeps its assertions, so an invalid ray aborts the process (SIGABRT).
// Valid (RayK::valid in Embree's kernels/common/ray.h): every component of
// the origin and of the direction within +-FLT_LARGE = 1.844e18, which NaN is
// not, and tnear, tfar not NaN. EmbreeAccel never passes a ray that fails
// this; the scene loader keeps every position within kMaxSceneCoordinate
// (core/geometry.h), so only a ray already poisoned by NaN can.
inline constexpr float kEmbreeLargest = 1.844e18f;
// Written with & on 0/1 integers rather than &&: no branch per component,
// so that a loop over arrays of rays (EmbreeAccel's check of a whole batch)
// vectorises.
inline bool embree_accepts(const vec3& origin, const vec3& dir, float tmax) {
  const auto ok = [](float v) { return static_cast<unsigned>(std::abs(v) <= kEmbreeLargest); };
  return (ok(origin.x) & ok(origin.y) & ok(origin.z) & ok(dir.x) & ok(dir.y) & ok(dir.z) &
          static_cast<unsigned>(!std::isnan(tmax))) != 0u;
}
inline bool embree_accepts(const Ray& ray) { return embree_accepts(ray.origin, ray.dir, ray.tmax); }

// How many rays EmbreeAccel has refused (embree_accepts) in this process. A
// refused ray is never passed to Embree: an intersection query reports a
// miss with t = NaN (RayHit::t, HitArrays::t) and an occlusion query
// "occluded"; the tracers turn such a miss into a NaN sample, which the
// film leaves out and reports as a bad sample.
std::uint64_t embree_rejected_rays();

// The limits of a scene that keep every ray the tracers make acceptable to
// Embree (core/ray.h, embree_accepts: origins within +-1.844e18): every
// world-space position - the camera and its aperture, vertices after their
// transforms, sphere centres +- radius, placed groups, lights - lies within
// +-kMaxSceneCoordinate in each coordinate, 100x inside Embree's bound, so
// that a ray leaving any point of the scene (a unit direction, an offset of
// a few floats) stays acceptable. Sphere radii are at least kMinSphereRadius,
// so that radius^2 (a sphere light's area; once Embree's float sphere test,
// now sphere_crossing's, in double) is a normal float, not a denormal or
// zero. docs/scene-format.md ("Limits") states the same rule.
inline constexpr float kMaxSceneCoordinate = 1e16f;
inline constexpr float kMinSphereRadius = 1e-18f;
// The largest vertical field of view, in degrees. The camera works with
// tan(fov_y / 2) in float: its error grows towards 180 (3e-6 relative at
// 179, 3e-5 at 179.9), and just below 180 the float angle rounds to 180,
// whose tangent is -2.3e7: an image turned upside down, or garbage.
inline constexpr double kMaxFovYDegrees = 179.0;
// True if every coordinate of `p` lies within +-kMaxSceneCoordinate (NaN does not).
inline bool within_scene_range(const vec3& p) {
  return std::abs(p.x) <= kMaxSceneCoordinate && std::abs(p.y) <= kMaxSceneCoordinate &&
         std::abs(p.z) <= kMaxSceneCoordinate;
}
// True if every corner of `box` placed by `to_world` is within_scene_range.
bool placed_in_range(const Box& box, const mat4& to_world);
// Throws InputError unless every position of `scene` is within the limits
// above: the last line of defence for scenes the JSON loader did not place
// itself (glTF files, built-in scenes); each message names the file and
// the shape.
void check_scene_range(const Scene& scene);

}  // namespace pathlab
