// Target selection for Highway's dynamic dispatch (core/simd/simd.h). This
// file is compiled once per SIMD target (foreach_target.h) for the one
// function that reports which target dispatch reached.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/simd/simd.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h

#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace pathlab::HWY_NAMESPACE {
std::int64_t compiled_target() { return HWY_TARGET; }
}  // namespace pathlab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE

#include "core/error.h"
#include "core/simd/simd.h"

#include <algorithm>
#include <cstdlib>
#include <stdexcept>

namespace pathlab {

HWY_EXPORT(compiled_target);

namespace {

// pathlab's names for Highway's x86 targets. AVX3_DL (Ice Lake's extra
// AVX-512 instructions) is AVX-512 too; pathlab compiles no SSSE3 code
// (HWY_DISABLED_TARGETS, core/CMakeLists.txt) and on x86 never needs EMU128.
constexpr std::int64_t kAvx512Bits = HWY_AVX3 | HWY_AVX3_DL;
constexpr std::int64_t kVectorBits = kAvx512Bits | HWY_AVX2 | HWY_SSE4 | HWY_SSSE3 | HWY_EMU128;

// The targets select_simd_target() disabled (Highway keeps them, but does
// not say which they are).
std::int64_t g_disabled = 0;

SimdTarget from_hwy(std::int64_t t) {
  if (t & kAvx512Bits) return SimdTarget::Avx512;
  if (t & HWY_AVX2) return SimdTarget::Avx2;
  if (t & HWY_SSE4) return SimdTarget::Sse4;
  return SimdTarget::Scalar;
}

// The Highway targets to disable so that dispatch picks `t`.
std::int64_t disabled_for(SimdTarget t) {
  switch (t) {
    case SimdTarget::Auto: return 0;
    case SimdTarget::Avx512: return 0;
    case SimdTarget::Avx2: return kAvx512Bits;
    case SimdTarget::Sse4: return kAvx512Bits | HWY_AVX2;
    case SimdTarget::Scalar: return kVectorBits;
  }
  return 0;
}

std::string supported_list() {
  std::string s;
  for (SimdTarget t : supported_simd_targets()) s += (s.empty() ? "" : ", ") + std::string(simd_target_name(t));
  return s;
}

}  // namespace

const char* simd_target_name(SimdTarget t) {
  switch (t) {
    case SimdTarget::Auto: return "auto";
    case SimdTarget::Avx512: return "avx512";
    case SimdTarget::Avx2: return "avx2";
    case SimdTarget::Sse4: return "sse4";
    case SimdTarget::Scalar: return "scalar";
  }
  return "?";
}

std::optional<SimdTarget> parse_simd_target(std::string_view name) {
  for (SimdTarget t : {SimdTarget::Auto, SimdTarget::Avx512, SimdTarget::Avx2, SimdTarget::Sse4, SimdTarget::Scalar})
    if (name == simd_target_name(t)) return t;
  return std::nullopt;
}

std::vector<SimdTarget> supported_simd_targets() {
  // What the processor runs: Highway reports it only with no target
  // disabled, so lift select_simd_target()'s choice for the question.
  hwy::DisableTargets(0);
  const std::int64_t runs = hwy::SupportedTargets();
  hwy::DisableTargets(g_disabled);
  std::vector<SimdTarget> out;
  if (runs & kAvx512Bits & HWY_TARGETS) out.push_back(SimdTarget::Avx512);
  if (runs & HWY_AVX2 & HWY_TARGETS) out.push_back(SimdTarget::Avx2);
  if (runs & HWY_SSE4 & HWY_TARGETS) out.push_back(SimdTarget::Sse4);
  out.push_back(SimdTarget::Scalar);
  return out;
}

void select_simd_target(SimdTarget t) {
  if (t != SimdTarget::Auto) {
    const std::vector<SimdTarget> can = supported_simd_targets();
    if (std::find(can.begin(), can.end(), t) == can.end())
      throw InputError(std::string("SIMD target '") + simd_target_name(t) +
                       "': this processor (or this build) does not run it; it runs " + supported_list());
  }
  g_disabled = disabled_for(t);
  hwy::DisableTargets(g_disabled);
  if (t != SimdTarget::Auto && active_simd_target() != t)
    throw std::logic_error(std::string("select_simd_target: dispatch chose ") + simd_target_name(active_simd_target()) +
                           ", not " + simd_target_name(t));
}

void select_simd_target_from_environment() {
  const char* value = std::getenv("PATHLAB_SIMD");
  if (value == nullptr || *value == '\0') return;
  const std::optional<SimdTarget> t = parse_simd_target(value);
  if (!t)
    throw InputError(std::string("PATHLAB_SIMD='") + value + "': unknown SIMD target (expected auto, avx512, avx2, sse4 or scalar)");
  try {
    select_simd_target(*t);
  } catch (const InputError& e) {
    throw InputError(std::string("PATHLAB_SIMD: ") + e.what());
  }
}

void select_simd_target(std::optional<SimdTarget> asked, std::string_view option) {
  if (!asked) {
    select_simd_target_from_environment();
    return;
  }
  try {
    select_simd_target(*asked);
  } catch (const InputError& e) {
    throw InputError(std::string(option) + " " + simd_target_name(*asked) + ": " + e.what());
  }
}

SimdTarget active_simd_target() { return from_hwy(HWY_DYNAMIC_DISPATCH(compiled_target)()); }

}  // namespace pathlab

#endif  // HWY_ONCE
