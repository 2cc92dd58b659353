// Highway's dynamic dispatch (core/simd/simd.h) and the per-lane code of
// core/simd/*-inl.h: every SIMD target this machine runs computes, lane by
// lane, the bits of the width-1 code that both tracers' scalar paths call.
#include "core/bsdf/disney.h"
#include "core/error.h"
#include "core/ray.h"
#include "core/sampling.h"
#include "core/simd/simd.h"
#include "core/simd/width1.h"
#include "tests/simd_kernels.h"

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <utility>
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


// sin_cos_turn and exp2_lanes (core/simd/sampling-inl.h), pathlab's own
// transcendentals for the lanes: within a few ulps of libm, and the same
// bits on every target and at width 1 (libm's are not the lanes').
// placed_area_scale (Nanson's formula, |det L| |L^-T n|) against its
// definition: the area |L t1 x L t2| of the unit square of two orthonormal
// tangents t1, t2 of n after L, for a turned, sheared, non-uniformly scaled
// and a mirroring L, at random normals.
TEST(SimdGeometry, PlacedAreaScaleIsTheAreaOfThePlacedTangentSquare) {
  std::mt19937 gen(9);
  std::normal_distribution<float> normal;
  const mat3 turn = mat3(glm::rotate(glm::mat4(1.0f), 0.7f, glm::normalize(vec3(0.3f, 1.0f, -0.4f))));
  const mat3 shear(vec3(1.0f, 0.0f, 0.0f), vec3(0.6f, 1.0f, 0.0f), vec3(-0.3f, 0.2f, 1.0f));
  const auto diagonal = [](float x, float y, float z) { return mat3(vec3(x, 0, 0), vec3(0, y, 0), vec3(0, 0, z)); };
  for (const mat3& l : {turn * diagonal(2.0f, 3.0f, 0.5f) * shear, diagonal(-1.5f, 0.4f, 2.0f)}) {
    const mat3 t = glm::transpose(glm::inverse(l));
    for (int i = 0; i < 1000; ++i) {
      const vec3 n = glm::normalize(vec3(normal(gen), normal(gen), normal(gen)));
      const Frame f(n);
      const double want = glm::length(glm::cross(glm::dvec3(l * f.s), glm::dvec3(l * f.t)));
      using namespace width1;
      const float got = generic::placed_area_scale(lanes(l[0]), lanes(l[1]), lanes(l[2]), lanes(t[0]), lanes(t[1]),
                                                   lanes(t[2]), lanes(n)).raw;
      ASSERT_NEAR(got, want, 1e-5 * want) << i;
    }
  }
}

TEST(SimdTranscendentals, CloseToLibmAndTheSameBitsOnEveryTarget) {
  const SimdChoice restore;
  std::mt19937 g(20261203);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  std::vector<float> u = {0.0f, 0.125f, 0.25f, 0.375f, 0.5f, 0.625f, 0.75f, 0.875f, std::nextafter(1.0f, 0.0f), 1.0f,
                          1e-30f, std::nextafter(0.125f, 0.0f), std::nextafter(0.125f, 1.0f)};
  std::vector<float> y = {0.0f, -0.5f, 0.5f, -1.0f, -19.93f, -126.0f, 127.0f, -0.49999997f, 1e-30f, -1e-30f};
  while (u.size() < (1u << 16)) u.push_back(uniform(g));
  while (y.size() < u.size()) y.push_back(-20.0f * uniform(g));  // GTR1's range: log2(a^2) >= log2(1e-6)
  const std::size_t n = u.size();
  // The width-1 code (lane1), as core's scalar callers run it.
  std::vector<float> want[3] = {std::vector<float>(n), std::vector<float>(n), std::vector<float>(n)};
  for (std::size_t i = 0; i < n; ++i) {
    width1::F s, c;
    width1::generic::sin_cos_turn(width1::kScalar, width1::F{u[i]}, s, c);
    want[0][i] = s.raw, want[1][i] = c.raw;
    want[2][i] = width1::generic::exp2_lanes(width1::kScalar, width1::F{y[i]}).raw;
  }
  double worst_trig = 0.0, worst_exp = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double phi = 2.0 * 3.14159265358979323846 * double(u[i]);
    worst_trig = std::max({worst_trig, std::abs(double(want[0][i]) - std::sin(phi)), std::abs(double(want[1][i]) - std::cos(phi))});
    worst_exp = std::max(worst_exp, std::abs(double(want[2][i]) / std::exp2(double(y[i])) - 1.0));
  }
  // sin and cos within 2 ulp of 1 (plus the float rounding of the angle
  // pi/2 f); 2^y within 4e-7 relative (the polynomial's 2e-7 and the rounding).
  EXPECT_LT(worst_trig, 3.0 * 0x1p-24) << "sin_cos_turn against libm's double sin and cos";
  EXPECT_LT(worst_exp, 4e-7) << "exp2_lanes against libm's double exp2";
  EXPECT_EQ(want[0][0], 0.0f);
  EXPECT_EQ(want[1][0], 1.0f);
  EXPECT_EQ(want[2][0], 1.0f);
  for (SimdTarget t : supported_simd_targets()) {
    select_simd_target(t);
    std::vector<float> got[3] = {std::vector<float>(n), std::vector<float>(n), std::vector<float>(n)};
    test::simd_transcendentals(u.data(), y.data(), got[0].data(), got[1].data(), got[2].data(), n);
    for (int k = 0; k < 3; ++k)
      EXPECT_EQ(std::memcmp(got[k].data(), want[k].data(), n * sizeof(float)), 0)
          << simd_target_name(t) << ": output " << k << " (sin, cos, exp2) differs from the width-1 code's";
  }
}

