// The rays a tracer casts on a scene, captured once so that Embree's raw
// rate can be measured on exactly that mix. Captured from the reference
// tracer's paths (every pixel, sample 0, through a PathObserver): camera
// rays, continuation ("bounce") rays and shadow rays, each list in the order
// the wavefront tracer would cast them (by vertex, then pixel), kept as
// arrays and cast through the same calls as the wavefront's.
#pragma once

#include "core/compiled_scene.h"

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace pathlab::bench {

enum class RayKind { Camera, Bounce, Shadow };
inline constexpr RayKind kAllRayKinds[] = {RayKind::Camera, RayKind::Bounce, RayKind::Shadow};
const char* ray_kind_name(RayKind kind);

// Rays as one array per scalar, the layout the vectorised wavefront hands to
// Embree (EmbreeAccel::intersect_arrays / occluded_arrays).
struct RayList {
  std::vector<float> ox, oy, oz, dx, dy, dz, tmax;
  std::size_t size() const { return ox.size(); }
  bool empty() const { return ox.empty(); }
  void push_back(const Ray& r);
  // Rays [first, size()) as arrays.
  RayArrays from(std::size_t first) const;
};

struct CapturedRays {
  RayList camera, bounce, shadow;
  std::size_t samples = 0;
  const RayList& of(RayKind kind) const {
    return kind == RayKind::Camera ? camera : kind == RayKind::Bounce ? bounce : shadow;
  }
  std::size_t total() const { return camera.size() + bounce.size() + shadow.size(); }
};

CapturedRays capture_rays(const CompiledScene& scene, const RenderSettings& settings);

// Where a cast writes its hits: room for one chunk of rays.
struct HitBuffers {
  std::vector<float> t, u, v;
  std::vector<std::uint32_t> shape, prim;
  std::vector<std::uint8_t> found;
  explicit HitBuffers(std::size_t n) : t(n), u(n), v(n), shape(n), prim(n), found(n) {}
  HitArrays arrays() { return {t.data(), u.data(), v.data(), shape.data(), prim.data(), found.data()}; }
};

// The rays the wavefront hands Embree in one call: at most a wave's worth
// (WavefrontTracer::kDefaultWaveSize; bench_tracers.cpp checks they agree).
inline constexpr std::size_t kCastChunk = 4096;

// Casts rays [first, first + n) of `rays` (n <= kCastChunk) of `kind` on the
// calling thread, as the wavefront's vectorised stages hand them to Embree:
// from the arrays, closest hit into `hits`, or occlusion into hits.found for
// shadow rays; camera rays marked coherent. Returns how many hit something.
std::size_t cast_batch(const CompiledScene& scene, const RayList& rays, std::size_t first, std::size_t n,
                       RayKind kind, RayBatchMode mode, HitBuffers& hits);

// Casts every ray of `rays` over every worker thread, kCastChunk at a time
// (as the wavefront casts a wave's rays at once). Returns how many hit
// something.
std::size_t cast(const CompiledScene& scene, const RayList& rays, RayKind kind, RayBatchMode mode);

// "Raw/<kind>/<mode>", the benchmark's name.
std::string raw_name(RayKind kind, RayBatchMode mode);

}  // namespace pathlab::bench
