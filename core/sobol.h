// The parts of the zsobol sampler (core/rng.h), each a pure function: the
// first two dimensions of Sobol's sequence, a nested (Owen-type) scrambling
// of a 32-bit fixed-point value, the Morton index of a pixel and a nested
// random permutation of an index's base-4 digits. The design is that of
// pbrt-v4's ZSobolSampler (Ahmed & Wonka 2020, "Screen-space blue-noise
// diffusion of Monte Carlo sampling error via hierarchical ordering of
// pixels"); docs/scene-format.md (Samplers) says how pathlab uses it.
//
// Fixed point: a value v in [0, 2^32) stands for v / 2^32; bit 31 is the
// first binary digit after the point.
#pragma once

#include "core/simd/lane1.h"

#include <hwy/base.h>  // HWY_INLINE, for core/simd/sobol-generic.h

#include <array>
#include <cstdint>

namespace pathlab::sobol {

// The constants of the zsobol sampler's hashes, named once for the scalar
// code here and in core/rng.h and for its lanes (core/simd/sobol-inl.h,
// core/simd/lanes-inl.h), which must compute the same bits.
inline constexpr std::uint64_t kMixMul0 = 0xbf58476d1ce4e5b9ull;  // splitmix64's finaliser
inline constexpr std::uint64_t kMixMul1 = 0x94d049bb133111ebull;
inline constexpr std::uint64_t kDigitStep = 0x9e3779b97f4a7c15ull;  // permute_digits: per digit place
inline constexpr std::uint64_t kLoneBitSalt = 0x3c6ef372fe94f82bull;  // permute_digits: the lone lowest bit
inline constexpr std::uint64_t kScrambleSalt = 0xa0761d6478bd642full;  // scramble: the second pair of keys
inline constexpr std::uint32_t kScrambleEven0 = 0x6b43a9b6u;  // scramble: the xor-multiplies (even)
inline constexpr std::uint32_t kScrambleEven1 = 0x9e3779b8u;
inline constexpr std::uint64_t kSlotStep = 0xd1b54a32d192ed03ull;  // SampleStream: a slot's point hash

// Point `index` of Sobol's sequence in dimension 0 or 1, unscrambled, from
// its generator matrix (column j the image of index bit j; index bits from 32
// on only reach digits past the 32nd, which a 32-bit value drops).
// Dimension 0 is the identity (van der Corput: index bit j becomes digit
// j + 1 after the point). Dimension 1 is Pascal's matrix mod 2 (Sobol's
// direction numbers for the primitive polynomial x + 1): digit i + 1 of
// column j is binomial(j, i) mod 2, 1 exactly when the bits of i are a
// subset of the bits of j (Lucas). So digit i + 1 of the point is the parity
// of the index's set bits j that contain i, a sum over supersets which five
// butterflies compute for every i at once (f[i] ^= f[i + 2^b] where bit b of
// i is clear), before the reversal into digit order. The body is
// core/simd/sobol-generic.h's sobol_sample, which the lanes run too;
// tests/test_sobol.cpp checks it against the binomials.
// Butterfly b (shift 2^b) updates the positions i whose bit b is clear.
inline constexpr std::array<std::uint32_t, 5> kSupersetMasks = {0x55555555u, 0x33333333u, 0x0f0f0f0fu, 0x00ff00ffu,
                                                                0x0000ffffu};
constexpr std::uint32_t sample(std::uint64_t index, int dim);

// A nested scrambling of v seeded by `seed`: digit k of the result is digit
// k of v flipped or not by a function of `seed` and v's digits before k, so
// it maps each elementary interval [a / 2^k, (a + 1) / 2^k) onto one of the
// same length (a bijection on each), as Owen's scrambling does, and keeps
// every (t, m, s)-net a net. It works on the reversed value, where digit k
// is bit k - 1 and "before" means "less significant": adding a constant,
// multiplying by an odd one and v ^= v * even each make bit i depend only on
// bits <= i, and each is a bijection (Laine & Karras 2011 describe the idea;
// this is a chain of our own: two rounds of add, odd multiply, xor-multiply,
// with four 32-bit keys drawn from the seed). The first add's key is
// independent of the rest, so each value is scrambled to a uniform one.
constexpr std::uint32_t scramble(std::uint32_t v, std::uint64_t seed);

// x in the even bits, y in the odd bits: pixels close on the screen get
// close indices, and each aligned 2^k x 2^k block of pixels is an aligned
// run of 4^k indices.
constexpr std::uint64_t morton(std::uint32_t x, std::uint32_t y) {
  auto spread = [](std::uint64_t v) {
    v &= 0xffffffffu;
    v = (v | (v << 16)) & 0x0000ffff0000ffffull;
    v = (v | (v << 8)) & 0x00ff00ff00ff00ffull;
    v = (v | (v << 4)) & 0x0f0f0f0f0f0f0f0full;
    v = (v | (v << 2)) & 0x3333333333333333ull;
    v = (v | (v << 1)) & 0x5555555555555555ull;
    return v;
  };
  return spread(x) | (spread(y) << 1);
}

// The 24 permutations of {0, 1, 2, 3}, each packed as four 2-bit images
// (the image of d in bits 2d, 2d + 1), in lexicographic order.
inline constexpr std::array<std::uint8_t, 24> kPermutations4 = [] {
  std::array<std::uint8_t, 24> out{};
  int n = 0;
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b)
      for (int c = 0; c < 4; ++c)
        for (int d = 0; d < 4; ++d)
          if (a != b && a != c && a != d && b != c && b != d && c != d)
            out[static_cast<std::size_t>(n++)] = static_cast<std::uint8_t>(a | (b << 2) | (c << 4) | (d << 6));
  return out;
}();

