// Sample warps of core/sampling.h written once over Highway's vectors:
// core/sampling.cpp calls them at width 1 for both tracers' scalar code,
// and vectorised code calls them at the width of its SIMD target. Every
// lane computes the bits the width-1 call computes (core/simd/simd.h says
// why; tests/test_simd.cpp checks it on every target this machine runs).
//
// Highway's "-inl.h" convention: no include guard but the toggle below, so
// that foreach_target.h can include this file once per target, each time
// inside that target's namespace and with its instruction set enabled.
#if defined(PATHLAB_CORE_SIMD_SAMPLING_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef PATHLAB_CORE_SIMD_SAMPLING_INL_H_
#undef PATHLAB_CORE_SIMD_SAMPLING_INL_H_
#else
#define PATHLAB_CORE_SIMD_SAMPLING_INL_H_
#endif

#include <hwy/highway.h>

#include "core/math.h"
#include "core/simd/lane1.h"
#include "core/simd/lanes-inl.h"

#include <initializer_list>

HWY_BEFORE_NAMESPACE();
namespace pathlab::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// sin and cos of x for |x| <= pi/4: Cephes' single-precision minimax
// polynomials (sinf, cosf), |error| < 2 ulp there, evaluated term by term
// in this order (no FMA), so that every target and width rounds alike.
template <class D, class V = VecOf<D>>
HWY_INLINE void sin_cos_quarter(D d, V x, V& sin, V& cos) {
  const V z = x * x;
  sin = ((((Set(d, -1.9515295891e-4f) * z) + Set(d, 8.3321608736e-3f)) * z) - Set(d, 1.6666654611e-1f)) *
            z * x +
        x;
  cos = ((((Set(d, 2.443315711809948e-5f) * z) - Set(d, 1.388731625493765e-3f)) * z +
          Set(d, 4.166664568298827e-2f)) *
             z * z -
         Set(d, 0.5f) * z) +
        Set(d, 1.0f);
}

// sin and cos of r + q pi/2 from s = sin r and c = cos r, where q1, q2 and q3
// are the lanes in which q mod 4 is 1, 2 and 3: (c, s) turned by 0 (c, s),
// 1 (-s, c), 2 (-c, -s) or 3 (s, -c) quarter turns.
template <class M, class V>
HWY_INLINE void quarter_turns(M q1, M q2, M q3, V s, V c, V& sin, V& cos) {
  const auto swap = Or(q1, q3);
  const V cs = IfThenElse(swap, s, c), sn = IfThenElse(swap, c, s);
  cos = IfThenElse(Or(q1, q2), Neg(cs), cs);
  sin = IfThenElse(Or(q2, q3), Neg(sn), sn);
}

// sin and cos of 2 pi u for u in [0, 1] (an azimuth from a uniform
// number): u in quarter turns, 4u = q + f with q the nearest whole number
// (exact: 4u and 4u - q are floats), sin_cos_quarter of f pi/2 in
// [-pi/4, pi/4], then turned by q quarter turns. Within 2 ulp of libm's
// sinf/cosf of the angle (tests/test_simd.cpp), and the same bits on every
// target and width, as libm's are not.
template <class D, class V = VecOf<D>>
HWY_INLINE void sin_cos_turn(D d, V u, V& sin, V& cos) {
  const V t = Set(d, 4.0f) * u;
  const V q = Round(t);
  V s, c;
  sin_cos_quarter(d, (t - q) * Set(d, 3.14159265358979323846f / 2.0f), s, c);
  // q mod 4 (4 as 0).
  quarter_turns(q == Set(d, 1.0f), q == Set(d, 2.0f), q == Set(d, 3.0f), s, c, sin, cos);
}

// 2^y for y in [-126, 127]: y = n + f with n the nearest whole number and f
// in [-1/2, 1/2] (exact), 2^f by Cephes' single-precision minimax
// polynomial (exp2f, relative error < 2e-7), evaluated term by term, times
// 2^n exactly (Pow2I, core/simd/lanes-inl.h).
template <class D, class V = VecOf<D>>
HWY_INLINE V exp2_lanes(D d, V y) {
  const V n = Round(y);
  const V f = y - n;
  const V p = (((((Set(d, 1.535336188319500e-4f) * f + Set(d, 1.339887440266574e-3f)) * f +
                  Set(d, 9.618437357674640e-3f)) * f +
                 Set(d, 5.550332471162809e-2f)) * f +
                Set(d, 2.402264791363012e-1f)) * f +
               Set(d, 6.931472028550421e-1f)) * f;
  return (Set(d, 1.0f) + p) * Pow2I(d, n);
}