// log_lanes, log1p_lanes, exp_lanes and expm1_lanes (core/simd/sampling-inl.h),
// the cosine-power lobe's (core/bsdf/cospow-inl.h) in both tracers: within
// a few ulp of libm's double functions, relative to the result, over their
// whole domains (every binade of log's, the ends of each reduction and
// series, arguments from 1e-30 to the overflow), and the same bits on every
// target and at width 1.
TEST(SimdTranscendentals, LogAndExpCloseToLibmAndTheSameBitsOnEveryTarget) {
  const SimdChoice restore;
  std::mt19937 g(20261205);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  constexpr std::size_t n = 1u << 16;
  std::vector<float> in[4];  // log, log1p, exp, expm1
  const auto around = [](std::vector<float>& v, float x) {
    for (float y : {x, std::nextafter(x, -HUGE_VALF), std::nextafter(x, HUGE_VALF), -x, std::nextafter(-x, -HUGE_VALF),
                    std::nextafter(-x, HUGE_VALF)})
      v.push_back(y);
  };
  for (float x : {1.0f, 2.0f, 0.5f, 1.41421354f, 0.70710677f, FLT_MIN, FLT_MAX, 0x1p-24f, 3.0f, 1e-30f, 1e30f})
    for (float y : {x, std::nextafter(x, 0.0f), std::nextafter(x, HUGE_VALF)})
      if (std::isnormal(y)) in[0].push_back(y);
  for (float x : {0.0f, 1e-30f, 1e-8f, 0.29289323f, 0.41421354f, 0.5f, 0.99f}) around(in[1], x);
  in[1].insert(in[1].end(), {std::nextafter(-1.0f, 0.0f), 1.0f, 1e30f, 3.0e38f});
  for (float x : {0.0f, 1e-30f, 1e-8f, 0.34657359f, 0.5f, 1.0f, 20.0f, 87.6f, 88.0f}) around(in[2], x), around(in[3], x);
  for (auto* v : {&in[2], &in[3]}) v->insert(v->end(), {-100.0f, -1e30f, -HUGE_VALF});
  while (in[0].size() < n) in[0].push_back(std::ldexp(1.0f + uniform(g), static_cast<int>(253.0f * uniform(g)) - 126));
  while (in[1].size() < n / 2) in[1].push_back(2.0f * uniform(g) - 1.0f);
  while (in[1].size() < n) in[1].push_back(std::ldexp(uniform(g), static_cast<int>(60.0f * uniform(g)) - 30));
  for (auto* v : {&in[2], &in[3]}) {
    while (v->size() < n / 2) v->push_back(2.0f * uniform(g) - 1.0f);
    while (v->size() < n) v->push_back(176.0f * uniform(g) - 88.0f);
  }
  std::vector<float> all(4 * n), want(4 * n);
  for (int k = 0; k < 4; ++k) std::copy(in[k].begin(), in[k].end(), all.begin() + k * n);
  double worst[4] = {};
  const char* names[4] = {"log_lanes", "log1p_lanes", "exp_lanes", "expm1_lanes"};
  for (std::size_t i = 0; i < n; ++i) {
    const width1::F x[4] = {{all[i]}, {all[n + i]}, {all[2 * n + i]}, {all[3 * n + i]}};
    const float got[4] = {width1::generic::log_lanes(width1::kScalar, x[0]).raw,
                          width1::generic::log1p_lanes(width1::kScalar, x[1]).raw,
                          width1::generic::exp_lanes(width1::kScalar, x[2]).raw,
                          width1::generic::expm1_lanes(width1::kScalar, x[3]).raw};
    const double exact[4] = {std::log(double(x[0].raw)), std::log1p(double(x[1].raw)), std::exp(double(x[2].raw)),
                             std::expm1(double(x[3].raw))};
    for (int k = 0; k < 4; ++k) {
      want[k * n + i] = got[k];
      if (k >= 2 && x[k].raw < -87.6f) {  // below the smallest normal float: 0 (expm1: -1)
        EXPECT_EQ(got[k], k == 2 ? 0.0f : -1.0f) << names[k] << "(" << x[k].raw << ")";
        continue;
      }
      // In units of 2^-24 of the result (of the smallest normal float at least).
      const double ulps = std::abs(double(got[k]) - exact[k]) / std::max(std::abs(exact[k]), double(FLT_MIN)) * 0x1p24;
      if (!std::isnan(worst[k]) && !(ulps <= worst[k])) worst[k] = ulps;  // a NaN sticks
    }
  }
  EXPECT_EQ(want[0], 0.0f) << "log 1";
  EXPECT_EQ(want[n], 0.0f) << "log1p 0";
  EXPECT_EQ(want[2 * n], 1.0f) << "exp 0";
  EXPECT_EQ(want[3 * n], 0.0f) << "expm1 0";
  for (int k = 0; k < 4; ++k) {
    RecordProperty(names[k], std::to_string(worst[k]));
    EXPECT_LT(worst[k], 4.5) << names[k] << " against libm's double function, in units of 2^-24 of the result";
  }
  for (SimdTarget t : supported_simd_targets()) {
    select_simd_target(t);
    std::vector<float> got(4 * n);
    test::simd_log_exp(all.data(), got.data(), n);
    for (int k = 0; k < 4; ++k)
      EXPECT_EQ(std::memcmp(got.data() + k * n, want.data() + k * n, n * sizeof(float)), 0)
          << simd_target_name(t) << ": " << names[k] << " differs from the width-1 code's";
  }
}

