// Optional observer of one path's events. Tracers take a PathObserver*
// that is null in production (one predictable branch per event); replay,
// `trace-pixel`, VTK export and NaN forensics are built on it.
//
// Contributions ("added") are in the units of the pixel sample: already
// multiplied by the path throughput and any MIS weight.
#pragma once

#include "core/material.h"
#include "core/math.h"
#include "core/ray.h"
#include "core/scene.h"

#include <cstdint>

namespace pathlab {

enum class PathEnd : std::uint8_t {
  Escaped,    // the ray left the scene
  MaxDepth,   // the vertex was past the depth cap
  Absorbed,   // the material sampled no continuation (black, an impulse's absorption,
              // or a direction with zero density such as an exactly grazing one)
  Roulette,   // Russian roulette ended it
  NoSample,   // the sampled direction carried no energy (a zero weight)
};
const char* path_end_name(PathEnd end);

struct CameraEvent {
  std::uint32_t x = 0, y = 0, sample = 0;
  vec2 film{0.0f};
  vec3 origin{0.0f}, dir{0.0f};
};

struct HitEvent {
  int vertex = 0;           // 1 = first surface seen from the camera
  vec3 p{0.0f}, n{0.0f};    // position and front geometric normal
  bool front = true;        // the ray arrived on the front side
  std::uint32_t material = 0, shape = 0, prim = 0;
  std::uint32_t instance = kNoInstance;  // the instance that placed the shape, if it is in a group
  Spectrum emitted{0.0f};   // L_e towards the ray's origin
  float emission_weight = 0.0f;  // 0 when NEE already accounted for it, MIS weight under mis
  Spectrum added{0.0f};     // throughput * weight * L_e
  Spectrum throughput{0.0f};
};

struct EscapeEvent {
  int vertex = 0;           // the vertex the ray would have reached
  Spectrum emitted{0.0f};   // environment radiance
  float emission_weight = 0.0f;
  Spectrum added{0.0f};
};

// Why a light sample brought nothing before any shadow ray was traced (a
// next-event estimate that is missing for a reason, rather than silently).
enum class LightRejection : std::uint8_t {
  None,          // a shadow ray was traced: see `visible`
  NoSample,      // the light sampler gave none: zero density, the back of a one-sided
                 // emitter, seen edge-on, outside a spot's cone (no light, point, wi)
  BelowSurface,  // the light lies on the other side of the surface than the viewer
  BlackBsdf,     // the BSDF is zero for this pair of directions (same side)
};
const char* light_rejection_name(LightRejection r);  // "none", "no_sample", "below_surface", "black_bsdf"
// The reason a sample towards `wi` that the BSDF valued at zero was
// rejected, from the geometric normal `n` and the direction to the viewer `wo`.
inline LightRejection black_light_sample_reason(const vec3& n, const vec3& wi, const vec3& wo) {
  return glm::dot(n, wi) * glm::dot(n, wo) <= 0.0f ? LightRejection::BelowSurface : LightRejection::BlackBsdf;
}

struct LightEvent {
  int vertex = 0;
  bool delta = false;       // a point light
  bool infinite = false;    // the environment
  std::uint32_t light = 0;
  vec3 point{0.0f};         // point on the light (undefined for the environment)
  vec3 wi{0.0f};
  float dist = 0.0f, pdf = 0.0f;
  Spectrum Le{0.0f};
  bool visible = false;
  float mis_weight = 1.0f;
  Spectrum added{0.0f};
  Ray ray{vec3(0.0f), vec3(0.0f), 0.0f};  // the shadow ray as traced (offset off both surfaces); tmax 0 if none
  LightRejection rejected = LightRejection::None;  // not None: no shadow ray, visible false, added 0
};

struct ScatterEvent {
  int vertex = 0;
  Lobe lobe = Lobe::Lambert;
  bool impulse = false;
  bool cosine = false;      // strategy "cosine" replaced the material's sampling
  vec3 wi{0.0f};
  float pdf = 0.0f;
  Spectrum weight{0.0f};    // f |cos| / pdf, divided by `survival` if the path survived roulette
  float survival = 1.0f;    // Russian roulette probability (1 = not applied)
  Spectrum throughput{0.0f};  // after this scattering
  Ray next{vec3(0.0f), vec3(0.0f), 0.0f};  // the ray the path goes on with (tmax 0 if it ends here)
};

struct EndEvent {
  int vertex = 0;
  PathEnd reason = PathEnd::Escaped;
};

class PathObserver {
 public:
  virtual ~PathObserver() = default;
  virtual void on_camera(const CameraEvent&) {}
  virtual void on_hit(const HitEvent&) {}
  virtual void on_escape(const EscapeEvent&) {}
  virtual void on_light(const LightEvent&) {}
  virtual void on_scatter(const ScatterEvent&) {}
  virtual void on_end(const EndEvent&) {}
  // The sample's final radiance (before the film looks at it).
  virtual void on_result(const Spectrum&) {}
};

}  // namespace pathlab
