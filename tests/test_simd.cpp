// Highway's dynamic dispatch (core/simd/simd.h) and the per-lane code of
// core/simd/*-inl.h: every SIMD target this machine runs computes, lane by
// lane, the bits of the width-1 code that both tracers' scalar paths call.
#include "core/error.h"
#include "core/ray.h"
#include "core/sampling.h"
#include "core/simd/simd.h"
#include "tests/simd_kernels.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace pathlab {
namespace {

// Leaves dispatch as it found it (the best target).
struct SimdChoice {
  ~SimdChoice() { select_simd_target(SimdTarget::Auto); }
};

bool runs(SimdTarget t) {
  const std::vector<SimdTarget> s = supported_simd_targets();
  return std::find(s.begin(), s.end(), t) != s.end();
}

// Every x86-64 machine pathlab's CI runs on has AVX2, so AVX2 and SSE4 are
// tested everywhere; AVX-512 where the processor has it.
TEST(SimdTargets, AvxTwoSseFourAndScalarRunHereAndDispatchObeysTheChoice) {
  const SimdChoice restore;
  const std::vector<SimdTarget> targets = supported_simd_targets();
  std::string list;
  for (SimdTarget t : targets) list += std::string(simd_target_name(t)) + " ";
  RecordProperty("targets", list);
  EXPECT_TRUE(runs(SimdTarget::Avx2)) << list;
  EXPECT_TRUE(runs(SimdTarget::Sse4)) << list;
  ASSERT_EQ(targets.back(), SimdTarget::Scalar) << list;
  for (SimdTarget t : targets) {
    select_simd_target(t);
    EXPECT_EQ(active_simd_target(), t) << simd_target_name(t);
    // Asking what the processor runs does not undo the choice.
    EXPECT_EQ(supported_simd_targets(), targets);
    EXPECT_EQ(active_simd_target(), t) << simd_target_name(t);
  }
  select_simd_target(SimdTarget::Auto);
  EXPECT_EQ(active_simd_target(), targets.front());
}

TEST(SimdTargets, NamesParseAndBadNamesAreRefused) {
  const SimdChoice restore;
  for (SimdTarget t : {SimdTarget::Auto, SimdTarget::Avx512, SimdTarget::Avx2, SimdTarget::Sse4, SimdTarget::Scalar})
    EXPECT_EQ(parse_simd_target(simd_target_name(t)), t);
  EXPECT_FALSE(parse_simd_target("avx3"));
  EXPECT_FALSE(parse_simd_target("AVX2"));
  ::setenv("PATHLAB_SIMD", "neon", 1);
  try {
    select_simd_target_from_environment();
    ADD_FAILURE() << "PATHLAB_SIMD=neon accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("PATHLAB_SIMD='neon': unknown SIMD target"), std::string::npos) << e.what();
  }
  ::setenv("PATHLAB_SIMD", "scalar", 1);
  select_simd_target_from_environment();
  EXPECT_EQ(active_simd_target(), SimdTarget::Scalar);
  ::unsetenv("PATHLAB_SIMD");
  if (!runs(SimdTarget::Avx512)) {
    try {
      select_simd_target(SimdTarget::Avx512);
      ADD_FAILURE() << "avx512 accepted on a processor without it";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("does not run it"), std::string::npos) << e.what();
    }
  }
}

// Inputs: the corners and the centre, the diagonals (where the concentric
// map changes wedge), values a few ulps either side of 0.5 (o = 2u - 1 near
// 0: the 0/0 of the centre and huge ratios), and 2^20 + 3 uniform pairs (a
// length no vector width divides, so the width-1 tail runs too).
void inputs(std::vector<float>& ux, std::vector<float>& uy) {
  const float one_minus = std::nextafter(1.0f, 0.0f);
  const std::vector<float> special = {0.0f, 0.5f, one_minus, 0.25f, 0.75f, std::nextafter(0.5f, 0.0f),
                                      std::nextafter(0.5f, 1.0f), 1e-30f, 0.5f + 0x1p-24f, 0.5f - 0x1p-25f};
  for (float a : special)
    for (float b : special) ux.push_back(a), uy.push_back(b);
  std::mt19937 g(20261202);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int i = 0; i < 1000; ++i) {
    const float a = u(g);
    ux.push_back(a), uy.push_back(a);
    ux.push_back(a), uy.push_back(1.0f - a);
  }
  while (ux.size() < (1u << 20) + 3) ux.push_back(u(g)), uy.push_back(u(g));
}