// atan2_lanes (core/simd/sampling-inl.h), the environment image's azimuth
// and polar angle in both tracers: within 3e-7 of libm's double atan2 on
// every octant, the axes, signed zeros, ratios from 1e-30 to 1e30 and random
// directions, and the same bits on every target and at width 1.
TEST(SimdTranscendentals, Atan2CloseToLibmAndTheSameBitsOnEveryTarget) {
  const SimdChoice restore;
  std::mt19937 g(20261204);
  std::uniform_real_distribution<float> uniform(-1.0f, 1.0f);
  std::vector<float> y, x;
  for (float a : {0.0f, -0.0f, 1.0f, -1.0f, 1e-30f, -1e-30f, 1e30f, 0.41421356f, 2.4142136f, 3.0f})
    for (float b : {0.0f, -0.0f, 1.0f, -1.0f, 1e-30f, -1e-30f, 1e30f, 0.41421356f, 2.4142136f, -3.0f}) {
      y.push_back(a);
      x.push_back(b);
    }
  while (y.size() < (1u << 16)) {
    y.push_back(uniform(g));
    x.push_back(uniform(g));
  }
  const std::size_t n = y.size();
  std::vector<float> want(n);
  double worst = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    want[i] = width1::generic::atan2_lanes(width1::kScalar, width1::F{y[i]}, width1::F{x[i]}).raw;
    if (y[i] == 0.0f && x[i] == 0.0f) {
      EXPECT_EQ(want[i], 0.0f) << "atan2(0, 0)";
      EXPECT_EQ(std::signbit(want[i]), std::signbit(y[i])) << "atan2(+-0, +-0) keeps y's sign";
      continue;
    }
    worst = std::max(worst, std::abs(double(want[i]) - std::atan2(double(y[i]), double(x[i]))));
  }
  EXPECT_LT(worst, 3e-7) << "atan2_lanes against libm's double atan2";
  for (SimdTarget t : supported_simd_targets()) {
    select_simd_target(t);
    std::vector<float> got(n);
    test::simd_atan2(y.data(), x.data(), got.data(), n);
    EXPECT_EQ(std::memcmp(got.data(), want.data(), n * sizeof(float)), 0)
        << simd_target_name(t) << ": atan2 differs from the width-1 code's";
  }
}

