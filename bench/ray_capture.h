// The rays a tracer casts on a scene, captured once so that Embree's raw
// rate can be measured on exactly that mix. Captured from the reference
// tracer's paths (every pixel, sample 0, through a PathObserver): camera
// rays, continuation ("bounce") rays and shadow rays, each list in the order
// the wavefront tracer would cast them (by vertex, then pixel).
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

struct CapturedRays {
  std::vector<Ray> camera, bounce, shadow;
  std::size_t samples = 0;
  const std::vector<Ray>& of(RayKind kind) const {
    return kind == RayKind::Camera ? camera : kind == RayKind::Bounce ? bounce : shadow;
  }
  std::size_t total() const { return camera.size() + bounce.size() + shadow.size(); }
};

CapturedRays capture_rays(const CompiledScene& scene, const RenderSettings& settings);

// Casts one batch of `kind` on the calling thread, as the wavefront hands it
// to Embree (closest hit into hits/found, or occlusion into found for shadow
// rays; camera rays marked coherent). Returns how many hit something.
std::size_t cast_batch(const CompiledScene& scene, std::span<const Ray> rays, RayKind kind, RayBatchMode mode,
                       std::span<RayHit> hits, std::span<std::uint8_t> found);

// Casts `rays` (closest hit, or occlusion for shadow rays) over every worker
// thread in tasks of 256 rays, as the wavefront tracer does. Returns how
// many hit something.
std::size_t cast(const CompiledScene& scene, const std::vector<Ray>& rays, RayKind kind, RayBatchMode mode);

// "Raw/<kind>/<mode>", the benchmark's name.
std::string raw_name(RayKind kind, RayBatchMode mode);

}  // namespace pathlab::bench
