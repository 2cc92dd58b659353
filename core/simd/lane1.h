// One lane as a plain scalar: the width-1 instantiation of the generic
// per-lane code (core/simd/lanes-inl.h) that core's scalar functions call,
// so that the reference tracer and the wavefront's lanes run one source.
//
// Why not Highway's own width 1: the build's baseline is Highway's
// HWY_SCALAR target, whose Max, selects and bit casts go through branches
// and memcpy; the generic offset_ray_origin cost 4x core's hand-written
// scalar body there (docs/one-estimator.md). Here every operation is the
// plain scalar expression the compiler already turns into one instruction
// (maxss, a conditional move, a register move), and it has x86's semantics,
// which the generic code is written against:
//   Max(a, b) = a > b ? a : b and Min(a, b) = a < b ? a : b return the
//   second operand when either is NaN or both are zero (maxps/minps);
//   Sqrt is IEEE's correctly rounded square root (sqrtss = sqrtps lane).
//
// The generic code finds these by argument-dependent lookup: it calls its
// operations unqualified (Max(a, b), Set(d, x)), and for Highway's vectors
// and descriptors the same lookup finds Highway's. It names its vector type
// VecOf<D> (below) rather than hn::Vec<D>.
#pragma once

#include "core/ray.h"

#include <cmath>
#include <cstdint>
#include <type_traits>

