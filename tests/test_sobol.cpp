// The zsobol sampler (core/sobol.h, core/rng.h): Sobol's first two
// dimensions against closed forms, the (0, m, 2)-net property of the plain
// and the scrambled points, the nested scrambling and digit permutation,
// the Morton layout (a 2x2 block of pixels is one net), the sample
// contract (pure function, independent unchanged bit for bit, both tracers
// the same paths, images the same bits for any thread count and wave size)
// and a convergence rate steeper than Monte Carlo's on a smooth integrand.
#include "core/compiled_scene.h"
#include "core/film.h"
#include "core/parallel.h"
#include "core/render.h"
#include "core/rng.h"
#include "core/scene_loader.h"
#include "core/sobol.h"
#include "debugtools/compare.h"
#include "reference/reference_tracer.h"
#include "tests/stat_util.h"
#include "wavefront/vector_stages.h"
#include "wavefront/wavefront_tracer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <numbers>
#include <set>
#include <string>
#include <vector>

namespace pathlab {
namespace {

using test::chi2_critical;
using test::chi2_equal;
using test::sidak;
using test::z_critical;

constexpr double kAlpha = 1e-3;  // family-wise false-alarm rate of each statistical test

// --- Sobol' points against closed forms ------------------------------------------

// The radical inverse in base 2, digit by digit.
double radical_inverse(std::uint64_t i) {
  double x = 0.0, f = 0.5;
  for (; i != 0; i >>= 1, f *= 0.5)
    if (i & 1) x += f;
  return x;
}

// Dimension 1 by its definition: the generator matrix is Pascal's triangle
// mod 2, built here by Pascal's rule (not Lucas's theorem, as sobol.h does).
double pascal_point(std::uint64_t i) {
  constexpr int n = 32;
  std::vector<std::vector<int>> c(n, std::vector<int>(n, 0));  // c[j][k] = binomial(j, k) mod 2
  for (int j = 0; j < n; ++j) {
    c[static_cast<std::size_t>(j)][0] = 1;
    for (int k = 1; k <= j; ++k)
      c[static_cast<std::size_t>(j)][static_cast<std::size_t>(k)] =
          (c[static_cast<std::size_t>(j - 1)][static_cast<std::size_t>(k - 1)] +
           (k < j ? c[static_cast<std::size_t>(j - 1)][static_cast<std::size_t>(k)] : 0)) % 2;
  }
  double x = 0.0;
  for (int k = 0; k < n; ++k) {  // output digit k + 1 = sum over index bits j of binomial(j, k) * bit j
    int digit = 0;
    for (int j = 0; j < n; ++j)
      if ((i >> j) & 1) digit ^= c[static_cast<std::size_t>(j)][static_cast<std::size_t>(k)];
    if (digit) x += std::ldexp(1.0, -(k + 1));
  }
  return x;
}

double fixed(std::uint32_t v) { return static_cast<double>(v) * 0x1p-32; }

TEST(SobolPoints, FirstTwoDimensionsMatchTheirDefinitions) {
  // The first points of dimension 1 in index order (not the Gray-code order
  // of the usual tables, 0, .5, .75, .25, .375, .875, .625, .125): the XOR of
  // direction numbers .1, .11, .101 (binary) over the index's bits.
  const double known[8] = {0.0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875};
  for (std::uint64_t i = 0; i < 8; ++i) {
    EXPECT_EQ(fixed(sobol::sample(i, 0)), radical_inverse(i)) << i;
    EXPECT_EQ(fixed(sobol::sample(i, 1)), known[i]) << i;
  }
  for (std::uint64_t i = 0; i < 4096; i += 7) {
    EXPECT_EQ(fixed(sobol::sample(i, 0)), radical_inverse(i)) << i;
    EXPECT_EQ(fixed(sobol::sample(i, 1)), pascal_point(i)) << i;
  }
  for (std::uint64_t i : {0xffffffffull, 0x12345678ull, 0x80000001ull}) {
    EXPECT_EQ(fixed(sobol::sample(i, 0)), radical_inverse(i)) << i;
    EXPECT_EQ(fixed(sobol::sample(i, 1)), pascal_point(i)) << i;
  }
}

// Whether the n = 2^m points (x[k], y[k]) put exactly one point in every
// elementary interval [a/2^i, (a+1)/2^i) x [b/2^(m-i), (b+1)/2^(m-i)),
// i = 0..m: a (0, m, 2)-net in base 2. Returns "" or what failed.
std::string net_failure(const std::vector<std::uint32_t>& x, const std::vector<std::uint32_t>& y, int m) {
  for (int i = 0; i <= m; ++i) {
    std::vector<int> count(std::size_t{1} << m, 0);
    for (std::size_t k = 0; k < x.size(); ++k) {
      const std::uint32_t a = i == 0 ? 0 : x[k] >> (32 - i), b = m - i == 0 ? 0 : y[k] >> (32 - (m - i));
      ++count[(static_cast<std::size_t>(a) << (m - i)) | b];
    }
    for (std::size_t c = 0; c < count.size(); ++c)
      if (count[c] != 1)
        return "intervals 2^-" + std::to_string(i) + " x 2^-" + std::to_string(m - i) + ": cell " +
               std::to_string(c) + " holds " + std::to_string(count[c]) + " points";
  }
  return "";
}

TEST(SobolPoints, AlignedRunsAreZeroMTwoNets) {
  for (int m = 0; m <= 10; ++m)
    for (std::uint64_t start : {std::uint64_t{0}, std::uint64_t{3} << m, std::uint64_t{0x1234} << m}) {
      std::vector<std::uint32_t> x, y, sx, sy;
      for (std::uint64_t i = start; i < start + (std::uint64_t{1} << m); ++i) {
        x.push_back(sobol::sample(i, 0));
        y.push_back(sobol::sample(i, 1));
        sx.push_back(sobol::scramble(x.back(), 0x9a3b5c7d11223344ull + static_cast<std::uint64_t>(m)));
        sy.push_back(sobol::scramble(y.back(), 0x0f1e2d3c4b5a6978ull * static_cast<std::uint64_t>(m + 1)));
      }
      EXPECT_EQ(net_failure(x, y, m), "") << "plain, m = " << m << ", start " << start;
      EXPECT_EQ(net_failure(sx, sy, m), "") << "scrambled, m = " << m << ", start " << start;
    }
}

// --- the nested scrambling -------------------------------------------------------------

TEST(SobolScramble, EachDigitDependsOnlyOnTheDigitsBeforeIt) {
  // Changing digit k (bit 31 - k) of the input leaves digits 0..k-1 of the
  // output alone, and changes digit k: a bijection of each elementary
  // interval onto one of the same length.
  std::uint64_t seed = 0x243f6a8885a308d3ull;
  for (int trial = 0; trial < 200; ++trial) {
    seed = mix64(seed + 1);
    const auto v = static_cast<std::uint32_t>(mix64(seed ^ 0x55));
    const std::uint32_t out = sobol::scramble(v, seed);
    for (int k = 0; k < 32; ++k) {
      const std::uint32_t w = sobol::scramble(v ^ (0x80000000u >> k), seed);
      const std::uint32_t above = k == 0 ? 0u : ~0u << (32 - k);
      ASSERT_EQ(out & above, w & above) << "digit " << k << " changed an earlier digit";
      ASSERT_NE(out & (0x80000000u >> k), w & (0x80000000u >> k)) << "digit " << k << " did not change itself";
    }
  }
}

TEST(SobolScramble, DecorrelatesSeeds) {
  // Point 0 (plain: 0) under 4096 seeds is uniform in 64 bins, and so is the
  // pair (point 0 under seed s, under seed s + 1).
  constexpr int n = 4096, bins = 64;
  std::vector<int> one(bins, 0), pair(bins, 0);
  for (int s = 0; s < n; ++s) {
    const std::uint32_t a = sobol::scramble(0, mix64(static_cast<std::uint64_t>(s)));
    const std::uint32_t b = sobol::scramble(0, mix64(static_cast<std::uint64_t>(s) + 1));
    ++one[a >> 26];
    ++pair[((a >> 29) << 3) | (b >> 29)];
  }
  const double crit = chi2_critical(bins - 1, sidak(kAlpha, 2));
  EXPECT_LT(chi2_equal(one, n), crit);
  EXPECT_LT(chi2_equal(pair, n), crit);
}

// --- Morton order and the digit permutation ----------------------------------------

TEST(SobolMorton, InterleavesXInEvenBitsAndYInOddBits) {
  EXPECT_EQ(sobol::morton(0, 0), 0u);
  EXPECT_EQ(sobol::morton(1, 0), 1u);
  EXPECT_EQ(sobol::morton(0, 1), 2u);
  EXPECT_EQ(sobol::morton(3, 3), 15u);
  EXPECT_EQ(sobol::morton(5, 9), 0b10010011u);  // x = 0101, y = 1001: y3 x3 y2 x2 y1 x1 y0 x0
  for (std::uint32_t x = 0; x < 64; ++x)
    for (std::uint32_t y = 0; y < 64; ++y) {
      std::uint64_t expect = 0;
      for (int b = 0; b < 6; ++b) expect |= static_cast<std::uint64_t>(((x >> b) & 1) | (((y >> b) & 1) << 1)) << (2 * b);
      ASSERT_EQ(sobol::morton(x, y), expect) << x << "," << y;
    }
  EXPECT_EQ(sobol::morton(65535, 65535), 0xffffffffull);
}

TEST(SobolPermutation, IsABijectionMappingAlignedRunsOntoAlignedRuns) {
  for (unsigned bits : {1u, 2u, 5u, 6u, 9u}) {
    const std::uint64_t n = std::uint64_t{1} << bits;
    for (std::uint64_t seed : {1ull, 0xdeadbeefull}) {
      std::set<std::uint64_t> seen;
      for (std::uint64_t i = 0; i < n; ++i) seen.insert(sobol::permute_digits(i, bits, seed));
      EXPECT_EQ(seen.size(), n) << "not a bijection, bits " << bits;
      EXPECT_EQ(*seen.rbegin(), n - 1);
      // Runs of 2^k indices sharing their bits from k up, k on a digit boundary.
      for (unsigned k = bits & 1u; k <= bits; k += 2)
        for (std::uint64_t run = 0; run < n; run += std::uint64_t{1} << k) {
          const std::uint64_t high = sobol::permute_digits(run, bits, seed) >> k;
          for (std::uint64_t i = run; i < run + (std::uint64_t{1} << k); ++i)
            ASSERT_EQ(sobol::permute_digits(i, bits, seed) >> k, high) << "bits " << bits << " k " << k << " i " << i;
        }
    }
  }
  // Bits above `bits` are kept.
  EXPECT_EQ(sobol::permute_digits(0xabc00000ull | 5u, 6, 7) >> 6, 0xabc00000ull >> 6);
}

// --- the stream ----------------------------------------------------------------

// The slot pairs and the 1D slots of a vertex, by their named dimensions.
struct Pair {
  Dim x, y;
};
constexpr Pair kPairs0[] = {{Dim::FilmX, Dim::FilmY}, {Dim::LensX, Dim::LensY}};
constexpr Pair kPairsK[] = {{Dim::LightX, Dim::LightY}, {Dim::DirectionX, Dim::DirectionY}};
constexpr Dim k1D[] = {Dim::DeltaLightChoice, Dim::LightChoice, Dim::Technique, Dim::LobeChoice, Dim::Roulette};

std::uint32_t fixed24(float u) { return static_cast<std::uint32_t>(std::ldexp(static_cast<double>(u), 24)) << 8; }

// Whether float points (as 24-bit fixed point) form a (0, m, 2)-net; m <= 24.
std::string float_net_failure(const std::vector<float>& x, const std::vector<float>& y, int m) {
  std::vector<std::uint32_t> a, b;
  for (float v : x) a.push_back(fixed24(v));
  for (float v : y) b.push_back(fixed24(v));
  return net_failure(a, b, m);
}

TEST(ZSobolStream, EachPixelsSamplesAreANetInEveryPairAndStratifiedInEveryDimension) {
  constexpr std::uint32_t w = 5, h = 3;
  for (std::uint32_t spp : {1u, 4u, 8u, 64u}) {
    const SamplerSetup s(SamplerKind::ZSobol, 42, w, h, spp);
    const int m = static_cast<int>(s.log2_spp());
    for (std::uint32_t y = 0; y < h; ++y)
      for (std::uint32_t x = 0; x < w; ++x)
        for (std::uint32_t bounce = 0; bounce < 4; ++bounce) {
          std::vector<Pair> pairs(bounce == 0 ? std::begin(kPairs0) : std::begin(kPairsK),
                                  bounce == 0 ? std::end(kPairs0) : std::end(kPairsK));
          for (const Pair& p : pairs) {
            std::vector<float> u, v;
            for (std::uint32_t j = 0; j < spp; ++j) {
              u.push_back(s.stream(x, y, j).get(bounce, p.x));
              v.push_back(s.stream(x, y, j).get(bounce, p.y));
            }
            EXPECT_EQ(float_net_failure(u, v, m), "") << "spp " << spp << " pixel " << x << "," << y << " bounce "
                                                     << bounce << " dims " << static_cast<int>(p.x);
          }
          if (bounce == 0) continue;
          for (Dim d : k1D) {  // one point in each interval [k / spp, (k + 1) / spp)
            std::vector<int> count(spp, 0);
            for (std::uint32_t j = 0; j < spp; ++j) {
              const std::uint32_t v = fixed24(s.stream(x, y, j).get(bounce, d));
              ++count[m == 0 ? 0u : v >> (32 - m)];
            }
            EXPECT_EQ(std::count(count.begin(), count.end(), 1), static_cast<long>(spp)) << "1D dim " << static_cast<int>(d);
          }
        }
  }
}

TEST(ZSobolStream, AnAlignedBlockOfPixelsIsOneNet) {
  // Morton order: the 4 pixels of an aligned 2x2 block hold an aligned run
  // of 4 * spp indices, so their film samples together are a
  // (0, log2 spp + 2, 2)-net (and a 4x4 block's, + 4): the error's blue noise.
  constexpr std::uint32_t spp = 4;
  const SamplerSetup s(SamplerKind::ZSobol, 7, 8, 8, spp);
  for (std::uint32_t side : {2u, 4u})
    for (std::uint32_t by = 0; by < 8; by += side)
      for (std::uint32_t bx = 0; bx < 8; bx += side)
        for (const Pair& p : kPairs0) {
          std::vector<float> u, v;
          for (std::uint32_t y = by; y < by + side; ++y)
            for (std::uint32_t x = bx; x < bx + side; ++x)
              for (std::uint32_t j = 0; j < spp; ++j) {
                // The point inside the pixel: the film sample's fraction.
                u.push_back(s.stream(x, y, j).get(0, p.x));
                v.push_back(s.stream(x, y, j).get(0, p.y));
              }
          const int m = std::countr_zero(spp * side * side);
          EXPECT_EQ(float_net_failure(u, v, m), "") << side << "x" << side << " block at " << bx << "," << by;
        }
}

TEST(ZSobolStream, ValuesLieInTheUnitInterval) {
  for (std::uint32_t spp : {1u, 3u, 16u, 1u << 24}) {
    const SamplerSetup s(SamplerKind::ZSobol, 0xffffffffffffffffull, 65536, 65536, spp);
    for (std::uint32_t k = 0; k < 2000; ++k) {
      const auto x = static_cast<std::uint32_t>(mix64(k) % 65536), y = static_cast<std::uint32_t>(mix64(k + 9) % 65536);
      const std::uint32_t sample = k < 10 ? 0xffffffffu - k : static_cast<std::uint32_t>(mix64(k + 3));
      const SampleStream st = s.stream(x, y, sample);
      for (std::uint32_t d = 0; d < static_cast<std::uint32_t>(Dim::Count); ++d) {
        const float u = st.get(k % 1001, static_cast<Dim>(d));
        ASSERT_TRUE(u >= 0.0f && u < 1.0f) << u;
      }
    }
  }
}

TEST(ZSobolStream, IsAPureFunctionAndIndependentIsUnchanged) {
  const SamplerSetup z(SamplerKind::ZSobol, 99, 40, 30, 16), ind(SamplerKind::Independent, 99, 40, 30, 16);
  // Drawn in two different orders, the same numbers.
  std::vector<float> forward, backward;
  for (std::uint32_t i = 0; i < 1200; ++i)
    forward.push_back(sample_u(z, i % 40, i / 40, i % 37, i % 5, static_cast<Dim>(i % 13)));
  for (std::uint32_t i = 1200; i-- > 0;)
    backward.push_back(z.stream(i % 40, i / 40, i % 37).get(i % 5, static_cast<Dim>(i % 13)));
  for (std::uint32_t i = 0; i < 1200; ++i) EXPECT_EQ(forward[i], backward[1199 - i]);
  // independent: the documented hash chain, bit for bit, whatever spp and
  // resolution; zsobol keeps it for bits() and Alpha.
  for (std::uint32_t i = 0; i < 1000; ++i) {
    const std::uint32_t x = i % 40, y = i / 40 % 30, sample = i * 7, bounce = i % 6;
    const Dim d = static_cast<Dim>(i % static_cast<std::uint32_t>(Dim::Count));
    const std::uint64_t h1 = mix64(mix64(99 + 0x9e3779b97f4a7c15ull) ^ ((std::uint64_t{y * 40 + x} << 32) | sample));
    const std::uint64_t h = mix64(h1 ^ ((std::uint64_t{bounce} << 32) | static_cast<std::uint32_t>(d)));
    EXPECT_EQ(ind.stream(x, y, sample).get(bounce, d), to_unit_float(h));
    EXPECT_EQ(ind.stream(x, y, sample).get(bounce, d), sample_u(99, y * 40 + x, sample, bounce, d));
    EXPECT_EQ(z.stream(x, y, sample).bits(bounce, d), h);
    EXPECT_EQ(z.stream(x, y, sample).get(bounce, Dim::Alpha), to_unit_float(z.stream(x, y, sample).bits(bounce, Dim::Alpha)));
  }
  EXPECT_TRUE(ind.stream(1, 2, 3).independent());
  EXPECT_FALSE(z.stream(1, 2, 3).independent());
}

// get2(bounce, x) is {get(bounce, x), get(bounce, x + 1)} bit for bit under
// both samplers: for the four pairs (one permutation for both axes under
// zsobol) and for any other dimension (two plain draws).
TEST(ZSobolStream, PairsAreTheTwoSingleDrawsBitForBit) {
  for (const SamplerKind kind : {SamplerKind::ZSobol, SamplerKind::Independent})
    for (std::uint32_t spp : {1u, 5u, 64u}) {
      const SamplerSetup setup(kind, 7, 33, 17, spp);
      for (std::uint32_t i = 0; i < 3000; ++i) {
        const SampleStream st = setup.stream(i % 33, i / 33 % 17, i % 97);
        const std::uint32_t bounce = i % 7;
        for (std::uint32_t d = 0; d + 1 < static_cast<std::uint32_t>(Dim::Count); ++d) {
          const auto x = static_cast<Dim>(d), y = static_cast<Dim>(d + 1);
          const SampleStream::Pair p = st.get2(bounce, x);
          ASSERT_EQ(std::bit_cast<std::uint32_t>(p.x), std::bit_cast<std::uint32_t>(st.get(bounce, x)))
              << sampler_name(kind) << " dim " << d;
          ASSERT_EQ(std::bit_cast<std::uint32_t>(p.y), std::bit_cast<std::uint32_t>(st.get(bounce, y)))
              << sampler_name(kind) << " dim " << d;
        }
      }
    }
}

TEST(ZSobolStream, SeedsRandomiseEveryPoint) {
  // One pixel at 1 spp: the whole sequence is point 0 (plain: 0), so the
  // numbers over 4096 seeds are uniform only through the scrambling: a
  // 64-bin chi-square for each dimension at vertices 0 and 1.
  constexpr int n = 4096, bins = 64;
  constexpr auto kDims = static_cast<std::uint32_t>(Dim::Alpha);
  std::vector<std::pair<std::string, double>> stats;
  for (std::uint32_t bounce : {0u, 1u})
    for (std::uint32_t d = 0; d < kDims; ++d) {
      if ((bounce == 0) != (d < static_cast<std::uint32_t>(Dim::DeltaLightChoice))) continue;
      std::vector<int> count(bins, 0);
      for (int s = 0; s < n; ++s) {
        const SamplerSetup z(SamplerKind::ZSobol, static_cast<std::uint64_t>(s), 1, 1, 1);
        ++count[static_cast<std::size_t>(z.stream(0, 0, 0).get(bounce, static_cast<Dim>(d)) * bins)];
      }
      stats.emplace_back("bounce " + std::to_string(bounce) + " dim " + std::to_string(d), chi2_equal(count, n));
    }
  const double crit = chi2_critical(bins - 1, sidak(kAlpha, static_cast<double>(stats.size())));
  for (const auto& [what, chi2] : stats) EXPECT_LT(chi2, crit) << what;
}

// Chi-square of the pair (a, b) in 8 x 8 bins over many pixels, samples and
// seeds: the slots of a vertex, and the vertices, are independent.
double pair_chi2(const std::function<std::pair<float, float>(std::uint32_t k)>& draw, std::uint32_t n) {
  std::vector<int> count(64, 0);
  for (std::uint32_t k = 0; k < n; ++k) {
    const auto [a, b] = draw(k);
    ++count[static_cast<std::size_t>(static_cast<int>(a * 8.0f) * 8 + static_cast<int>(b * 8.0f))];
  }
  return chi2_equal(count, n);
}

TEST(ZSobolStream, DimensionsVerticesAndSeedsAreDecorrelated) {
  constexpr std::uint32_t w = 32, h = 32, spp = 8, n = w * h * spp;
  constexpr auto kDims = static_cast<std::uint32_t>(Dim::Alpha);  // the sampler's dimensions
  const SamplerSetup s(SamplerKind::ZSobol, 5, w, h, spp), s2(SamplerKind::ZSobol, 6, w, h, spp);
  auto key = [](std::uint32_t k) { return std::array<std::uint32_t, 3>{k / spp % w, k / spp / w, k % spp}; };
  std::vector<std::pair<std::string, double>> stats;
  // Every pair of dimensions at vertex 2 and at vertex 0 vs 1 (camera vs first vertex).
  for (std::uint32_t a = 0; a < kDims; ++a)
    for (std::uint32_t b = a + 1; b < kDims; ++b)
      for (std::uint32_t ba : {2u, 0u}) {
        const std::uint32_t bb = ba == 2 ? 2 : 1;
        stats.emplace_back("dims " + std::to_string(a) + "," + std::to_string(b) + " bounces " + std::to_string(ba) + "," +
                               std::to_string(bb),
                           pair_chi2(
                               [&](std::uint32_t k) {
                                 const auto [x, y, j] = key(k);
                                 const SampleStream st = s.stream(x, y, j);
                                 return std::pair{st.get(ba, static_cast<Dim>(a)), st.get(bb, static_cast<Dim>(b))};
                               },
                               n));
      }
  // The same dimension at vertices 1 and 2, and under seeds 5 and 6.
  for (std::uint32_t a = 0; a < kDims; ++a) {
    stats.emplace_back("dim " + std::to_string(a) + " bounces 1,2", pair_chi2(
                                                                     [&](std::uint32_t k) {
                                                                       const auto [x, y, j] = key(k);
                                                                       const SampleStream st = s.stream(x, y, j);
                                                                       return std::pair{st.get(1, static_cast<Dim>(a)),
                                                                                        st.get(2, static_cast<Dim>(a))};
                                                                     },
                                                                     n));
    stats.emplace_back("dim " + std::to_string(a) + " seeds 5,6", pair_chi2(
                                                                   [&](std::uint32_t k) {
                                                                     const auto [x, y, j] = key(k);
                                                                     return std::pair{
                                                                         s.stream(x, y, j).get(1, static_cast<Dim>(a)),
                                                                         s2.stream(x, y, j).get(1, static_cast<Dim>(a))};
                                                                   },
                                                                   n));
  }
  const double crit = chi2_critical(63, sidak(kAlpha, static_cast<double>(stats.size())));
  for (const auto& [what, chi2] : stats) EXPECT_LT(chi2, crit) << what;
}

// --- convergence on a smooth integrand --------------------------------------------------

// f(u, v) = u v + sin(pi u) e^v over the unit square: integral 1/4 + (2/pi)(e - 1).
double smooth_f(double u, double v) { return u * v + std::sin(std::numbers::pi * u) * std::exp(v); }
const double kSmoothIntegral = 0.25 + 2.0 / std::numbers::pi * (std::numbers::e - 1.0);

struct SlopeFit {
  double slope, se;
  double worst_mean_z = 0.0;  // the largest |mean error| / its standard error over the counts
};

// The slope of log RMSE against log n, by weighted least squares over the
// sample counts, RMSE from R seeds. Its standard error: the delta method
// gives Var(log RMSE) = Var(e^2) / (4 R MSE^2), estimated from the same
// squared errors.
SlopeFit fit_rmse_slope(SamplerKind kind, const std::vector<std::uint32_t>& counts, int seeds, Dim dx, Dim dy,
                        std::uint32_t bounce) {
  std::vector<double> lx, ly, wt;
  double worst_z = 0.0;
  for (std::uint32_t n : counts) {
    double sum2 = 0.0, sum4 = 0.0, sum1 = 0.0;
    for (int r = 0; r < seeds; ++r) {
      const SamplerSetup sr(kind, 1000 + static_cast<std::uint64_t>(r), 1, 1, n);
      double acc = 0.0;
      for (std::uint32_t j = 0; j < n; ++j) {
        const SampleStream st = sr.stream(0, 0, j);
        acc += smooth_f(st.get(bounce, dx), st.get(bounce, dy));
      }
      sum1 += acc / n - kSmoothIntegral;
      const double e2 = std::pow(acc / n - kSmoothIntegral, 2);
      sum2 += e2;
      sum4 += e2 * e2;
    }
    const double mse = sum2 / seeds, var_e2 = sum4 / seeds - mse * mse;
    const double var_log_rmse = var_e2 / (4.0 * seeds * mse * mse);
    // Unbiased: the mean error over the seeds against its standard error.
    const double mean_e = sum1 / seeds, se_mean = std::sqrt((mse - mean_e * mean_e) / (seeds - 1));
    worst_z = std::max(worst_z, se_mean > 0.0 ? std::abs(mean_e) / se_mean : (mean_e == 0.0 ? 0.0 : 1e300));
    lx.push_back(std::log(static_cast<double>(n)));
    ly.push_back(0.5 * std::log(mse));
    wt.push_back(1.0 / var_log_rmse);
  }
  double sw = 0, sx = 0, sy = 0;
  for (std::size_t i = 0; i < lx.size(); ++i) sw += wt[i], sx += wt[i] * lx[i], sy += wt[i] * ly[i];
  const double mx = sx / sw, my = sy / sw;
  double sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < lx.size(); ++i) sxx += wt[i] * (lx[i] - mx) * (lx[i] - mx), sxy += wt[i] * (lx[i] - mx) * (ly[i] - my);
  return {sxy / sxx, std::sqrt(1.0 / sxx), worst_z};
}

// Owen-scrambled (0, 2)-sequences integrate a smooth 2D function with RMSE
// O(n^-3/2) (Owen 1997); independent samples with O(n^-1/2). At
// n = 4, 16, 64, 256, 1024 over 200 seeds: zsobol's slope lies below -1/2
// by more than its z-bound, independent's within its z-bound of -1/2 (3
// tests, Šidák at kAlpha).
TEST(ZSobolConvergence, SmoothIntegrandErrorFallsFasterThanMonteCarlo) {
  const std::vector<std::uint32_t> counts{4, 16, 64, 256, 1024};
  const double z = z_critical(sidak(kAlpha, 3)), z_mean = z_critical(sidak(kAlpha, 3 * counts.size()));
  const SlopeFit film = fit_rmse_slope(SamplerKind::ZSobol, counts, 200, Dim::FilmX, Dim::FilmY, 0);
  const SlopeFit dir = fit_rmse_slope(SamplerKind::ZSobol, counts, 200, Dim::DirectionX, Dim::DirectionY, 3);
  const SlopeFit ind = fit_rmse_slope(SamplerKind::Independent, counts, 200, Dim::DirectionX, Dim::DirectionY, 3);
  EXPECT_LT(film.slope + z * film.se, -0.5) << "zsobol film pair: slope " << film.slope << " +- " << film.se;
  EXPECT_LT(dir.slope + z * dir.se, -0.5) << "zsobol direction pair: slope " << dir.slope << " +- " << dir.se;
  EXPECT_LT(std::abs(ind.slope + 0.5), z * ind.se) << "independent: slope " << ind.slope << " +- " << ind.se;
  // And every estimate is unbiased (the scrambling randomises it).
  EXPECT_LT(film.worst_mean_z, z_mean) << "zsobol film pair biased";
  EXPECT_LT(dir.worst_mean_z, z_mean) << "zsobol direction pair biased";
  EXPECT_LT(ind.worst_mean_z, z_mean) << "independent biased";
  std::cout << "slopes: zsobol film " << film.slope << " +- " << film.se << ", direction " << dir.slope << " +- "
            << dir.se << "; independent " << ind.slope << " +- " << ind.se << "\n";
}

// --- the setting ---------------------------------------------------------------------------

TEST(ZSobolSetting, SceneKeyAndRecordedSettings) {
  const char* text = R"({"pathlab_scene": 1, "camera": {"position": [0, 0, 4], "look_at": [0, 0, 0]},
    "materials": {"white": {"type": "diffuse", "albedo": 0.5}},
    "shapes": [{"type": "sphere", "material": "white"}], "render": {"sampler": "zsobol", "spp": 10}})";
  const Scene s = parse_scene(text, "zsobol.json");
  EXPECT_EQ(s.render.sampler, SamplerKind::ZSobol);
  EXPECT_EQ(RenderSettings{}.sampler, SamplerKind::Independent);
  bool sampler = false, block = false;
  for (const auto& [key, value] : sample_settings(s.render)) {
    if (key == "sampler") sampler = value == "zsobol";
    if (key == "zsobol_spp") block = value == "16";  // 10 rounded up
  }
  EXPECT_TRUE(sampler && block);
  for (const auto& [key, value] : sample_settings(RenderSettings{})) {
    if (key == "sampler") {
      EXPECT_EQ(value, "independent");
    }
    EXPECT_NE(key, "zsobol_spp");
  }
}