// atan2(y, x) in [-pi, pi] from atan_small(r), the arctangent of |r| <=
// tan(pi/8) (+ rounding): r is the ratio t of the smaller |coordinate| to the
// larger (in [0, 1]; 0 for (0, 0)), or above tan(pi/8) (t - 1) / (t + 1),
// whose arctangent is pi/4 less; the angle is then turned to the octant and
// quadrant of (x, y), with y's sign. The constants are the precision's
// (float or double): tan(pi/8), pi/4, pi/2, pi.
template <class D, class AtanSmall, class V = VecOf<D>>
HWY_INLINE V atan2_octants(D d, V y, V x, V tan_pi_8, V pi_4, V pi_2, V pi, const AtanSmall& atan_small) {
  const V ay = Abs(y), ax = Abs(x);
  const auto steep = ay > ax;
  const V num = IfThenElse(steep, ax, ay), den = IfThenElse(steep, ay, ax);
  const V t = IfThenZeroElse(den == Zero(d), num / den);
  const auto above = t > tan_pi_8;
  const V one = Set(d, 1.0f);
  const V p = atan_small(IfThenElse(above, (t - one) / (t + one), t));
  V a = IfThenElse(above, p + pi_4, p);
  a = IfThenElse(steep, pi_2 - a, a);
  a = IfThenElse(x < Zero(d), pi - a, a);
  return CopySign(a, y);
}

// atan2(y, x) in [-pi, pi]: Cephes' single-precision atanf polynomial
// (|error| < 2 ulp on [0, tan(pi/8)]) of the ratio of the smaller |coordinate|
// to the larger (in [0, 1]; above tan(pi/8) reduced about pi/4), then turned
// to the octant and quadrant of (x, y), with y's sign. Within 3e-7 of libm's
// double atan2 (tests/test_simd.cpp). (0, 0) gives 0 with y's sign, -0 for
// x included (libm: pi for x = -0).
template <class D, class V = VecOf<D>>
HWY_INLINE V atan2_lanes(D d, V y, V x) {
  return atan2_octants(d, y, x, Set(d, 0.4142135623730950f), Set(d, 0.78539816339744830962f),
                       Set(d, 1.57079632679489661923f), Set(d, 3.14159265358979323846f), [&](V r) {
                         const V z = r * r;
                         return ((((Set(d, 8.05374449538e-2f) * z - Set(d, 1.38776856032e-1f)) * z +
                                   Set(d, 1.99777106478e-1f)) * z -
                                  Set(d, 3.33329491539e-1f)) *
                                 z) *
                                    r +
                                r;
                       });
}

// A polynomial in z by Horner's rule, from the highest coefficient to the
// constant: (...(c[0] z + c[1]) z + ...) z + c[n-1], each coefficient
// rounded once to the lanes' type. (Adding a negative coefficient rounds as
// subtracting its magnitude.)
template <class D, class V = VecOf<D>>
HWY_INLINE V series(D d, V z, std::initializer_list<double> c) {
  using T = typename D::T;
  const double* k = c.begin();
  V p = Set(d, static_cast<T>(*k));
  for (++k; k != c.end(); ++k) p = p * z + Set(d, static_cast<T>(*k));
  return p;
}

// The float logarithms and exponentials of the cosine-power lobe
// (core/bsdf/cospow-inl.h), pathlab's own for the reasons of sin_cos_turn:
// reductions that are exact or nearly so, then Taylor series whose
// coefficients are 1/n and 1/n! (correctly rounded divisions, nothing from a
// table), evaluated term by term. tests/test_simd.cpp holds each within
// 4.5 x 2^-24 of libm's double function, relative to the result, over its
// domain (measured: log 2.0, log1p 3.0, exp 1.4, expm1 3.7) and to one set
// of bits on every target and at width 1.

// ln 2 as kLn2Hi + kLn2Lo: kLn2Hi has 12 significant bits, so its product
// with a whole number below 2^12 in magnitude is exact.
inline constexpr float kLn2Hi = 0x1.62ep-1f;
inline constexpr float kLn2Lo = 3.19461833e-05f;  // float(ln 2 - kLn2Hi)

// 2 atanh(s) = ln((1 + s) / (1 - s)) for |s| <= 3 - 2 sqrt(2) (0.1716):
// 2s + 2s^3/3 + ... + 2s^9/9; the first term left out is below 2.1e-9 of
// the sum.
template <class D, class V = VecOf<D>>
HWY_INLINE V two_atanh_small(D d, V s) {
  const V z = s * s;
  return Set(d, 2.0f) * s + (s * z) * series(d, z, {2.0 / 9.0, 2.0 / 7.0, 2.0 / 5.0, 2.0 / 3.0});
}

