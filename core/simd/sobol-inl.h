// The samplers' numbers (core/rng.h, core/sobol.h) over Highway's 64-bit
// lanes, for the wavefront's vectorised stages: one stream per lane, each
// lane the bits SampleStream::get() computes. The functions are
// core/simd/sobol-generic.h's hashes and core/simd/stream-generic.h's
// streams, the very texts core's scalar sampler runs at width 1
// (core/sobol.h, core/rng.h), compiled here in each target's namespace.
//
// Highway's "-inl.h" convention: no include guard but the toggle below.
#if defined(PATHLAB_CORE_SIMD_SOBOL_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef PATHLAB_CORE_SIMD_SOBOL_INL_H_
#undef PATHLAB_CORE_SIMD_SOBOL_INL_H_
#else
#define PATHLAB_CORE_SIMD_SOBOL_INL_H_
#endif

#include <hwy/highway.h>

#include "core/simd/lanes-inl.h"  // mul_wide32, mul64
#include "core/rng.h"  // Dim, sobol_slot, zsobol_draws, zsobol_pair, kNoZSobol
#include "core/sobol.h"

#include <cstdint>

HWY_BEFORE_NAMESPACE();
namespace pathlab::HWY_NAMESPACE {

#include "core/simd/sobol-generic.h"
#include "core/simd/stream-generic.h"

}  // namespace pathlab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // PATHLAB_CORE_SIMD_SOBOL_INL_H_ toggle