// --- the tracers under zsobol ------------------------------------------------------------

Scene small_scene(const std::string& file, int spp) {
  Scene s = file.empty() ? builtin_cornell_box()
                         : load_scene(std::filesystem::path(PATHLAB_SOURCE_DIR) / "analytic-scenes" / file);
  s.film.width = 24;
  s.film.height = 18;
  s.render.spp = spp;
  s.render.sampler = SamplerKind::ZSobol;
  return s;
}

TEST(ZSobolTracers, BothTracersFollowTheSamePaths) {
  for (const std::string file : {"", "penumbra-box.json"}) {
    Scene scene = small_scene(file, 4);
    const RenderSettings settings = scene.render;
    const CompiledScene compiled(std::move(scene));
    const ReferenceTracer reference(compiled, settings);
    // Both stage implementations: the vectorised ones draw zsobol's points in their lanes.
    for (const WavefrontStages stages : {WavefrontStages::Auto, WavefrontStages::Scalar}) {
      const WavefrontTracer wavefront(compiled, settings, 97, {}, stages);
      EXPECT_EQ(wavefront.vectorised(), stages == WavefrontStages::Auto && vector_stages::cpu_supported())
          << wavefront.scalar_reason();
      const SampleComparison r = compare_tracers(reference, wavefront, 4);
      EXPECT_TRUE(r.agree()) << file << ": " << r.differing() << " of " << r.samples << " samples differ";
      EXPECT_GE(static_cast<double>(r.equal), 0.999 * static_cast<double>(r.samples)) << file;
    }
  }
}

