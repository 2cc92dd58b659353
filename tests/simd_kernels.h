// Array kernels over the per-lane code of core/simd/*-inl.h, compiled for
// every SIMD target (tests/simd_kernels.cpp) and called through Highway's
// dynamic dispatch, so that a test can run each target in turn.
#pragma once

#include <cstddef>

namespace pathlab::test {

// For i in [0, n): (x, y) = concentric_disk(ux, uy), z = the cosine
// hemisphere's z, (s, c) = sin_cos_quarter(ux * pi/4). Full vectors of the
// dispatched target, then the tail at width 1.
void simd_warps(const float* ux, const float* uy, float* x, float* y, float* z, float* s, float* c, std::size_t n);

// For i in [0, n): out[3i..3i+2] = offset_ray_origin(p, error, normal) of
// core/simd/lanes-inl.h, each argument three floats at [3i]. Full vectors
// of the dispatched target, then the tail at Highway's width 1.
void simd_offset_ray_origin(const float* p, const float* error, const float* normal, float* out, std::size_t n);

// The Disney model of core/bsdf/disney-inl.h in lanes, with the lobes
// kDisneyLobes | kClearcoat (clearcoat) or kDisneyLobes, VNDF sampling or
// cosine-power lobes (cospow), no energy compensation. `in` holds kDisneyKernelInputs arrays of n floats
// (the closure's fields in ClosureLanes' order without the Lambert lobe:
// diffuse 3, roughness, subsurface, sheen 3, specular, spec0 3, ax, ay,
// clearcoat, clearcoat_alpha, its ln(a^2) and log2(a^2); then wo 3, wi 3,
// u_lobe, ux, uy); `out` kDisneyKernelOutputs arrays of n: eval's f 3, pdf,
// the lobe probabilities 3, the sample's wi 3, whether it was drawn (1 or
// 0) and its family. n must be a multiple of the widest vector (16).
inline constexpr int kDisneyKernelInputs = 28, kDisneyKernelOutputs = 12;
void simd_disney(bool clearcoat, bool cospow, const float* in, float* out, std::size_t n);

// sin_cos_turn(u) and exp2_lanes(y) of core/simd/sampling-inl.h for i in
// [0, n), n a multiple of 16.
void simd_transcendentals(const float* u, const float* y, float* sin, float* cos, float* exp2, std::size_t n);
// log_lanes, log1p_lanes, exp_lanes and expm1_lanes (sampling-inl.h): array
// k of `out` (k = 0..3, each n floats) is the k-th function of array k of
// `in`; n a multiple of 16.
void simd_log_exp(const float* in, float* out, std::size_t n);
// atan2_lanes(y[i], x[i]) (sampling-inl.h) into out; n a multiple of 16.
void simd_atan2(const float* y, const float* x, float* out, std::size_t n);
// sin_cos_d(x[i]) and atan2_d(y[i], x[i]) of core/simd/spherical-inl.h in
// double lanes; n a multiple of 8.
void simd_trig_d(const double* x, const double* y, double* sin, double* cos, double* atan2, std::size_t n);

}  // namespace pathlab::test
