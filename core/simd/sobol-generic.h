// The samplers' hashes and the zsobol sampler's points over 64-bit lanes,
// written once for every width: core/simd/sobol-inl.h includes this text in
// each Highway target's namespace (the wavefront's vectorised stages draw
// one stream per lane) and core/sobol.h in pathlab::sobol::width1, over
// lane1's one plain uint64 (core's scalar sampler, core/rng.h, which the
// reference tracer draws from). Integer arithmetic throughout, so every
// width computes the same bits by construction; tests/test_sobol.cpp holds
// the scalar results to their definitions (the binomials, the nets), and
// VectorStages.* the lanes to width 1. core/sobol.h says what each function
// computes and why.
//
// No include guard and no includes: this is the body of the namespace it
// is included in. That namespace provides VecOf and HWY_INLINE, and the
// operations are found by argument-dependent lookup on the lane type:
// Set, And, Or, Xor, ShiftRight<k>, ShiftLeft<k>, ShiftRightSame,
// ShiftLeftSame, +, -, and three primitives whose best form differs by
// width: the products mul_wide32 and mul64, and permutation_image (Highway's
// in core/simd/lanes-inl.h; lane1's products in core/simd/lane1.h and its
// permutation_image in core/sobol.h, beside the table; each pair held to
// one result: integer arithmetic, exact both ways).

// sobol::mix (core/rng.h's mix64): the splitmix64 finaliser.
template <class D64, class V64 = VecOf<D64>>
constexpr HWY_INLINE V64 mix64(D64 d64, V64 z) {
  z = mul64(d64, Xor(z, ShiftRight<30>(z)), sobol::kMixMul0);
  z = mul64(d64, Xor(z, ShiftRight<27>(z)), sobol::kMixMul1);
  return Xor(z, ShiftRight<31>(z));
}

// sobol::permute_digits: from the top, each base-4 digit of the `bits` low
// bits of index through one of 24 permutations chosen by a hash of seed, the
// digit's place and the digits above it; with `bits` odd the lowest bit
// flipped or not by such a hash. `bits` is the same for every lane (the
// render's), so the loop is over digit places, not lanes.
template <class D64, class V64 = VecOf<D64>>
constexpr HWY_INLINE V64 permute_digits(D64 d64, V64 index, unsigned bits, V64 seed) {
  const unsigned lone = bits & 1u;
  V64 out = And(index, Set(d64, ~((bits >= 64 ? 0ull : (1ull << bits)) - 1ull)));
  for (unsigned p = bits - 2; p + 2 > lone && p < 64; p -= 2) {  // digit in bits [p, p + 1]
    const V64 higher = ShiftRightSame(index, static_cast<int>(p + 2));
    const V64 digit = And(ShiftRightSame(index, static_cast<int>(p)), Set(d64, 3));
    const V64 h = mix64(d64, Xor(seed + Set(d64, (static_cast<std::uint64_t>(p) + 1) * sobol::kDigitStep), higher));
    const V64 image = permutation_image(d64, h, digit);
    out = Or(out, ShiftLeftSame(image, static_cast<int>(p)));
    if (p < 2) break;
  }
  if (lone) {
    const V64 h = mix64(d64, Xor(Xor(seed, Set(d64, sobol::kLoneBitSalt)), ShiftRight<1>(index)));
    out = Or(out, And(Xor(index, ShiftRight<63>(h)), Set(d64, 1)));
  }
  return out;
}

// The low 32 bits of each lane (the high 32 are 0) in reverse order.
template <class D64, class V64 = VecOf<D64>>
constexpr HWY_INLINE V64 reverse_bits32(D64 d64, V64 v) {
  const auto swap = [d64](V64 x, int shift, std::uint64_t mask) {
    const V64 m = Set(d64, mask);
    return Or(And(ShiftRightSame(x, shift), m), ShiftLeftSame(And(x, m), shift));
  };
  v = swap(v, 1, 0x55555555u);
  v = swap(v, 2, 0x33333333u);
  v = swap(v, 4, 0x0f0f0f0fu);
  v = swap(v, 8, 0x00ff00ffu);
  return And(Or(ShiftRight<16>(v), ShiftLeft<16>(v)), Set(d64, 0xffffffffu));
}