TEST(ZSobolTracers, ImagesAreTheSameBitsForAnyThreadCountAndWaveSize) {
  Scene scene = small_scene("", 8);
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  auto image = [&](const Tracer& t, int threads) {
    const ThreadLimit limit(threads);
    Film film(compiled.scene().film.width, compiled.scene().film.height, compiled.scene().film.filter);
    render(t, film);
    return film.image().pixels;
  };
  const ReferenceTracer reference(compiled, settings);
  const WavefrontTracer w97(compiled, settings, 97), w1000(compiled, settings, 1000);
  const auto r1 = image(reference, 1);
  EXPECT_EQ(r1, image(reference, 2));
  const auto w1 = image(w97, 1);
  EXPECT_EQ(w1, image(w97, 2));
  EXPECT_EQ(w1, image(w1000, 2));
  // trace-pixel's replay: one sample alone is the sample of the render.
  std::vector<FilmSample> batch(static_cast<std::size_t>(24 * 18) * 8);
  reference.render_batch(0, 8, batch);
  for (std::uint32_t j = 0; j < 8; ++j) {
    const FilmSample one = reference.trace_sample(5, 7, j, nullptr);
    EXPECT_EQ(one.L, batch[(7 * 24 + 5) * 8 + j].L) << j;
    EXPECT_EQ(one.film, batch[(7 * 24 + 5) * 8 + j].film) << j;
  }
}

