// Sums whose value does not depend on the order of their terms.
//
// The film adds every sample of a pixel into a few sums. In floating point
// (a + b) + c is not a + (b + c), so a render split into pieces - resumed
// from a checkpoint, spread over processes, merged from sample ranges -
// would give other bits than one process adding the same samples in one
// order. Here each term is rounded once, deterministically, to a fixed-point
// number (a 128-bit integer counting units of 2^-kFractionBits), and integer
// addition is exact, associative and commutative: any split, in any order,
// gives the same sum, bit for bit.
//
// The rounding is the only approximation: a term is represented to within
// half a unit, 2^-(kFractionBits + 1), whatever else is summed. Terms must
// stay below kLimit in magnitude (the film counts larger samples as bad, as
// it counts NaNs: docs/overnight.md, "The film's range").
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace pathlab {

__extension__ typedef __int128 int128_t;
__extension__ typedef unsigned __int128 uint128_t;

template <int kFractionBits>
class FixedSum {
 public:
  // Terms are kept below this, so that 2^31 of them cannot overflow.
  static constexpr int kIntegerBits = 127 - 31 - kFractionBits;
  static constexpr double kLimit = static_cast<double>(std::uint64_t{1} << kIntegerBits);

  constexpr FixedSum() = default;

  // Adds x, rounded to the nearest unit (halves away from zero). x must be
  // finite with |x| < kLimit.
  void add(double x) { set(get() + round(x)); }
  FixedSum& operator+=(const FixedSum& o) {
    set(get() + o.get());
    return *this;
  }
  // The sum, rounded to the nearest double.
  double value() const { return std::ldexp(static_cast<double>(get()), -kFractionBits); }
  bool operator==(const FixedSum& o) const { return lo_ == o.lo_ && hi_ == o.hi_; }

  // The raw 128 bits, low word first (the partial film's file format).
  std::uint64_t low() const { return lo_; }
  std::uint64_t high() const { return hi_; }
  static FixedSum from_words(std::uint64_t low, std::uint64_t high) {
    FixedSum s;
    s.lo_ = low;
    s.hi_ = high;
    return s;
  }

  // x in units of 2^-kFractionBits, rounded to nearest, halves away from
  // zero: a function of x alone.
  static int128_t round(double x) {
    const auto bits = std::bit_cast<std::uint64_t>(x);
    const int exponent = static_cast<int>((bits >> 52) & 0x7ff);
    if (exponent == 0) return 0;  // zero or subnormal: far below a unit
    const std::uint64_t mantissa = (bits & ((std::uint64_t{1} << 52) - 1)) | (std::uint64_t{1} << 52);
    // |x| = mantissa * 2^(exponent - 1075), so |x| / unit = mantissa * 2^shift.
    const int shift = exponent - 1075 + kFractionBits;
    int128_t units = 0;
    if (shift >= 0)
      units = static_cast<int128_t>(mantissa) << shift;  // |x| < kLimit keeps this inside 127 bits
    else if (shift > -64)
      units = static_cast<int128_t>((mantissa + (std::uint64_t{1} << (-shift - 1))) >> -shift);
    // else: |x| < half a unit; rounds to 0.
    return (bits >> 63) != 0 ? -units : units;
  }

 private:
  int128_t get() const { return static_cast<int128_t>((static_cast<uint128_t>(hi_) << 64) | lo_); }
  void set(int128_t v) {
    const auto u = static_cast<uint128_t>(v);
    lo_ = static_cast<std::uint64_t>(u);
    hi_ = static_cast<std::uint64_t>(u >> 64);
  }
  // Two words rather than an __int128 member: 8-byte alignment, so that a
  // pixel of three sums and a count takes 56 bytes, not 64.
  std::uint64_t lo_ = 0, hi_ = 0;
};

// First moments (radiance, weights): units of 2^-64, terms below 2^32.
using Sum1 = FixedSum<64>;
// Second moments (squared radiance): units of 2^-32, terms below 2^64.
using Sum2 = FixedSum<32>;

}  // namespace pathlab