// ln x for a positive normal float x: x = m 2^e (SplitExponent), m moved
// into [1/sqrt 2, sqrt 2] (a halving, exact), ln m = 2 atanh((m - 1) /
// (m + 1)) (m - 1 exact), plus e ln 2 in two parts.
template <class D, class V = VecOf<D>>
HWY_INLINE V log_lanes(D d, V x) {
  V e;
  V m = SplitExponent(d, x, e);
  const auto high = m > Set(d, 1.41421354f);
  m = IfThenElse(high, m * Set(d, 0.5f), m);
  e = IfThenElse(high, e + Set(d, 1.0f), e);
  const V one = Set(d, 1.0f);
  return e * Set(d, kLn2Hi) + (two_atanh_small(d, (m - one) / (m + one)) + e * Set(d, kLn2Lo));
}

// ln(1 + x) for x > -1 with 1 + x normal, keeping its relative accuracy
// near 0: where 1 + x is within [1/sqrt 2, sqrt 2], 2 atanh(x / (2 + x))
// (x itself, not the rounded 1 + x); elsewhere log_lanes(1 + x), whose
// rounding is then a small part of the result.
template <class D, class V = VecOf<D>>
HWY_INLINE V log1p_lanes(D d, V x) {
  const V one = Set(d, 1.0f);
  const auto near = And(x > Set(d, -0.29289323f), x < Set(d, 0.41421354f));
  const V small = two_atanh_small(d, x / (Set(d, 2.0f) + x));
  // Away from 0 only: the lanes near it give log_lanes 1 (a positive normal).
  const V far = log_lanes(d, IfThenElse(near, one, one + x));
  return IfThenElse(near, small, far);
}

// e^x - 1 for |x| <= ln 2 / 2 (plus rounding) by its Taylor series,
// x + x^2 (1/2 + x/6 + ... + x^7/9!); the first term left out is below
// 2e-11 of the result. exp_lanes's e^r is 1 plus this.
template <class D, class V = VecOf<D>>
HWY_INLINE V expm1_small(D d, V x) {
  return x + (x * x) * series(d, x, {1.0 / 362880.0, 1.0 / 40320.0, 1.0 / 5040.0, 1.0 / 720.0, 1.0 / 120.0,
                                     1.0 / 24.0, 1.0 / 6.0, 0.5});
}

// e^x for x in [-88, 88]; 0 below -87.6, where e^x is below the smallest
// normal float. x = k ln 2 + r with k the nearest whole number to x / ln 2
// and r = (x - k kLn2Hi) - k kLn2Lo (Cody and Waite; |r| <= ln 2 / 2 plus
// rounding), e^r = 1 + expm1_small(r), times 2^k exactly (Pow2I).
template <class D, class V = VecOf<D>>
HWY_INLINE V exp_lanes(D d, V x) {
  const auto underflow = x < Set(d, -87.6f);
  const V xc = IfThenElse(underflow, Zero(d), x);
  const V k = Round(xc * Set(d, 1.44269502f));  // 1 / ln 2
  const V r = (xc - k * Set(d, kLn2Hi)) - k * Set(d, kLn2Lo);
  const V er = Set(d, 1.0f) + expm1_small(d, r);
  return IfThenZeroElse(underflow, er * Pow2I(d, k));
}

// e^x - 1 for x <= 88, keeping its relative accuracy near 0: for |x| <=
// ln 2 / 2 expm1_small(x); elsewhere exp_lanes(x) - 1, exact by Sterbenz's
// lemma down to x = -ln 2 and a small part of the result beyond.
template <class D, class V = VecOf<D>>
HWY_INLINE V expm1_lanes(D d, V x) {
  const auto near = Abs(x) <= Set(d, 0.34657359f);
  return IfThenElse(near, expm1_small(d, x), exp_lanes(d, x) - Set(d, 1.0f));
}

// Distribution1D::sample's point in cell i of n whose cdf runs from lo to
// hi: where u falls between the two, kept inside the cell ((i + t) / n may
// round up to its upper edge). i and n are whole floats (exact below 2^24).
template <class D, class V = VecOf<D>>
HWY_INLINE V piecewise_point(D d, V u, V lo, V hi, V i, V n) {
  const V width = hi - lo;
  const V r = (u - lo) / width;
  const V clamped = IfThenElse(r < Zero(d), Zero(d), IfThenElse(Set(d, 1.0f) < r, Set(d, 1.0f), r));
  const V t = IfThenElseZero(width > Zero(d), clamped);
  const V upper = NextFloat<false>(d, (i + Set(d, 1.0f)) / n);
  return Min((i + t) / n, upper);
}

