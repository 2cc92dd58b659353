// The counter-based random numbers of core/rng.h: determinism, range,
// uniformity along every axis of the key (seed, pixel, sample, bounce, dim),
// and independence between dimensions and between neighbouring keys.
//
// Every statistical test uses fixed keys, so it is deterministic; its
// threshold is the critical value of the statistic's null distribution at a
// family-wise false-alarm rate kAlpha, split over the comparisons of the test
// by the Sidak correction. The RngPlantedBugs suite runs the same checks on
// deliberately broken generators and expects them to fail: it shows each
// check has the power to catch the class of bug it is there for.
#include "core/rng.h"
#include "tests/stat_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace pathlab {
namespace {

// --- statistics ----------------------------------------------------------------

using test::chi2_critical;
using test::chi2_equal;
using test::poisson_sf;
using test::sidak;
using test::z_critical;

// Family-wise false-alarm rate of each statistical test.
constexpr double kAlpha = 1e-3;

TEST(RngStats, CriticalValuesMatchTables) {
  // Abramowitz & Stegun table 26.8; chi2(2) has the closed form -2 ln(alpha).
  EXPECT_NEAR(chi2_critical(1, 0.05), 3.841459, 1e-5);
  EXPECT_NEAR(chi2_critical(10, 0.01), 23.209251, 1e-5);
  EXPECT_NEAR(chi2_critical(100, 0.05), 124.342113, 1e-5);
  EXPECT_NEAR(chi2_critical(2, 1e-3), -2.0 * std::log(1e-3), 1e-9);
  EXPECT_NEAR(z_critical(0.05), 1.959964, 1e-6);
  EXPECT_NEAR(z_critical(1e-3), 3.290527, 1e-6);
  EXPECT_NEAR(sidak(0.05, 1), 0.05, 1e-15);
  EXPECT_NEAR(1.0 - std::pow(1.0 - sidak(0.05, 78), 78), 0.05, 1e-12);
  EXPECT_NEAR(poisson_sf(1, 2.0), 1.0 - std::exp(-2.0), 1e-15);
  EXPECT_NEAR(poisson_sf(3, 2.0), 1.0 - 5.0 * std::exp(-2.0), 1e-15);
}

// --- the generator under test, as a value ------------------------------------------

using UFn = float (*)(std::uint64_t seed, std::uint32_t pixel, std::uint32_t sample,
                      std::uint32_t bounce, Dim dim);

constexpr std::uint32_t kDims = static_cast<std::uint32_t>(Dim::Count);
constexpr Dim dim(std::uint32_t i) { return static_cast<Dim>(i); }

struct Key {
  std::uint64_t seed;
  std::uint32_t pixel, sample, bounce;
};
float eval(UFn u, const Key& k, Dim d) { return u(k.seed, k.pixel, k.sample, k.bounce, d); }

enum class Axis { Seed, Pixel, Sample, Bounce };
Key step(Key k, Axis axis, std::uint32_t i) {
  switch (axis) {
    case Axis::Seed: k.seed += i; break;
    case Axis::Pixel: k.pixel += i; break;
    case Axis::Sample: k.sample += i; break;
    case Axis::Bounce: k.bounce += i; break;
  }
  return k;
}

constexpr Key kBase{0x5eed1234ull, 1234, 5, 2};

// 64-bin chi-square of n draws, or a failure if a draw leaves [0, 1).
testing::AssertionResult uniform_64(const std::function<float(std::uint32_t)>& draw, std::uint32_t n,
                                    double crit) {
  std::vector<std::uint32_t> counts(64, 0);
  for (std::uint32_t i = 0; i < n; ++i) {
    const float x = draw(i);
    if (!(x >= 0.0f && x < 1.0f)) return testing::AssertionFailure() << "draw " << i << " = " << x;
    ++counts[static_cast<std::size_t>(x * 64.0f)];
  }
  const double stat = chi2_equal(counts, n);
  if (stat > crit) return testing::AssertionFailure() << "chi2(63) = " << stat << " > " << crit;
  return testing::AssertionSuccess();
}

// Uniformity along one axis of the key, for every named dimension: 1e5 draws
// into 64 bins, one comparison per dimension.
testing::AssertionResult uniform_along(UFn u, Axis axis) {
  constexpr std::uint32_t kN = 100000;
  const double crit = chi2_critical(63, sidak(kAlpha, kDims));
  std::ostringstream failures;
  for (std::uint32_t d = 0; d < kDims; ++d) {
    const auto r = uniform_64([&](std::uint32_t i) { return eval(u, step(kBase, axis, i), dim(d)); }, kN, crit);
    if (!r) failures << "dim " << d << ": " << r.message() << "\n";
  }
  if (!failures.str().empty()) return testing::AssertionFailure() << failures.str();
  return testing::AssertionSuccess();
}

// Uniformity along the dimension index itself (any 32-bit value, not only
// the named ones): one key, 1e5 consecutive dimension numbers.
testing::AssertionResult uniform_along_dim_index(UFn u) {
  return uniform_64([&](std::uint32_t i) { return eval(u, kBase, dim(i)); }, 100000,
                    chi2_critical(63, kAlpha));
}

struct PairCase {
  std::string name;
  std::function<std::pair<float, float>(std::uint32_t)> draw;
};

// Independence of two uniform variables: chi-square of n pairs on 16x16
// equal cells (the joint of independent uniforms is uniform, 255 dof),
// Sidak-corrected over the cases.
testing::AssertionResult jointly_uniform(const std::vector<PairCase>& cases) {
  constexpr std::uint32_t kN = 16384;  // 64 expected per cell
  const double crit = chi2_critical(255, sidak(kAlpha, cases.size()));
  std::ostringstream failures;
  for (const PairCase& c : cases) {
    std::vector<std::uint32_t> counts(256, 0);
    for (std::uint32_t i = 0; i < kN; ++i) {
      const auto [a, b] = c.draw(i);
      ++counts[static_cast<std::size_t>(a * 16.0f) * 16 + static_cast<std::size_t>(b * 16.0f)];
    }
    const double stat = chi2_equal(counts, kN);
    if (stat > crit) failures << c.name << ": chi2(255) = " << stat << " > " << crit << "\n";
  }
  if (!failures.str().empty()) return testing::AssertionFailure() << failures.str();
  return testing::AssertionSuccess();
}

// Pearson correlation of n pairs. Under independence sqrt(n) r is
// asymptotically standard normal, whatever the marginals; two-sided bound
// Sidak-corrected over the cases.
testing::AssertionResult uncorrelated(const std::vector<PairCase>& cases) {
  constexpr std::uint32_t kN = 65536;
  const double bound = z_critical(sidak(kAlpha, cases.size()));
  std::ostringstream failures;
  for (const PairCase& c : cases) {
    double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
    for (std::uint32_t i = 0; i < kN; ++i) {
      const auto [a, b] = c.draw(i);
      sa += a;
      sb += b;
      saa += double(a) * a;
      sbb += double(b) * b;
      sab += double(a) * b;
    }
    const double n = kN;
    const double cov = sab - sa * sb / n, va = saa - sa * sa / n, vb = sbb - sb * sb / n;
    const double z = cov / std::sqrt(va * vb) * std::sqrt(n);
    if (!(std::abs(z) <= bound)) failures << c.name << ": sqrt(n) r = " << z << ", bound " << bound << "\n";
  }
  if (!failures.str().empty()) return testing::AssertionFailure() << failures.str();
  return testing::AssertionSuccess();
}

// Every pair of named dimensions drawn from the same key at bounce 1.
std::vector<PairCase> dim_pairs(UFn u) {
  std::vector<PairCase> cases;
  for (std::uint32_t a = 0; a < kDims; ++a)
    for (std::uint32_t b = a + 1; b < kDims; ++b)
      cases.push_back({"dims " + std::to_string(a) + "," + std::to_string(b), [=](std::uint32_t i) {
                         const Key k{kBase.seed, i % 256, i / 256, 1};
                         return std::pair(eval(u, k, dim(a)), eval(u, k, dim(b)));
                       }});
  return cases;
}

// For every named dimension, the same dimension at two neighbouring keys.
// Draw i uses its own pair of keys, so the n pairs are independent.
std::vector<PairCase> neighbour_pairs(UFn u) {
  constexpr std::uint32_t kWidth = 640;
  std::vector<PairCase> cases;
  auto add = [&](const std::string& what, std::uint32_t d, auto keys) {
    cases.push_back({what + ", dim " + std::to_string(d), [=](std::uint32_t i) {
                       const auto [k0, k1] = keys(i);
                       return std::pair(eval(u, k0, dim(d)), eval(u, k1, dim(d)));
                     }});
  };
  for (std::uint32_t d = 0; d < kDims; ++d) {
    add("pixel p, p+1", d, [](std::uint32_t i) {
      return std::pair(Key{kBase.seed, 2 * i, 3, 1}, Key{kBase.seed, 2 * i + 1, 3, 1});
    });
    add("pixel p, p+width", d, [](std::uint32_t i) {
      const std::uint32_t p = (i / kWidth) * 2 * kWidth + i % kWidth;
      return std::pair(Key{kBase.seed, p, 3, 1}, Key{kBase.seed, p + kWidth, 3, 1});
    });
    add("sample s, s+1", d, [](std::uint32_t i) {
      return std::pair(Key{kBase.seed, 777, 2 * i, 1}, Key{kBase.seed, 777, 2 * i + 1, 1});
    });
    for (std::uint32_t b : {0u, 1u, 7u})
      add("bounce " + std::to_string(b) + "," + std::to_string(b + 1), d, [b](std::uint32_t i) {
        return std::pair(Key{kBase.seed, i, 3, b}, Key{kBase.seed, i, 3, b + 1});
      });
    add("seed, seed+1", d, [](std::uint32_t i) {
      return std::pair(Key{kBase.seed, i, 3, 1}, Key{kBase.seed + 1, i, 3, 1});
    });
  }
  return cases;
}

// Distinct keys on a grid that straddles the 16-bit boundary of pixel and
// sample must give (24-bit) values that coincide only as often as
// independent uniform values would: the number of equal pairs among n values
// is Poisson with mean n(n-1)/2 * 2^-24. Structural aliasing of keys (two
// fields packed into overlapping bits, a field xor-ed into an unmixed state)
// makes whole families of keys share their numbers.
testing::AssertionResult no_structured_collisions(UFn u) {
  std::vector<std::uint32_t> small_and_large;
  for (std::uint32_t i = 0; i < 8; ++i) small_and_large.push_back(i);
  for (std::uint32_t i = 0; i < 8; ++i) small_and_large.push_back(65536 + i);
  std::vector<float> values;
  for (const std::uint32_t p : small_and_large)
    for (const std::uint32_t s : small_and_large)
      for (std::uint32_t b = 0; b < 8; ++b)
        for (std::uint32_t d = 0; d < kDims; ++d) values.push_back(u(kBase.seed, p, s, b, dim(d)));
  std::sort(values.begin(), values.end());
  long equal_pairs = 0;
  for (std::size_t i = 0; i < values.size();) {
    std::size_t j = i + 1;
    while (j < values.size() && values[j] == values[i]) ++j;
    equal_pairs += static_cast<long>((j - i) * (j - i - 1) / 2);
    i = j;
  }
  const double n = static_cast<double>(values.size());
  const double lambda = n * (n - 1.0) / 2.0 * 0x1p-24;
  long crit = 0;
  while (poisson_sf(crit, lambda) > kAlpha) ++crit;  // reject when equal_pairs >= crit
  if (equal_pairs >= crit)
    return testing::AssertionFailure() << equal_pairs << " equal pairs among " << values.size()
                                       << " values; Poisson mean " << lambda << ", critical " << crit;
  return testing::AssertionSuccess();
}

// --- determinism and range ---------------------------------------------------

TEST(RngDeterminism, MixerIsTheSplitMix64Finaliser) {
  // The first outputs of splitmix64 seeded with 0 (state += golden, then
  // mix), as published with the reference implementation.
  constexpr std::uint64_t kGolden = 0x9e3779b97f4a7c15ull;
  EXPECT_EQ(mix64(kGolden), 0xe220a8397b1dcdafull);
  EXPECT_EQ(mix64(2 * kGolden), 0x6e789e6aa1b965f4ull);
  EXPECT_EQ(mix64(3 * kGolden), 0x06c45d188009454full);
  EXPECT_EQ(mix64(0), 0u);
}

TEST(RngDeterminism, ValueIsTheDocumentedKeyChain) {
  // u = to_unit_float(mix(mix(mix(seed + golden) ^ (pixel << 32 | sample))
  //                       ^ (bounce << 32 | dim))), as rng.h documents:
  // both tracers, and any replay, depend on exactly this function.
  for (const std::uint64_t seed : {0ull, 1ull, 0x5eed1234ull, ~0ull})
    for (const std::uint32_t pixel : {0u, 1u, 307199u, 0xffffffffu})
      for (const std::uint32_t sample : {0u, 1u, 65536u, 0xffffffffu})
        for (const std::uint32_t bounce : {0u, 1u, 63u})
          for (std::uint32_t d = 0; d < kDims; ++d) {
            const std::uint64_t h1 = mix64(mix64(seed + 0x9e3779b97f4a7c15ull) ^
                                           (std::uint64_t{pixel} << 32 | sample));
            const std::uint64_t h = mix64(h1 ^ (std::uint64_t{bounce} << 32 | d));
            const float expected = static_cast<float>(h >> 40) / 16777216.0f;
            ASSERT_EQ(sample_u(seed, pixel, sample, bounce, dim(d)), expected)
                << seed << " " << pixel << " " << sample << " " << bounce << " " << d;
          }
}

TEST(RngDeterminism, SameKeyGivesSameValueInAnyOrder) {
  // Compile-time and run-time evaluation agree.
  constexpr float kAtCompileTime = sample_u(42, 7, 3, 1, Dim::DirectionX);
  volatile std::uint64_t seed = 42;  // defeats constant folding
  EXPECT_EQ(sample_u(seed, 7, 3, 1, Dim::DirectionX), kAtCompileTime);

  // Forward and backward over a block of keys, with unrelated draws between.
  std::vector<float> forward;
  for (std::uint32_t i = 0; i < 4096; ++i) forward.push_back(sample_u(9, i / 64, i % 64, i % 5, dim(i % kDims)));
  for (std::uint32_t i = 4096; i-- > 0;) {
    (void)sample_u(10, i, i, i, Dim::Roulette);
    ASSERT_EQ(sample_u(9, i / 64, i % 64, i % 5, dim(i % kDims)), forward[i]) << i;
  }
}

TEST(RngStream, GetMatchesSampleU) {
  for (const std::uint64_t seed : {0ull, 1ull, 0x5eed1234ull, ~0ull})
    for (const std::uint32_t pixel : {0u, 1u, 12345u, 0xffffffffu})
      for (const std::uint32_t sample : {0u, 1u, 999u, 0xffffffffu}) {
        const SampleStream stream(seed, pixel, sample);
        for (const std::uint32_t bounce : {0u, 1u, 2u, 100u, 0xffffffffu})
          for (std::uint32_t d = 0; d < kDims; ++d)
            ASSERT_EQ(stream.get(bounce, dim(d)), sample_u(seed, pixel, sample, bounce, dim(d)))
                << seed << " " << pixel << " " << sample << " " << bounce << " " << d;
      }
}

using ToUnitFn = float (*)(std::uint64_t);

// The hash-to-float conversion: exact multiples of 2^-24 in [0, 1), monotone,
// with the largest hash below 1.
testing::AssertionResult converts_into_unit_interval(ToUnitFn f) {
  if (f(0) != 0.0f) return testing::AssertionFailure() << "f(0) = " << f(0);
  if (!(f(~0ull) < 1.0f)) return testing::AssertionFailure() << "f(2^64 - 1) = " << f(~0ull) << ", not < 1";
  if (f(~0ull) != 1.0f - 0x1p-24f) return testing::AssertionFailure() << "f(2^64 - 1) = " << f(~0ull);
  if (f(1ull << 40) != 0x1p-24f) return testing::AssertionFailure() << "f(2^40) = " << f(1ull << 40);
  for (std::uint64_t top = 0; top < (1ull << 24); top += 4093) {
    const std::uint64_t h = top << 40 | 0xffffffffffull;
    if (f(h) != static_cast<float>(top) * 0x1p-24f) return testing::AssertionFailure() << "f(" << h << ") = " << f(h);
  }
  return testing::AssertionSuccess();
}

TEST(RngRange, ConversionStaysBelowOne) { EXPECT_TRUE(converts_into_unit_interval(to_unit_float)); }

TEST(RngRange, ValuesAreInUnitInterval) {
  for (std::uint32_t i = 0; i < 200000; ++i) {
    const float u = sample_u(i / 1000, i, i * 7, i % 9, dim(i % kDims));
    ASSERT_TRUE(u >= 0.0f && u < 1.0f) << i << ": " << u;
  }
}

// --- uniformity ----------------------------------------------------------------------

TEST(RngUniformity, AlongPixels) { EXPECT_TRUE(uniform_along(sample_u, Axis::Pixel)); }
TEST(RngUniformity, AlongSamples) { EXPECT_TRUE(uniform_along(sample_u, Axis::Sample)); }
TEST(RngUniformity, AlongBounces) { EXPECT_TRUE(uniform_along(sample_u, Axis::Bounce)); }
TEST(RngUniformity, AlongSeeds) { EXPECT_TRUE(uniform_along(sample_u, Axis::Seed)); }
TEST(RngUniformity, AlongDimIndex) { EXPECT_TRUE(uniform_along_dim_index(sample_u)); }

// --- independence --------------------------------------------------------------------

TEST(RngIndependence, AllPairsOfDimsAtOneBounce) { EXPECT_TRUE(jointly_uniform(dim_pairs(sample_u))); }
TEST(RngIndependence, NeighbouringPixelsSamplesBouncesSeeds) {
  EXPECT_TRUE(jointly_uniform(neighbour_pairs(sample_u)));
}
TEST(RngIndependence, NoStructuredCollisions) { EXPECT_TRUE(no_structured_collisions(sample_u)); }

TEST(RngCorrelation, BetweenDims) { EXPECT_TRUE(uncorrelated(dim_pairs(sample_u))); }
TEST(RngCorrelation, BetweenNeighbours) { EXPECT_TRUE(uncorrelated(neighbour_pairs(sample_u))); }

// --- planted bugs: each check above must catch the bugs it is there for ----------

constexpr std::uint64_t kGolden = 0x9e3779b97f4a7c15ull;
std::uint64_t good_key(std::uint64_t seed, std::uint32_t p, std::uint32_t s) {
  return mix64(mix64(seed + kGolden) ^ (std::uint64_t{p} << 32 | s));
}
std::uint64_t lane(std::uint32_t b, Dim d) { return std::uint64_t{b} << 32 | static_cast<std::uint32_t>(d); }

// The last mix dropped: the top bits hardly depend on bounce and dim.
float no_final_mix(std::uint64_t seed, std::uint32_t p, std::uint32_t s, std::uint32_t b, Dim d) {
  return to_unit_float(good_key(seed, p, s) ^ lane(b, d));
}
// The key not mixed after injecting (pixel, sample): (p, s, b, d) and
// (p^1, s, b^1, d) hash the same word.
float unmixed_key(std::uint64_t seed, std::uint32_t p, std::uint32_t s, std::uint32_t b, Dim d) {
  return to_unit_float(mix64(mix64(seed + kGolden) ^ (std::uint64_t{p} << 32 | s) ^ lane(b, d)));
}
// Pixel and sample packed into overlapping bits.
float overlapping_fields(std::uint64_t seed, std::uint32_t p, std::uint32_t s, std::uint32_t b, Dim d) {
  return to_unit_float(mix64(mix64(mix64(seed + kGolden) ^ (std::uint64_t{p} << 16 | s)) ^ lane(b, d)));
}
// The sample index left out of the key.
float sample_ignored(std::uint64_t seed, std::uint32_t p, std::uint32_t, std::uint32_t b, Dim d) {
  return sample_u(seed, p, 0, b, d);
}
// The bounce left out of the key.
float bounce_ignored(std::uint64_t seed, std::uint32_t p, std::uint32_t s, std::uint32_t, Dim d) {
  return sample_u(seed, p, s, 0, d);
}
// One bit too many shifted off: values in [0, 1/2).
float half_range(std::uint64_t seed, std::uint32_t p, std::uint32_t s, std::uint32_t b, Dim d) {
  return static_cast<float>(mix64(good_key(seed, p, s) ^ lane(b, d)) >> 41) * 0x1p-24f;
}
// A weak linear hash: neighbouring keys give values on a lattice.
float linear_hash(std::uint64_t seed, std::uint32_t p, std::uint32_t s, std::uint32_t b, Dim d) {
  const std::uint64_t x = seed * 0x632be59bd9b4e019ull + p * 0x8cb92ba72f3d8dd7ull + s * 0xd1b54a32d192ed03ull +
                          b * 0xaef17502108ef2d9ull + static_cast<std::uint32_t>(d) * 0xf1357aea2e62a9c5ull;
  return to_unit_float(x * kGolden);
}
// DirectionY repeats DirectionX for one key in 32.
float leaky_dims(std::uint64_t seed, std::uint32_t p, std::uint32_t s, std::uint32_t b, Dim d) {
  if (d == Dim::DirectionY && (good_key(seed, p, s) & 31) == 0) d = Dim::DirectionX;
  return sample_u(seed, p, s, b, d);
}
// A conversion that rounds the largest hashes up to 1.0.
float float_of_whole_hash(std::uint64_t h) { return static_cast<float>(h) * 0x1p-64f; }

TEST(RngPlantedBugs, DroppedFinalMixIsCaught) {
  EXPECT_FALSE(uniform_along_dim_index(no_final_mix));
  EXPECT_FALSE(jointly_uniform(dim_pairs(no_final_mix)));
  EXPECT_FALSE(uncorrelated(dim_pairs(no_final_mix)));
}
TEST(RngPlantedBugs, KeyAliasingIsCaught) {
  EXPECT_FALSE(no_structured_collisions(unmixed_key));
  EXPECT_FALSE(no_structured_collisions(overlapping_fields));
}
TEST(RngPlantedBugs, IgnoredKeyFieldIsCaught) {
  EXPECT_FALSE(uniform_along(sample_ignored, Axis::Sample));
  EXPECT_FALSE(uniform_along(bounce_ignored, Axis::Bounce));
  EXPECT_FALSE(jointly_uniform(neighbour_pairs(sample_ignored)));
  EXPECT_FALSE(jointly_uniform(neighbour_pairs(bounce_ignored)));
}
TEST(RngPlantedBugs, BiasedRangeIsCaught) {
  EXPECT_FALSE(uniform_along(half_range, Axis::Pixel));
  EXPECT_FALSE(converts_into_unit_interval(float_of_whole_hash));
}
TEST(RngPlantedBugs, LatticeStructureIsCaught) { EXPECT_FALSE(jointly_uniform(neighbour_pairs(linear_hash))); }
TEST(RngPlantedBugs, WeakDimCorrelationIsCaught) {
  EXPECT_FALSE(jointly_uniform(dim_pairs(leaky_dims)));
  EXPECT_FALSE(uncorrelated(dim_pairs(leaky_dims)));
}

}  // namespace
}  // namespace pathlab