// sin_cos_d and atan2_d (core/simd/spherical-inl.h), the double-precision
// transcendentals of solid-angle sampling in both tracers: within a few ulp
// of libm's on the angles that sampling takes ([-pi, 2 pi], with the ends,
// the quarter turns and their neighbours) and on every octant, axis, signed
// zero and ratio from 1e-300 to 1e300 of atan2, relative to the value (an
// angle near 0 keeps its relative accuracy: a tiny triangle's solid angle is
// 2 atan2 of a tiny ratio); and the same bits on every target and at width 1.
TEST(SimdTranscendentals, DoublePrecisionCloseToLibmAndTheSameBitsOnEveryTarget) {
  const SimdChoice restore;
  constexpr double kPiD = 3.14159265358979323846;
  std::mt19937_64 g(20261204);
  std::uniform_real_distribution<double> angle(-kPiD, 2.0 * kPiD), coord(-1.0, 1.0);
  std::vector<double> x, y;
  for (int q = -2; q <= 4; ++q)
    for (double a : {q * kPiD / 2.0, q * kPiD / 4.0}) {
      for (double v : {a, std::nextafter(a, -10.0), std::nextafter(a, 10.0)}) x.push_back(v);
    }
  for (double v : {1e-300, -1e-300, 1e-20, -1e-20, 1e-8, 0.0, -0.0}) x.push_back(v);
  y.resize(x.size(), 0.5);
  for (double a : {0.0, -0.0, 1.0, -1.0, 1e-300, -1e-300, 1e300, 0.41421356237309503, 2.414213562373095, -3.0, 1e-12})
    for (double b : {0.0, -0.0, 1.0, -1.0, 1e-300, -1e-300, 1e300, 0.41421356237309503, 2.414213562373095, 3.0, 1e-12}) {
      y.push_back(a);
      x.push_back(b);
    }
  while (x.size() < (1u << 16)) {
    x.push_back(angle(g));
    y.push_back(coord(g));
  }
  while (x.size() < (1u << 17)) {  // atan2 of random directions, as angles too
    y.push_back(coord(g));
    x.push_back(coord(g));
  }
  const std::size_t n = x.size();
  std::vector<double> want[3] = {std::vector<double>(n), std::vector<double>(n), std::vector<double>(n)};
  double worst_sin = 0.0, worst_cos = 0.0, worst_atan = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    width1::D1 s, c;
    width1::generic::sin_cos_d(width1::kScalarD, width1::D1{x[i]}, s, c);
    want[0][i] = s.raw, want[1][i] = c.raw;
    want[2][i] = width1::generic::atan2_d(width1::kScalarD, width1::D1{y[i]}, width1::D1{x[i]}).raw;
    // Errors in units of the value's last place (of 2^-53 at least, for
    // sin and cos of exactly 0).
    const auto ulps = [](double got, double exact, double floor) {
      return std::abs(got - exact) / std::max(std::abs(exact), floor) * 0x1p52;
    };
    if (std::abs(x[i]) <= 2.5 * kPiD) {
      worst_sin = std::max(worst_sin, ulps(want[0][i], std::sin(x[i]), 0x1p-53));
      worst_cos = std::max(worst_cos, ulps(want[1][i], std::cos(x[i]), 0x1p-53));
    }
    if (y[i] == 0.0 && x[i] == 0.0) {
      EXPECT_EQ(want[2][i], 0.0) << "atan2(0, 0)";
      EXPECT_EQ(std::signbit(want[2][i]), std::signbit(y[i])) << "atan2(+-0, +-0) keeps y's sign";
      continue;
    }
    // Relative to the smallest normal double at least: a subnormal angle
    // (atan2(1e-12, 1e300)) has fewer bits than a double's.
    worst_atan = std::max(worst_atan, ulps(want[2][i], std::atan2(y[i], x[i]), DBL_MIN));
  }
  EXPECT_LT(worst_sin, 4.0) << "sin_cos_d's sin against libm's, in ulp";
  EXPECT_LT(worst_cos, 4.0) << "sin_cos_d's cos against libm's, in ulp";
  EXPECT_LT(worst_atan, 4.0) << "atan2_d against libm's, in ulp";
  for (SimdTarget t : supported_simd_targets()) {
    select_simd_target(t);
    std::vector<double> got[3] = {std::vector<double>(n), std::vector<double>(n), std::vector<double>(n)};
    test::simd_trig_d(x.data(), y.data(), got[0].data(), got[1].data(), got[2].data(), n);
    for (int k = 0; k < 3; ++k)
      EXPECT_EQ(std::memcmp(got[k].data(), want[k].data(), n * sizeof(double)), 0)
          << simd_target_name(t) << ": output " << k << " (sin, cos, atan2) differs from the width-1 code's";
  }
}