// A uniform direction on the unit sphere (square_to_uniform_sphere,
// core/sampling.h): z = 1 - 2 u.x, then the azimuth 2 pi u.y at radius
// sqrt(max(0, 1 - z z)) (Max(v, 0) in that order is std::max(0.0f, v), NaN
// included: cosine_hemisphere says why).
template <class D, class V = VecOf<D>>
HWY_INLINE void uniform_sphere(D d, V ux, V uy, V& x, V& y, V& z) {
  z = Set(d, 1.0f) - Set(d, 2.0f) * ux;
  const V r = Sqrt(Max(Set(d, 1.0f) - z * z, Zero(d)));
  V s, c;
  sin_cos_turn(d, uy, s, c);
  x = r * c;
  y = r * s;
}

// Shirley and Chiu's concentric map, square [0,1)^2 -> unit disk, area
// preserving. With o = 2u - 1: in the left and right wedges (|o.x| > |o.y|)
// the point is o.x (cos t, sin t) with t = (pi/4)(o.y / o.x); in the top and
// bottom ones o.y (sin p, cos p) with p = (pi/4)(o.x / o.y). The centre maps
// to 0 (where both ratios are 0/0).
template <class D, class V = VecOf<D>>
HWY_INLINE void concentric_disk(D d, V ux, V uy, V& x, V& y) {
  const V ox = Set(d, 2.0f) * ux - Set(d, 1.0f);
  const V oy = Set(d, 2.0f) * uy - Set(d, 1.0f);
  const auto wide = Abs(ox) > Abs(oy);
  const V r = IfThenElse(wide, ox, oy);
  V s, c;
  sin_cos_quarter(d, Set(d, 3.14159265358979323846f / 4.0f) * (IfThenElse(wide, oy, ox) / r), s, c);
  const auto centre = And(ox == Zero(d), oy == Zero(d));
  x = IfThenZeroElse(centre, r * IfThenElse(wide, c, s));
  y = IfThenZeroElse(centre, r * IfThenElse(wide, s, c));
}

// Camera::generate_ray: the ray through film position (fx, fy) in pixels
// (camera_direction) from a pinhole at the plane's position where
// aperture_radius <= 0, else from a thin lens of that radius focused at
// focus_distance, through its point aperture_radius concentric_disk(lu, lv)
// (thin_lens). lens_u(lu, lv) draws the lens pair (LensX, LensY): called
// only for a lens.
template <class D, class LensU, class V = VecOf<D>>
HWY_INLINE void camera_ray(D d, const CameraPlane<V>& plane, float aperture_radius, float focus_distance, V fx, V fy,
                           const LensU& lens_u, Vec3<V>& origin, Vec3<V>& dir) {
  const Vec3<V> through = camera_direction(d, plane, fx, fy);
  if (aperture_radius <= 0.0f) {
    origin = plane.position;
    dir = through;
    return;
  }
  V lu, lv, lx, ly;
  lens_u(lu, lv);
  concentric_disk(d, lu, lv, lx, ly);
  const V radius = Set(d, aperture_radius);
  thin_lens(d, plane, Set(d, focus_distance), through, radius * lx, radius * ly, origin, dir);
}

// Cosine-weighted direction about +z (Malley's method): the disk point
// lifted to the hemisphere, z = sqrt(max(0, (1 - x x) - y y)). Max(v, 0)
// in that order: x86's max returns its second operand for a NaN or for
// -0 against +0, so this is std::max(0.0f, v) exactly, NaN included.
template <class D, class V = VecOf<D>>
HWY_INLINE void cosine_hemisphere(D d, V ux, V uy, V& x, V& y, V& z) {
  concentric_disk(d, ux, uy, x, y);
  z = Sqrt(Max(Set(d, 1.0f) - x * x - y * y, Zero(d)));
}

// cosine_hemisphere_pdf (core/sampling.h): cos / pi above the horizon
// (z > 0), else 0.
template <class D, class V = VecOf<D>>
HWY_INLINE V cosine_hemisphere_pdf(D d, V z) {
  return IfThenElseZero(z > Zero(d), z * Set(d, kInvPi));
}

}  // namespace pathlab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // PATHLAB_CORE_SIMD_SAMPLING_INL_H_ toggle
