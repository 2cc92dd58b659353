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

}  // namespace pathlab::test
