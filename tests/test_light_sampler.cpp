// Light selection: the probability the estimators divide by is the
// probability with which a light is really picked.
#include "core/compiled_scene.h"
#include "core/rng.h"
#include "core/sampling.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include <limits>
#include <map>

namespace pathlab {
namespace {

// Two emitting triangles whose powers differ by `ratio`.
Scene two_lights(float ratio) {
  Scene scene;
  scene.name = "two-lights";
  scene.materials.push_back(Material{"bright", MaterialType::Emissive, Spectrum(0.0f), Spectrum(ratio), false});
  scene.materials.push_back(Material{"dim", MaterialType::Emissive, Spectrum(0.0f), Spectrum(1.0f), false});
  for (std::uint32_t m = 0; m < 2; ++m) {
    Shape s;
    s.description = "light";
    s.material = m;
    const float x = 3.0f * static_cast<float>(m);
    s.mesh = {{{x, 0, 0}, {x + 1, 0, 0}, {x, 1, 0}}, {{0, 1, 2}}};
    scene.shapes.push_back(s);
  }
  return scene;
}

// How many of the 2^24 values a random number can take pick each of the two
// lights. The pick is monotone in u: binary-search the first value that
// picks light 1.
std::map<std::uint32_t, std::uint64_t> count_every_pick(const LightSampler& lights) {
  auto picks_second = [&](std::uint64_t k) {
    const auto ls = lights.sample(vec3(0.3f, 0.3f, 1.0f), to_unit_float(k << 40), vec2(0.3f, 0.3f));
    return ls && ls->light == 1;
  };
  std::uint64_t lo = 0, hi = std::uint64_t{1} << 24;  // first k picking light 1 lies in [lo, hi]
  while (lo < hi) {
    const std::uint64_t mid = (lo + hi) / 2;
    if (picks_second(mid)) hi = mid;
    else lo = mid + 1;
  }
  std::map<std::uint32_t, std::uint64_t> counts;
  if (lo > 0) counts[0] = lo;
  if (lo < (std::uint64_t{1} << 24)) counts[1] = (std::uint64_t{1} << 24) - lo;
  return counts;
}

// The pick is a branch-free binary search written once for the lanes and
// core (pick_cdf): it must give std::upper_bound's entry (clamped to the
// last) for every u, including u equal to an entry, runs of equal entries
// (lights of power 0), 0, 1, the infinities and NaN (the last entry).
TEST(LightSampler, PickFromACdfIsUpperBoundsEntry) {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  std::uint64_t state = 12345;
  auto next = [&state] { return static_cast<float>((state = state * 6364136223846793005ull + 1442695040888963407ull) >> 40) * 0x1p-24f; };
  for (std::size_t n : {1u, 2u, 3u, 5u, 16u, 17u, 100u, 1000u}) {
    std::vector<float> cdf(n);
    float running = 0.0f;
    for (std::size_t i = 0; i < n; ++i) cdf[i] = running += (i % 3 == 1 ? 0.0f : next());  // runs of ties
    for (float& c : cdf) c /= running;
    cdf.back() = 1.0f;
    std::vector<float> us = {0.0f, -0.0f, 1.0f, 0x1p-24f, 1.0f - 0x1p-24f, inf, -inf, nan};
    for (float c : cdf) us.insert(us.end(), {c, std::nextafter(c, 0.0f), std::nextafter(c, 2.0f)});
    for (int k = 0; k < 200; ++k) us.push_back(next());
    for (float u : us) {
      const std::size_t expected =
          std::min<std::size_t>(static_cast<std::size_t>(std::upper_bound(cdf.begin(), cdf.end(), u) - cdf.begin()), n - 1);
      ASSERT_EQ(LightSampler::pick(cdf, u), expected) << n << " entries, u " << u;
    }
  }
}

TEST(LightSampler, PickProbabilityIsWhatThePdfDividesBy) {
  for (float ratio : {1.0f, 3.0f, 1e6f}) {
    const CompiledScene scene(two_lights(ratio));
    const auto counts = count_every_pick(scene.lights());
    const vec3 ref(0.3f, 0.3f, 1.0f);
    for (std::uint32_t light = 0; light < 2; ++light) {
      // pdf() of a point on that light, divided by its area density in
      // solid angle, leaves the pick probability.
      Surfel hit;
      hit.shape = light;
      hit.prim = 0;
      hit.p = vec3(3.0f * static_cast<float>(light) + 0.25f, 0.25f, 0.0f);
      hit.n = vec3(0, 0, 1);
      const vec3 d = hit.p - ref;
      const float dist = glm::length(d);
      const float pick = scene.lights().pdf(ref, hit) / area_to_solid_angle(2.0f, dist, glm::dot(hit.n, d) / dist);
      const double frequency = double(counts.count(light) ? counts.at(light) : 0) * 0x1p-24;
      EXPECT_NEAR(pick, frequency, 1e-6 * frequency + 1e-12) << "ratio " << ratio << " light " << light;
    }
  }
}

TEST(LightSampler, ALightTooDimToPickHasPdfZeroAndIsReported) {
  const CompiledScene scene(two_lights(1e9f));
  EXPECT_EQ(scene.lights().unsampled_light_count(), 1u);
  EXPECT_EQ(count_every_pick(scene.lights()).count(1), 0u);
  Surfel hit;
  hit.shape = 1;
  hit.p = vec3(3.25f, 0.25f, 0.0f);
  hit.n = vec3(0, 0, 1);
  EXPECT_EQ(scene.lights().pdf(vec3(3.3f, 0.3f, 1.0f), hit), 0.0f);
}

// Radiance up to FLT_MAX is a valid scene value: the powers that pick the
// lights must not overflow (pi * 2e38 did in float, and every pmf became NaN:
// a NaN MIS weight on every path that hit the lamp).
TEST(LightSampler, PowersOfRadianceNearFloatMaxStayFinite) {
  for (float big : {2e38f, std::numeric_limits<float>::max()}) {
    Scene scene = two_lights(1.0f);
    scene.materials[0].emission = Spectrum(big);
    scene.materials[1].emission = Spectrum(big / 4.0f);
    const CompiledScene compiled(std::move(scene));
    const auto counts = count_every_pick(compiled.lights());
    // Equal areas: picked 4 : 1.
    EXPECT_NEAR(double(counts.at(0)) * 0x1p-24, 0.8, 1e-6) << big;
    Surfel hit;
    hit.shape = 0;
    hit.p = vec3(0.25f, 0.25f, 0.0f);
    hit.n = vec3(0, 0, 1);
    const float pdf = compiled.lights().pdf(vec3(0.3f, 0.3f, 1.0f), hit);
    EXPECT_TRUE(std::isfinite(pdf) && pdf > 0.0f) << big << ": pdf " << pdf;
  }
}

}  // namespace
}  // namespace pathlab
