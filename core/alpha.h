// Stochastic alpha (coverage), as pbrt-v4 treats it: a ray that meets a
// surface of coverage a stops there with probability a and passes through
// otherwise (a = 0 never stops a ray, a = 1 always does). The decision is
// made inside Embree's traversal, by the intersection and occlusion filters
// EmbreeAccel registers on the geometries whose material has alpha, and
// nowhere else.
//
// It is a pure function of the ray's key and of the surface met, so that
// (a) every ray mode gives the same decisions, however often and in
// whatever order Embree calls a filter for one triangle, and (b) different
// surfaces along one ray are decided independently. A ray's key is the
// sample contract's number for the vertex it leaves (Dim::Alpha): the
// camera ray's is bounce 0's, and a continuation or shadow ray leaving
// vertex k takes vertex k's. Both tracers set it with alpha_key(), so they
// see through the same surfaces. A vertex's continuation and shadow rays
// share its key: each ray is still decided with the right probability, and
// their contributions are added, so the sharing biases nothing (it only
// correlates them where they cross the same triangle). A ray without a key
// (0) is still deterministic: it is one key like any other.
// Spheres take no alpha: a ray may cross one twice at its one primitive,
// and both crossings would share a decision.
#pragma once

#include "core/rng.h"

#include <cstdint>

namespace pathlab {

// The key of the rays leaving `vertex` of the sample `rng` draws for: the
// high 32 bits of its Alpha hash (core/simd/stream-generic.h's
// stream_alpha_key, which the wavefront's lanes run too).
constexpr std::uint32_t alpha_key(const SampleStream& rng, std::uint32_t vertex) {
  return static_cast<std::uint32_t>(sobol::width1::stream_alpha_key(sobol::detail::kLane, rng.at(vertex)).raw);
}

// The uniform that decides whether a ray of key `key` stops at triangle
// `prim` of the scene's shape `shape`, placed by instance `instance`
// (kNoInstance for a shape in world space): the key and the surface hashed
// in a chain, as SampleStream hashes its key.
constexpr float alpha_uniform(std::uint32_t key, std::uint32_t shape, std::uint32_t prim, std::uint32_t instance) {
  const std::uint64_t h = mix64(((static_cast<std::uint64_t>(key) << 32) | shape) + 0x9e3779b97f4a7c15ull);
  return to_unit_float(mix64(h ^ ((static_cast<std::uint64_t>(instance) << 32) | prim)));
}

// True if a surface of coverage `alpha` stops the ray whose uniform is `u`:
// with probability alpha, since u is uniform in [0, 1) (to_unit_float).
constexpr bool alpha_stops(float alpha, float u) { return u < alpha; }

}  // namespace pathlab