// The low 32 bits of a * b (each below 2^32), as a 32-bit multiply gives.
template <class D64, class V64 = VecOf<D64>>
constexpr HWY_INLINE V64 mul32(D64 d64, V64 a, V64 b) {
  return And(mul_wide32(d64, a, b), Set(d64, 0xffffffffu));
}

// sobol::sample: point `index` (its low 32 bits) of Sobol's sequence in
// dimension `axis`, unscrambled, as a 32-bit fixed-point value (dimension 1
// by the five butterflies over supersets).
// sobol_sample_reversed is the point with its digits in reverse order (digit
// k after the point in bit k - 1), as scramble_reversed takes it: a zsobol
// draw skips the two reversals that would cancel.
template <class D64, class V64 = VecOf<D64>>
constexpr HWY_INLINE V64 sobol_sample_reversed(D64 d64, V64 index, int axis) {
  V64 f = And(index, Set(d64, 0xffffffffu));
  if (axis == 0) return f;
  for (unsigned b = 0; b < 5; ++b)
    f = Xor(f, And(ShiftRightSame(f, 1 << b), Set(d64, sobol::kSupersetMasks[b])));
  return f;
}
template <class D64, class V64 = VecOf<D64>>
constexpr HWY_INLINE V64 sobol_sample(D64 d64, V64 index, int axis) {
  return reverse_bits32(d64, sobol_sample_reversed(d64, index, axis));
}

// sobol::scramble: the nested scrambling of the 32-bit value v by `seed`.
// scramble_reversed takes v with its digits reversed (reverse_bits32(v)).
template <class D64, class V64 = VecOf<D64>>
constexpr HWY_INLINE V64 scramble_reversed(D64 d64, V64 v, V64 seed) {
  const V64 mask = Set(d64, 0xffffffffu), odd = Set(d64, 1);
  const V64 more = mix64(d64, Xor(seed, Set(d64, sobol::kScrambleSalt)));
  const V64 k0 = And(seed, mask), k1 = ShiftRight<32>(seed);
  const V64 k2 = And(more, mask), k3 = ShiftRight<32>(more);
  v = And(v + k0, mask);
  v = mul32(d64, v, Or(k1, odd));
  v = Xor(v, mul32(d64, v, Set(d64, sobol::kScrambleEven0)));
  v = And(v + k2, mask);
  v = mul32(d64, v, Or(k3, odd));
  v = Xor(v, mul32(d64, v, Set(d64, sobol::kScrambleEven1)));
  return reverse_bits32(d64, v);
}
template <class D64, class V64 = VecOf<D64>>
constexpr HWY_INLINE V64 scramble(D64 d64, V64 v, V64 seed) {
  return scramble_reversed(d64, reverse_bits32(d64, v), seed);
}

// A zsobol stream's number (SampleStream::get, get2): the top 24 bits of the
// scrambled point of `slot` in Sobol' dimension axis0 and, when `second` is
// not null, in axis 1 too (a 2D pair shares its permuted index). `key` is
// SamplerSetup::zsobol_key, `index` zsobol_index, `bits` zsobol_bits.
template <class D64, class V64 = VecOf<D64>>
constexpr HWY_INLINE V64 zsobol_top24(D64 d64, V64 index, V64 key, unsigned bits, V64 slot, int axis0,
                                      V64* second) {
  const V64 h = mix64(d64, Xor(key, mul64(d64, slot, sobol::kSlotStep)));
  const V64 permuted = permute_digits(d64, index, bits, h);
  const auto value = [&](int axis) {
    const V64 seed = h + Set(d64, 1 + static_cast<std::uint64_t>(axis));
    return ShiftRight<8>(scramble_reversed(d64, sobol_sample_reversed(d64, permuted, axis), mix64(d64, seed)));
  };
  if (second) *second = value(1);
  return value(axis0);
}