// The Disney model in lanes (core/bsdf/disney-inl.h): eval, pdf, the lobe
// probabilities and sample at every target give the bits of core's
// disney::eval, pdf, lobe_probabilities and sample (the same source at
// width 1), on closures from the parameters' corners and at random, views
// from normal to 1e-6 of grazing, directions on both sides, and u at 0 and
// just below 1. NaN equals NaN (none is expected).
TEST(SimdDisney, EveryTargetComputesTheBitsOfCoresDisneyModel) {
  const SimdChoice restore;
  std::mt19937 g(1203);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  const auto unit = [&](float z) {
    const float phi = 6.2831853f * uniform(g), s = std::sqrt(std::max(0.0f, 1.0f - z * z));
    return vec3(s * std::cos(phi), s * std::sin(phi), z);
  };
  const float corner[] = {0.0f, 1.0f};
  std::vector<disney::Closure> closures;
  for (float metallic : corner)
    for (float roughness : {0.0f, 0.25f, 1.0f})
      for (float clearcoat : corner) {
        DisneyParams p;
        p.metallic = metallic;
        p.roughness = roughness;
        p.clearcoat = clearcoat;
        p.sheen = 1.0f - metallic;
        p.anisotropic = roughness == 0.25f ? 0.9f : 0.0f;
        p.subsurface = roughness;
        closures.push_back(disney::make_closure(p));
      }
  while (closures.size() < 64) {
    DisneyParams p;
    p.base_color = Spectrum(uniform(g), uniform(g), uniform(g));
    for (float* x : {&p.metallic, &p.subsurface, &p.specular, &p.specular_tint, &p.roughness, &p.anisotropic, &p.sheen,
                     &p.sheen_tint, &p.clearcoat, &p.clearcoat_gloss})
      *x = uniform(g);
    closures.push_back(disney::make_closure(p));
  }
  constexpr std::size_t kPerClosure = 1024;  // a multiple of every vector width
  const std::size_t n = closures.size() * kPerClosure;
  std::vector<float> in(test::kDisneyKernelInputs * n);
  const auto put = [&](int k, std::size_t i, float v) { in[k * n + i] = v; };
  for (std::size_t ci = 0; ci < closures.size(); ++ci) {
    const disney::Closure& c = closures[ci];
    for (std::size_t j = 0; j < kPerClosure; ++j) {
      const std::size_t i = ci * kPerClosure + j;
      const float fields[18] = {c.diffuse.x, c.diffuse.y, c.diffuse.z, c.roughness,  c.subsurface,       c.sheen.x,
                                c.sheen.y,   c.sheen.z,   c.specular,  c.spec0.x,    c.spec0.y,          c.spec0.z,
                                c.ax,        c.ay,        c.clearcoat, c.clearcoat_alpha, c.clearcoat_log_a2,
                                c.clearcoat_log2_a2};
      for (int k = 0; k < 18; ++k) put(k, i, fields[k]);
      const float views[] = {1.0f, 0.5f, 1e-2f, 1e-4f, 1e-6f};
      const vec3 wo = unit(j < 5 ? views[j] : uniform(g));
      const vec3 wi = unit(j % 7 == 0 ? -uniform(g) : uniform(g));
      const float u[3] = {uniform(g), j % 11 == 0 ? 0.0f : uniform(g), j % 13 == 0 ? std::nextafter(1.0f, 0.0f) : uniform(g)};
      for (int k = 0; k < 3; ++k) put(18 + k, i, wo[k]), put(21 + k, i, wi[k]), put(24 + k, i, u[k]);
    }
  }
  for (const auto& [clearcoat, cospow] : {std::pair{true, false}, {false, false}, {true, true}, {false, true}}) {
    const BsdfSampling sampling = cospow ? BsdfSampling::Cospow : BsdfSampling::Vndf;
    const std::string model =
        std::string(clearcoat ? " (clearcoat" : " (no clearcoat") + (cospow ? ", cospow)" : ", vndf)");
    // The width-1 code: what both tracers' scalar paths call.
    std::vector<float> want(test::kDisneyKernelOutputs * n);
    for (std::size_t i = 0; i < n; ++i) {
      const disney::Closure& c = closures[i / kPerClosure];
      const vec3 wo(in[18 * n + i], in[19 * n + i], in[20 * n + i]), wi(in[21 * n + i], in[22 * n + i], in[23 * n + i]);
      const unsigned features = clearcoat ? disney::kDisneyLobes | disney::kClearcoat : disney::kDisneyLobes;
      const Spectrum f = clearcoat ? disney::eval<disney::kDisneyLobes | disney::kClearcoat>(c, wo, wi)
                                   : disney::eval<disney::kDisneyLobes>(c, wo, wi);
      const float pdf = clearcoat ? disney::pdf<disney::kDisneyLobes | disney::kClearcoat>(c, wo, wi, sampling)
                                  : disney::pdf<disney::kDisneyLobes>(c, wo, wi, sampling);
      const disney::LobeProbabilities p = disney::lobe_probabilities(c, wo, features, sampling);
      const float u_lobe = in[24 * n + i];
      const vec2 u(in[25 * n + i], in[26 * n + i]);
      const auto s = clearcoat ? disney::sample<disney::kDisneyLobes | disney::kClearcoat>(c, wo, u_lobe, u, sampling)
                               : disney::sample<disney::kDisneyLobes>(c, wo, u_lobe, u, sampling);
      const float family = !s                                   ? -1.0f
                           : s->lobe == Lobe::Specular          ? 1.0f
                           : s->lobe == Lobe::Clearcoat         ? 2.0f
                                                                : 0.0f;
      const float v[12] = {f.x, f.y, f.z, pdf, p[0], p[1], p[2], s ? s->wi.x : 0.0f, s ? s->wi.y : 0.0f,
                           s ? s->wi.z : 0.0f, s ? 1.0f : 0.0f, family};
      for (int k = 0; k < 12; ++k) want[k * n + i] = v[k];
    }
    const char* names[12] = {"f.r", "f.g", "f.b", "pdf", "p diffuse", "p specular", "p clearcoat",
                             "wi.x", "wi.y", "wi.z", "drawn", "family"};
    for (SimdTarget t : supported_simd_targets()) {
      if (t == SimdTarget::Scalar) continue;  // Highway's one-lane target: the kernels' tails elsewhere, not here
      select_simd_target(t);
      std::vector<float> got(test::kDisneyKernelOutputs * n, std::numeric_limits<float>::quiet_NaN());
      test::simd_disney(clearcoat, cospow, in.data(), got.data(), n);
      std::size_t differ = 0;
      for (std::size_t i = 0; i < n; ++i) {
        const bool drawn = want[10 * n + i] != 0.0f;
        for (int k = 0; k < 12; ++k) {
          if ((k >= 7 && k <= 9 && !drawn) || (k == 11 && !drawn)) continue;  // no sample: its direction is not read
          const float a = got[k * n + i], b = want[k * n + i];
          const bool same = std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b) || (std::isnan(a) && std::isnan(b));
          if (!same && differ++ < 5)
            ADD_FAILURE() << simd_target_name(t) << model << ": " << names[k] << " of input " << i
                          << " is " << a << ", the width-1 code gives " << b;
        }
      }
      EXPECT_EQ(differ, 0u) << simd_target_name(t) << model << ": values differing, of "
                            << 12 * n;
    }
  }
}

}  // namespace
}  // namespace pathlab
