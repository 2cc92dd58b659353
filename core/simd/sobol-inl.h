// The zsobol sampler's numbers (core/rng.h, core/sobol.h) over Highway's
// 64-bit lanes, for the wavefront's vectorised stages: one stream per lane,
// each lane the bits SampleStream::get() computes (integer arithmetic
// throughout, so exactness is by construction; VectorStages.* checks it).
// Each function names the scalar one it computes.
//
// Highway's "-inl.h" convention: no include guard but the toggle below.
#if defined(PATHLAB_CORE_SIMD_SOBOL_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef PATHLAB_CORE_SIMD_SOBOL_INL_H_
#undef PATHLAB_CORE_SIMD_SOBOL_INL_H_
#else
#define PATHLAB_CORE_SIMD_SOBOL_INL_H_
#endif

#include <hwy/highway.h>

#include "core/simd/lanes-inl.h"
#include "core/sobol.h"

#include <array>
#include <cstdint>

HWY_BEFORE_NAMESPACE();
namespace pathlab::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// sobol::kPermutations4 packed eight to a 64-bit word (entry i in byte
// i % 8 of word i / 8): a lane finds its entry by two selects and a shift,
// where a gather from the table cost its latency once per digit (40 % of
// the zsobol draws' time in perf on AMD family 26 model 2).
inline constexpr std::array<std::uint64_t, 3> kPermutations4Packed = [] {
  std::array<std::uint64_t, 3> out{};
  for (std::size_t i = 0; i < 24; ++i) out[i / 8] |= std::uint64_t{sobol::kPermutations4[i]} << (8 * (i % 8));
  return out;
}();

// sobol::permute_digits: from the top, each base-4 digit of the `bits` low
// bits of index through one of 24 permutations chosen by a hash of seed, the
// digit's place and the digits above it; with `bits` odd the lowest bit
// flipped or not by such a hash. `bits` is the same for every lane (the
// render's), so the loop is the scalar one.
template <class D64, class V64 = hn::Vec<D64>>
HWY_INLINE V64 permute_digits(D64 d64, V64 index, unsigned bits, V64 seed) {
  const unsigned lone = bits & 1u;
  V64 out = hn::And(index, hn::Set(d64, ~((bits >= 64 ? 0ull : (1ull << bits)) - 1ull)));
  for (unsigned p = bits - 2; p + 2 > lone && p < 64; p -= 2) {  // digit in bits [p, p + 1]
    const V64 higher = hn::ShiftRightSame(index, static_cast<int>(p + 2));
    const V64 digit = hn::And(hn::ShiftRightSame(index, static_cast<int>(p)), hn::Set(d64, 3));
    const V64 h = mix64(d64, hn::Xor(seed + hn::Set(d64, (static_cast<std::uint64_t>(p) + 1) * sobol::kDigitStep),
                                     higher));
    // (h >> 32) % 24, exactly: for x < 2^32, x / 24 = (x * 0xaaaaaaab) >> 36
    // (a 32 x 32 -> 64-bit product), and q * 24 < 2^32.
    const V64 x = hn::ShiftRight<32>(h);
    const V64 q = hn::ShiftRight<36>(mul_wide32(d64, x, hn::Set(d64, 0xaaaaaaabull)));
    const V64 which = x - mul_wide32(d64, q, hn::Set(d64, 24));
    // Entry `which` of the packed table, then the digit's image in it.
    const V64 word = hn::IfThenElse(which < hn::Set(d64, 8), hn::Set(d64, kPermutations4Packed[0]),
                                    hn::IfThenElse(which < hn::Set(d64, 16), hn::Set(d64, kPermutations4Packed[1]),
                                                   hn::Set(d64, kPermutations4Packed[2])));
    const V64 shift = hn::ShiftLeft<3>(hn::And(which, hn::Set(d64, 7))) + hn::ShiftLeft<1>(digit);
    out = hn::Or(out, hn::ShiftLeftSame(hn::And(word >> shift, hn::Set(d64, 3)), static_cast<int>(p)));
    if (p < 2) break;
  }
  if (lone) {
    const V64 h = mix64(d64, hn::Xor(hn::Xor(seed, hn::Set(d64, sobol::kLoneBitSalt)), hn::ShiftRight<1>(index)));
    out = hn::Or(out, hn::And(hn::Xor(index, hn::ShiftRight<63>(h)), hn::Set(d64, 1)));
  }
  return out;
}

