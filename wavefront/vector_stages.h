// Wavefront stages that run 16 paths at a time in AVX-512 registers:
// - making camera rays, for any scene seen through a pinhole camera;
// - sampling lights and scattering, for scenes that need nothing more than
//   Lambert surfaces and triangle area lights (the dragon benchmark, the
//   Cornell box).
// Other scenes, and machines without AVX-512, run the scalar stages of
// wavefront_tracer.cpp.
//
// Same paths: every lane computes what the scalar code computes, operation
// for operation and in the same order (IEEE add, multiply, divide and square
// root round the same in a vector lane as in a scalar register), nothing is
// contracted into FMAs (-ffp-contract=off, project-wide), and the one
// transcendental step, the concentric disk's sine and cosine, is
// core/sampling.h's sin_cos_quarter polynomial rather than libm's.
// tests/test_wavefront.cpp checks every sample of several scenes bit for
// bit against the scalar stages.
//
// This header is plain data on purpose: vector_stages_avx512.cpp is compiled
// for AVX-512 and must not instantiate any inline function (GLM, the standard
// library) that another translation unit also instantiates - the linker would
// keep one copy, possibly the AVX-512 one, for everybody.
#pragma once

#include "core/sample_dims.h"

#include <cstddef>
#include <cstdint>

namespace pathlab::vector_stages {

// The sampling strategies the vectorised stages support ("cosine" scatters
// differently and stays scalar).
enum class Strategy : std::uint8_t { Bsdf, Light, Mis, LightBsdf };

// The area lights, as LightSampler::sample() picks and samples them.
struct Lights {
  std::size_t count = 0;
  const float* cdf = nullptr;       // LightSampler::cdf()
  const float* pmf = nullptr;       // LightSampler::pmf()
  const float* inv_area = nullptr;  // 1 / area, as LightSampler computes it
  // Per light, 16 floats: p0, p1, p2, front normal, emitted radiance, and
  // 1 if it emits on both sides (else 0).
  const float* triangle = nullptr;
};

// What the stages read of the scene and the render settings.
struct Scene {
  Strategy strategy = Strategy::Mis;
  int rr_depth = 0;
  float min_pdf = 0.0f;
  std::ptrdiff_t albedo_offset = 0;  // bytes from a Material to its albedo
  Lights lights;
};

// A pinhole camera (Camera::generate_ray without an aperture).
struct Camera {
  float position[3], forward[3], right[3], up[3];
  float tan_half_fov, aspect, inv_width, inv_height;
};

// The wave's arrays (wavefront_tracer.cpp's Wave), as raw memory. The record
// layouts (Ray, Surfel, PreviousVertex) are fixed below and checked with
// static_asserts where the real types are visible.
struct WaveView {
  std::size_t n = 0;                   // paths in slots [0, n)
  const std::uint64_t* rng = nullptr;  // SampleStream::key() per path
  const std::uint32_t* x = nullptr;    // pixel per path
  const std::uint32_t* y = nullptr;
  float* film = nullptr;               // vec2 per path
  float* L = nullptr;                  // Spectrum per path
  std::uint32_t* rays = nullptr;
  std::int32_t* vertex = nullptr;
  void* ray = nullptr;                 // Ray per path
  float* beta = nullptr;               // Spectrum per path
  void* prev = nullptr;                // PreviousVertex per path
  std::uint8_t* alive = nullptr;
  const void* surfel = nullptr;        // Surfel per path
  void* shadow = nullptr;              // two Rays per path: [2i + 1] is the area light's
  float* unoccluded = nullptr;         // two Spectrums per path
  float* light_weight = nullptr;       // two per path
  std::uint8_t* shadow_state = nullptr;  // two per path
};

// Byte layouts of the records the stages read and write.
namespace layout {
inline constexpr std::size_t kRaySize = 28, kRayOrigin = 0, kRayDir = 12, kRayTmax = 24;
inline constexpr std::size_t kSurfelSize = 88, kSurfelP = 0, kSurfelPError = 12, kSurfelN = 24, kSurfelFrameS = 36,
                             kSurfelFrameT = 48, kSurfelFrameN = 60, kSurfelMaterial = 72;
inline constexpr std::size_t kPrevSize = 20, kPrevP = 0, kPrevPdf = 12, kPrevImpulse = 16, kPrevBsdfTechnique = 17;
}  // namespace layout

// Whether this processor runs the vectorised stages.
bool cpu_supported();

// generate_camera_rays: every path's camera ray, and its state reset.
void generate_camera_rays(const Camera& camera, const WaveView& wave);
// sample_lights: for every live path, next-event estimation towards one
// area light (the scalar stage's slot [2i + 1]; slot [2i] is cleared, as
// the scene has no point lights).
void sample_lights(const Scene& scene, const WaveView& wave);
// scatter: a cosine-weighted continuation, Russian roulette and the next ray.
void scatter(const Scene& scene, const WaveView& wave);

}  // namespace pathlab::vector_stages