namespace pathlab {

// The vector type of descriptor D, for Highway's descriptors and lane1's.
template <class D>
using VecOf = decltype(Zero(D()));

namespace lane1 {

// The descriptor: one lane of Lane. Only the operations the width-1 callers
// instantiate are here (core/simd/width1.h lists those callers); a generic
// function that needs another fails to compile at width 1 until it is added.
template <typename Lane>
struct One {
  using T = Lane;
};

// A lane and a lane's mask. Abs is fabs: +0 for -0, as Highway's Abs (GLM's
// abs keeps -0; triangle_point's error bound was -0 there, which no caller
// tells from +0).
template <typename T>
struct V {
  T raw;
};
struct M {
  bool raw;
};

// x converted to the lane's type, as Highway's Set does (Set(d64, 3)).
template <typename T>
constexpr V<T> Set(One<T>, std::type_identity_t<T> x) {
  return {x};
}
// Generic code written for float lanes (normalize's Set(d, 1.0f)) at a
// double lane: the constant widened, as Highway's Set does.
inline V<double> Set(One<double>, double x) { return {x}; }
template <typename T>
inline V<T> Zero(One<T>) {
  return {T(0)};
}

template <typename T>
constexpr V<T> operator+(V<T> a, V<T> b) {
  return {static_cast<T>(a.raw + b.raw)};
}
template <typename T>
constexpr V<T> operator-(V<T> a, V<T> b) {
  return {static_cast<T>(a.raw - b.raw)};
}
template <typename T>
inline V<T> operator*(V<T> a, V<T> b) {
  return {static_cast<T>(a.raw * b.raw)};
}
template <typename T>
inline V<T> operator/(V<T> a, V<T> b) {
  return {static_cast<T>(a.raw / b.raw)};
}
template <typename T>
inline M operator==(V<T> a, V<T> b) {
  return {a.raw == b.raw};
}
template <typename T>
inline M operator!=(V<T> a, V<T> b) {
  return {a.raw != b.raw};
}
template <typename T>
inline M operator>(V<T> a, V<T> b) {
  return {a.raw > b.raw};
}
template <typename T>
inline M operator>=(V<T> a, V<T> b) {
  return {a.raw >= b.raw};
}
template <typename T>
inline M operator<(V<T> a, V<T> b) {
  return {a.raw < b.raw};
}
template <typename T>
inline M operator<=(V<T> a, V<T> b) {
  return {a.raw <= b.raw};
}

template <typename T>
inline V<T> IfThenElse(M m, V<T> yes, V<T> no) {
  return m.raw ? yes : no;
}
template <typename T>
inline V<T> IfThenElseZero(M m, V<T> yes) {
  return m.raw ? yes : V<T>{T(0)};
}
template <typename T>
inline V<T> IfThenZeroElse(M m, V<T> no) {
  return m.raw ? V<T>{T(0)} : no;
}
inline M And(M a, M b) { return {a.raw && b.raw}; }
inline M AndNot(M not_a, M b) { return {!not_a.raw && b.raw}; }
inline M Not(M a) { return {!a.raw}; }
inline M Or(M a, M b) { return {a.raw || b.raw}; }
// A mask for lanes of another type: one lane is one lane.
template <typename T>
inline M RebindMask(One<T>, M m) {
  return m;
}
template <typename T>
inline bool AllFalse(One<T>, M m) {
  return !m.raw;
}
template <typename T>
inline bool AllTrue(One<T>, M m) {
  return m.raw;
}

// x86's maxps/minps, operand order included (see the top of the file).
inline V<float> Max(V<float> a, V<float> b) { return a.raw > b.raw ? a : b; }
inline V<float> Min(V<float> a, V<float> b) { return a.raw < b.raw ? a : b; }
inline V<float> Sqrt(V<float> a) { return {std::sqrt(a.raw)}; }
inline V<double> Sqrt(V<double> a) { return {std::sqrt(a.raw)}; }
// To the nearest integer, halves to even (roundps's nearest mode; the
// default rounding mode's nearbyint).
inline V<float> Round(V<float> a) { return {std::nearbyint(a.raw)}; }
inline V<float> Floor(V<float> a) { return {std::floor(a.raw)}; }
inline V<float> Abs(V<float> a) { return {std::fabs(a.raw)}; }
inline V<float> Neg(V<float> a) { return {-a.raw}; }
inline V<float> CopySign(V<float> magnitude, V<float> sign) { return {std::copysign(magnitude.raw, sign.raw)}; }
inline M IsInf(V<float> a) { return {std::isinf(a.raw)}; }
inline M IsFinite(V<float> a) { return {std::isfinite(a.raw)}; }

// The same for double lanes (core/simd/spherical-inl.h).
inline V<double> Max(V<double> a, V<double> b) { return a.raw > b.raw ? a : b; }
inline V<double> Min(V<double> a, V<double> b) { return a.raw < b.raw ? a : b; }
inline V<double> Round(V<double> a) { return {std::nearbyint(a.raw)}; }
inline V<double> Floor(V<double> a) { return {std::floor(a.raw)}; }
inline V<double> Abs(V<double> a) { return {std::fabs(a.raw)}; }
inline V<double> Neg(V<double> a) { return {-a.raw}; }
inline V<double> CopySign(V<double> magnitude, V<double> sign) { return {std::copysign(magnitude.raw, sign.raw)}; }
inline M IsFinite(V<double> a) { return {std::isfinite(a.raw)}; }

// c one float up for o > 0, down for o < 0 (lanes-inl.h's StepAway) by
// core/ray.h's scalar primitives, whose branches are cheaper at width 1
// than the form vector lanes need (both neighbours, then selects; held to
// these bits by tests/test_simd.cpp).
inline V<float> StepAway(One<float>, V<float> c, V<float> o) {
  return {o.raw > 0.0f ? next_float_up(c.raw) : o.raw < 0.0f ? next_float_down(c.raw) : c.raw};
}

// The float next to v towards +infinity (kUp) or -infinity: lanes-inl.h's
// NextFloat, by libm at width 1 (the same bits).
template <bool kUp>
inline V<float> NextFloat(One<float>, V<float> v) {
  return {std::nextafter(v.raw, kUp ? HUGE_VALF : -HUGE_VALF)};
}

// 2^n for a whole n in [-126, 127] (lanes-inl.h's Pow2I; exact both ways).
inline V<float> Pow2I(One<float>, V<float> n) { return {std::ldexp(1.0f, static_cast<int>(n.raw))}; }

// x = m 2^e, m in [1, 2), for a positive normal x (lanes-inl.h's
// SplitExponent; exact both ways).
inline V<float> SplitExponent(One<float>, V<float> x, V<float>& e) {
  int n = 0;
  const float m = std::frexp(x.raw, &n);  // in [1/2, 1)
  e.raw = static_cast<float>(n - 1);
  return {m * 2.0f};
}

// 64-bit integer lanes (core/simd/sobol-generic.h: the samplers' hashes),
// modulo 2^64 as Highway's are.
using U64 = V<std::uint64_t>;
constexpr U64 And(U64 a, U64 b) { return {a.raw & b.raw}; }
constexpr U64 Or(U64 a, U64 b) { return {a.raw | b.raw}; }
constexpr U64 Xor(U64 a, U64 b) { return {a.raw ^ b.raw}; }
template <int kBits>
constexpr U64 ShiftRight(U64 a) {
  return {a.raw >> kBits};
}
template <int kBits>
constexpr U64 ShiftLeft(U64 a) {
  return {a.raw << kBits};
}
constexpr U64 ShiftRightSame(U64 a, int bits) { return {a.raw >> bits}; }
constexpr U64 ShiftLeftSame(U64 a, int bits) { return {a.raw << bits}; }
// The two products core/simd/lanes-inl.h builds for Highway's lanes: the
// 64-bit product of the low 32 bits of a and b, and z * c modulo 2^64.
constexpr U64 mul_wide32(One<std::uint64_t>, U64 a, U64 b) { return {(a.raw & 0xffffffffu) * (b.raw & 0xffffffffu)}; }
constexpr U64 mul64(One<std::uint64_t>, U64 z, std::uint64_t c) { return {z.raw * c}; }
// (The third, permutation_image, is in core/sobol.h, beside its table.)

// 64-bit signed integer lanes: indices into a table (core/simd/light_bvh-inl.h's
// node indices), converted from doubles by truncation (cvttpd2qq) and read
// by GatherIndex.
using I64 = V<std::int64_t>;
inline I64 ConvertTo(One<std::int64_t>, V<double> v) { return {static_cast<std::int64_t>(v.raw)}; }
template <typename T>
inline V<T> GatherIndex(One<T>, const T* base, I64 index) {
  return {base[index.raw]};
}

}  // namespace lane1
}  // namespace pathlab