// What the tracers draw, against the nets, not against each other: each
// pixel's film samples of an 8-spp render (the FilmX/FilmY pair, drawn by
// get2 in the reference and the scalar stages, by the lanes' u2 in the
// vectorised ones: one text, core/simd/stream-generic.h) are a
// (0, 3, 2)-net, their fractions in the pixel as fixed point. A bug in the
// shared text reaches every tracer alike, where BothTracersFollowTheSamePaths
// and VectorStages cannot see it.
TEST(ZSobolTracers, EachPixelsFilmSamplesAreANetInEveryTracer) {
  constexpr std::uint32_t spp = 8;
  Scene scene = small_scene("", static_cast<int>(spp));
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  const std::uint32_t w = static_cast<std::uint32_t>(compiled.scene().film.width);
  const std::uint32_t h = static_cast<std::uint32_t>(compiled.scene().film.height);
  const ReferenceTracer reference(compiled, settings);
  const WavefrontTracer lanes(compiled, settings, 97, {}, WavefrontStages::Auto);
  const WavefrontTracer scalar(compiled, settings, 97, {}, WavefrontStages::Scalar);
  for (const Tracer* t : {static_cast<const Tracer*>(&reference), static_cast<const Tracer*>(&lanes),
                          static_cast<const Tracer*>(&scalar)}) {
    std::vector<FilmSample> batch(static_cast<std::size_t>(w) * h * spp);
    t->render_batch(0, spp, batch);
    int failures = 0;
    for (std::uint32_t p = 0; p < w * h; ++p) {
      std::vector<float> u, v;
      for (std::uint32_t j = 0; j < spp; ++j) {
        const vec2 film = batch[p * spp + j].film;  // (x, y) + the pair: its fraction exact to 2^-19 here
        u.push_back(film.x - static_cast<float>(p % w));
        v.push_back(film.y - static_cast<float>(p / w));
      }
      const std::string failure = float_net_failure(u, v, 3);
      if (!failure.empty() && failures++ < 3)
        ADD_FAILURE() << t->name() << (t == &scalar ? " (scalar stages)" : "") << ", pixel " << p % w << ","
                      << p / w << ": " << failure;
    }
    EXPECT_EQ(failures, 0) << t->name() << (t == &scalar ? " (scalar stages)" : "") << ": of " << w * h << " pixels";
  }
}

}  // namespace
}  // namespace pathlab