// A nested random permutation of the `bits` low bits of `index` (bits above
// them are kept): from the top, each base-4 digit goes through one of the 24
// permutations, chosen by a hash of `seed`, the digit's place and the
// original digits above it. With `bits` odd the lowest digit is a single bit,
// flipped or not by such a hash. An aligned run of indices (the 2^k indices
// that share all bits from k up, k even, or k odd when `bits` is odd) maps
// onto an aligned run of the same length, so the points of a run of a
// (0, 2)-sequence stay a (0, k, 2)-net.
constexpr std::uint64_t permute_digits(std::uint64_t index, unsigned bits, std::uint64_t seed);

// kPermutations4 packed eight to a 64-bit word (entry i in byte i % 8 of
// word i / 8), as the lanes' permute_digits reads it (permutation_image,
// core/simd/lanes-inl.h).
inline constexpr std::array<std::uint64_t, 3> kPermutations4Packed = [] {
  std::array<std::uint64_t, 3> out{};
  for (std::size_t i = 0; i < 24; ++i) out[i / 8] |= std::uint64_t{kPermutations4[i]} << (8 * (i % 8));
  return out;
}();

}  // namespace pathlab::sobol

namespace pathlab::lane1 {
// core/simd/lanes-inl.h's permutation_image at width 1: the image of
// `digit` under permutation (h >> 32) % 24 of the four, by indexing the
// table (the lanes read it packed, by selects; the same entry).
constexpr U64 permutation_image(One<std::uint64_t>, U64 h, U64 digit) {
  return {(std::uint64_t{sobol::kPermutations4[(h.raw >> 32) % 24]} >> (2 * digit.raw)) & 3u};
}
}  // namespace pathlab::lane1

namespace pathlab::sobol {

// The bodies, written once for every width (core/simd/sobol-generic.h),
// here over lane1's one plain uint64; the wavefront's lanes compile the
// same text over Highway's vectors (core/simd/sobol-inl.h).
namespace width1 {
#include "core/simd/sobol-generic.h"
}  // namespace width1

namespace detail {
inline constexpr lane1::One<std::uint64_t> kLane{};
constexpr lane1::U64 lane(std::uint64_t v) { return {v}; }
}  // namespace detail

// splitmix64's finaliser (core/rng.h's mix64 is this one).
constexpr std::uint64_t mix(std::uint64_t z) { return width1::mix64(detail::kLane, detail::lane(z)).raw; }

constexpr std::uint32_t sample(std::uint64_t index, int dim) {
  return static_cast<std::uint32_t>(width1::sobol_sample(detail::kLane, detail::lane(index), dim).raw);
}

constexpr std::uint32_t scramble(std::uint32_t v, std::uint64_t seed) {
  return static_cast<std::uint32_t>(width1::scramble(detail::kLane, detail::lane(v), detail::lane(seed)).raw);
}

constexpr std::uint64_t permute_digits(std::uint64_t index, unsigned bits, std::uint64_t seed) {
  return width1::permute_digits(detail::kLane, detail::lane(index), bits, detail::lane(seed)).raw;
}

// The top 24 bits of point `slot` of a zsobol stream (index, key, bits: its
// SamplerSetup::zsobol_index, zsobol_key, zsobol_bits) in Sobol' dimension
// `axis`, scrambled; with `second` not null, dimension 1's too (one permuted
// index for the pair). SampleStream::get draws it, the lanes the same.
constexpr std::uint32_t zsobol_top24(std::uint64_t index, std::uint64_t key, unsigned bits, std::uint32_t slot,
                                     int axis, std::uint32_t* second) {
  lane1::U64 other{};
  const lane1::U64 top = width1::zsobol_top24(detail::kLane, detail::lane(index), detail::lane(key), bits,
                                              detail::lane(slot), axis, second ? &other : nullptr);
  if (second) *second = static_cast<std::uint32_t>(other.raw);
  return static_cast<std::uint32_t>(top.raw);
}
// A 32-bit fixed-point value's top 24 bits (zsobol_top24's) as a float in
// [0, 1); to_unit_float (core/rng.h) takes the hash's top 24 bits through it.
constexpr float top24_to_float(std::uint32_t top) { return static_cast<float>(top) * 0x1p-24f; }

}  // namespace pathlab::sobol
