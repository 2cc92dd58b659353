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
  int max_vertex = 0;  // paths end at a vertex beyond this (the depth cap)
  float min_pdf = 0.0f;
  Lights lights;
  // Per shape, 16 floats: its material's albedo, emission, 1 if it emits on
  // both sides, 1 if it emits, 1 if it scatters; the bits of the int32 index
  // of its first light entry (-1: not a light); then unused.
  const float* shape = nullptr;
  // Every triangle (CompiledScene::triangles(): 12 floats each, p0 p1 p2 n),
  // null if a shape is not a triangle mesh or there are more than 2^27
  // (resolve then stays scalar); per shape, the index of its first one and
  // its material (for Surfel::material).
  const float* triangles = nullptr;
  const std::int32_t* first_triangle = nullptr;
  const void* const* material = nullptr;
};
namespace shape_field {
inline constexpr std::size_t kAlbedo = 0, kEmission = 3, kTwoSided = 6, kEmits = 7, kScatters = 8, kFirstLight = 9;
}

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
  void* surfel = nullptr;              // Surfel per path
  const void* hit = nullptr;           // RayHit per path
  const std::uint8_t* found = nullptr;
  void* shadow = nullptr;              // two Rays per path: [2i + 1] is the area light's
  float* unoccluded = nullptr;         // two Spectrums per path
  float* light_weight = nullptr;       // two per path
  std::uint8_t* shadow_state = nullptr;  // two per path
};

// Byte layouts of the records the stages read and write.
namespace layout {
inline constexpr std::size_t kRaySize = 28, kRayOrigin = 0, kRayDir = 12, kRayTmax = 24;
inline constexpr std::size_t kSurfelSize = 88, kSurfelP = 0, kSurfelPError = 12, kSurfelN = 24, kSurfelFrameS = 36,
                             kSurfelFrameT = 48, kSurfelFrameN = 60, kSurfelMaterial = 72, kSurfelShape = 80,
                             kSurfelPrim = 84;
inline constexpr std::size_t kHitSize = 20, kHitT = 0, kHitShape = 4, kHitPrim = 8, kHitUv = 12;
inline constexpr std::size_t kPrevSize = 20, kPrevP = 0, kPrevPdf = 12, kPrevImpulse = 16, kPrevBsdfTechnique = 17;
}  // namespace layout

// Whether this processor runs the vectorised stages.
bool cpu_supported();

// generate_camera_rays: every path's camera ray, and its state reset.
void generate_camera_rays(const Camera& camera, const WaveView& wave);
// resolve: the Surfel of every path whose ray found a surface, and one more
// ray per path (needs Scene::triangles).
void resolve(const Scene& scene, const WaveView& wave);
// add_emission: the emission each path's ray found, as the strategy weighs
// it, and the end of paths that escaped, passed the depth cap or cannot
// scatter (the scene has no environment light).
void add_emission(const Scene& scene, const WaveView& wave);
// sample_lights: for every live path, next-event estimation towards one
// area light (the scalar stage's slot [2i + 1]; slot [2i] is cleared, as
// the scene has no point lights).
void sample_lights(const Scene& scene, const WaveView& wave);
// add_light: the light of every visible area-light sample.
void add_light(const WaveView& wave);
// scatter: a cosine-weighted continuation, Russian roulette and the next ray.
void scatter(const Scene& scene, const WaveView& wave);

}  // namespace pathlab::vector_stages