TEST(SimdWarps, EveryTargetComputesTheBitsOfTheWidthOneCode) {
  const SimdChoice restore;
  std::vector<float> ux, uy;
  inputs(ux, uy);
  const std::size_t n = ux.size();
  // The width-1 code: what both tracers' scalar paths call.
  std::vector<std::uint32_t> want(5 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const vec3 w = square_to_cosine_hemisphere(vec2(ux[i], uy[i]));
    const vec2 disk = square_to_concentric_disk(vec2(ux[i], uy[i]));
    const SinCos sc = sin_cos_quarter(ux[i] * (3.14159265358979323846f / 4.0f));
    ASSERT_EQ(std::bit_cast<std::uint32_t>(disk.x), std::bit_cast<std::uint32_t>(w.x));
    ASSERT_EQ(std::bit_cast<std::uint32_t>(disk.y), std::bit_cast<std::uint32_t>(w.y));
    const float v[5] = {w.x, w.y, w.z, sc.sin, sc.cos};
    for (int k = 0; k < 5; ++k) want[5 * i + k] = std::bit_cast<std::uint32_t>(v[k]);
  }
  for (SimdTarget t : supported_simd_targets()) {
    select_simd_target(t);
    std::vector<float> out[5];
    for (auto& o : out) o.assign(n, std::numeric_limits<float>::quiet_NaN());
    test::simd_warps(ux.data(), uy.data(), out[0].data(), out[1].data(), out[2].data(), out[3].data(),
                     out[4].data(), n);
    const char* names[5] = {"disk x", "disk y", "hemisphere z", "sin", "cos"};
    std::size_t differ = 0;
    for (std::size_t i = 0; i < n; ++i)
      for (int k = 0; k < 5; ++k)
        if (std::bit_cast<std::uint32_t>(out[k][i]) != want[5 * i + k] && differ++ < 5)
          ADD_FAILURE() << simd_target_name(t) << ": " << names[k] << " of u = (" << ux[i] << ", " << uy[i]
                        << ") is " << out[k][i] << ", the width-1 code gives " << std::bit_cast<float>(want[5 * i + k]);
    EXPECT_EQ(differ, 0u) << simd_target_name(t) << ": values differing from the width-1 code, of " << 5 * n;
  }
}

// offset_ray_origin: core's scalar function (lanes-inl.h's generic code at
// lane1's width 1, whose StepAway is core/ray.h's branches) and every
// target's lanes (NextFloat by selects) step to the same floats, on points
// where the stepping's cases meet: both zeros, denormals, the largest
// floats and the infinities, no error across the surface (the fallback
// offset), normals with zero and negative components. A NaN result (inf -
// inf on the way) counts as equal to any NaN: the compiler may swap the
// operands of an addition, and with them which NaN's sign comes out. NaN
// points are not among the inputs: Highway's width-1 target (HWY_SCALAR,
// which only these kernels run) takes Max's non-NaN operand where x86
// takes the second; a ray from a NaN point is NaN whatever these bits, and
// the film counts and drops its sample.
TEST(SimdOffsetRayOrigin, EveryTargetComputesTheBitsOfCoresScalarFunction) {
  const SimdChoice restore;
  const float specials[] = {0.0f,
                            -0.0f,
                            std::numeric_limits<float>::denorm_min(),
                            -std::numeric_limits<float>::denorm_min(),
                            std::numeric_limits<float>::min(),
                            1.0f,
                            -1.0f,
                            0x1p-100f,
                            3.5e7f,
                            -std::numeric_limits<float>::max(),
                            std::numeric_limits<float>::max(),
                            std::numeric_limits<float>::infinity(),
                            -std::numeric_limits<float>::infinity()};
  std::mt19937 g(5);
  std::uniform_int_distribution<int> pick(0, static_cast<int>(std::size(specials)) - 1);
  std::uniform_real_distribution<float> u(-4.0f, 4.0f);
  constexpr std::size_t n = 200003;  // not a multiple of any width: the tail runs at width 1
  std::vector<float> p(3 * n), e(3 * n), nrm(3 * n);
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      // Half the points special coordinate by coordinate; the errors 0 a
      // third of the time (the fallback); normals with zeros and signs.
      p[3 * i + k] = i % 2 ? specials[pick(g)] : u(g);
      e[3 * i + k] = i % 3 ? std::abs(u(g)) * 1e-6f : 0.0f;
      nrm[3 * i + k] = i % 5 == 0 ? (k == 1 ? 0.0f : -0.5f) : u(g);
    }
  // p + offset exactly 0, then stepped up and down to the denormals.
  for (std::size_t i = 0; i < 64; ++i) {
    const float side = i % 2 ? 1.0f : -1.0f, d = std::ldexp(1.0f, -static_cast<int>(i));
    for (int k = 0; k < 3; ++k) {
      p[3 * i + k] = -side * d;
      e[3 * i + k] = k == 2 ? d : 0.0f;
      nrm[3 * i + k] = k == 2 ? side : 0.0f;
    }
  }
  std::vector<std::uint32_t> want(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const vec3 o = offset_ray_origin(vec3(p[3 * i], p[3 * i + 1], p[3 * i + 2]),
                                     vec3(e[3 * i], e[3 * i + 1], e[3 * i + 2]),
                                     vec3(nrm[3 * i], nrm[3 * i + 1], nrm[3 * i + 2]));
    for (int k = 0; k < 3; ++k) want[3 * i + k] = std::bit_cast<std::uint32_t>(o[k]);
  }
  for (SimdTarget t : supported_simd_targets()) {
    select_simd_target(t);
    std::vector<float> out(3 * n, std::numeric_limits<float>::quiet_NaN());
    test::simd_offset_ray_origin(p.data(), e.data(), nrm.data(), out.data(), n);
    std::size_t differ = 0;
    for (std::size_t i = 0; i < 3 * n; ++i)
      if (std::bit_cast<std::uint32_t>(out[i]) != want[i] && !(std::isnan(out[i]) && std::isnan(std::bit_cast<float>(want[i]))) &&
          differ++ < 5)
        ADD_FAILURE() << simd_target_name(t) << ": coordinate " << i % 3 << " of p = (" << p[i - i % 3] << ", "
                      << p[i - i % 3 + 1] << ", " << p[i - i % 3 + 2] << ") is " << out[i] << ", core's "
                      << std::bit_cast<float>(want[i]);
    EXPECT_EQ(differ, 0u) << simd_target_name(t);
  }
}

}  // namespace
}  // namespace pathlab