// sobol::reverse_bits of the low 32 bits of each lane (the high 32 are 0).
template <class D64, class V64 = hn::Vec<D64>>
HWY_INLINE V64 reverse_bits32(D64 d64, V64 v) {
  auto swap = [d64](V64 x, int shift, std::uint64_t mask) {
    const V64 m = hn::Set(d64, mask);
    return hn::Or(hn::And(hn::ShiftRightSame(x, shift), m), hn::ShiftLeftSame(hn::And(x, m), shift));
  };
  v = swap(v, 1, 0x55555555u);
  v = swap(v, 2, 0x33333333u);
  v = swap(v, 4, 0x0f0f0f0fu);
  v = swap(v, 8, 0x00ff00ffu);
  return hn::And(hn::Or(hn::ShiftRight<16>(v), hn::ShiftLeft<16>(v)), hn::Set(d64, 0xffffffffu));
}

// The low 32 bits of a * b (each below 2^32), as a 32-bit multiply gives.
template <class D64, class V64 = hn::Vec<D64>>
HWY_INLINE V64 mul32(D64 d64, V64 a, V64 b) {
  return hn::And(mul_wide32(d64, a, b), hn::Set(d64, 0xffffffffu));
}

// sobol::sample: point `index` (its low 32 bits) of Sobol's sequence in
// dimension `axis`, unscrambled, as a 32-bit fixed-point value (dimension 1
// by the five butterflies over supersets that sobol::sample explains).
template <class D64, class V64 = hn::Vec<D64>>
HWY_INLINE V64 sobol_sample(D64 d64, V64 index, int axis) {
  V64 f = hn::And(index, hn::Set(d64, 0xffffffffu));
  if (axis == 0) return reverse_bits32(d64, f);
  for (unsigned b = 0; b < 5; ++b)
    f = hn::Xor(f, hn::And(hn::ShiftRightSame(f, 1 << b), hn::Set(d64, sobol::kSupersetMasks[b])));
  return reverse_bits32(d64, f);
}

// sobol::scramble: the nested scrambling of the 32-bit value v by `seed`.
template <class D64, class V64 = hn::Vec<D64>>
HWY_INLINE V64 scramble(D64 d64, V64 v, V64 seed) {
  const V64 mask = hn::Set(d64, 0xffffffffu), odd = hn::Set(d64, 1);
  const V64 more = mix64(d64, hn::Xor(seed, hn::Set(d64, sobol::kScrambleSalt)));
  const V64 k0 = hn::And(seed, mask), k1 = hn::ShiftRight<32>(seed);
  const V64 k2 = hn::And(more, mask), k3 = hn::ShiftRight<32>(more);
  v = reverse_bits32(d64, v);
  v = hn::And(v + k0, mask);
  v = mul32(d64, v, hn::Or(k1, odd));
  v = hn::Xor(v, mul32(d64, v, hn::Set(d64, sobol::kScrambleEven0)));
  v = hn::And(v + k2, mask);
  v = mul32(d64, v, hn::Or(k3, odd));
  v = hn::Xor(v, mul32(d64, v, hn::Set(d64, sobol::kScrambleEven1)));
  return reverse_bits32(d64, v);
}

// SampleStream::zsobol_point and Point::value: the top 24 bits of the
// scrambled point of `slot` (per lane) in Sobol' dimension axis0 and, when
// `second` is not null, axis 1 too (a 2D pair shares its point). `key` is
// SamplerSetup::zsobol_key, `index` zsobol_index, `bits` zsobol_bits.
template <class D64, class V64 = hn::Vec<D64>>
HWY_INLINE V64 zsobol_top24(D64 d64, V64 index, V64 key, unsigned bits, V64 slot, int axis0, V64* second) {
  const V64 h = mix64(d64, hn::Xor(key, mul64(d64, slot, sobol::kSlotStep)));
  const V64 permuted = permute_digits(d64, index, bits, h);
  auto value = [&](int axis) {
    const V64 seed = h + hn::Set(d64, 1 + static_cast<std::uint64_t>(axis));
    return hn::ShiftRight<8>(scramble(d64, sobol_sample(d64, permuted, axis), mix64(d64, seed)));
  };
  if (second) *second = value(1);
  return value(axis0);
}

}  // namespace pathlab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // PATHLAB_CORE_SIMD_SOBOL_INL_H_ toggle
