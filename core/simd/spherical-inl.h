// Solid-angle sampling of emitters (core/sampling_spherical.h, for
// `light_sampling: solid_angle`) written once over Highway's double lanes:
// core/sampling_spherical.cpp calls these at width 1 (core/simd/width1.h) for
// both tracers' scalar code, the wavefront's vectorised stages in the double
// halves of their float registers.
//
// Everything is double, as the scalar code always was (a small or distant
// triangle's formulas subtract nearly equal angles). The transcendentals are
// pathlab's own, so that every target and width rounds alike (libm's last
// bits differ between its FMA and plain builds, and Highway's contrib math
// between targets): sin and cos by their Taylor series on [-pi/4, pi/4] after
// an exact reduction by quarter turns, atan by its series after two
// reductions. The series' coefficients are 1/n! and 1/n, each one correctly
// rounded division of whole numbers exact in double; the truncation errors
// are below 1e-19, so the results are within a few ulp of the true values
// (tests/test_solid_angle_sampling.cpp holds them to libm's on 10^6 points).
// Term by term, no fused multiply-add (docs/one-estimator.md).
//
// Highway's "-inl.h" convention: no include guard but the toggle below.
#if defined(PATHLAB_CORE_SIMD_SPHERICAL_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef PATHLAB_CORE_SIMD_SPHERICAL_INL_H_
#undef PATHLAB_CORE_SIMD_SPHERICAL_INL_H_
#else
#define PATHLAB_CORE_SIMD_SPHERICAL_INL_H_
#endif

#include <hwy/highway.h>

#include "core/sampling_spherical.h"
#include "core/simd/lane1.h"
#include "core/simd/lanes-inl.h"
#include "core/simd/sampling-inl.h"

HWY_BEFORE_NAMESPACE();
namespace pathlab::HWY_NAMESPACE {

// sin and cos of x for |x| <= 5 pi / 2 (the angles here are within
// [-pi, 2 pi]). x = q pi/2 + r with q the nearest whole number to x 2/pi and
// r = ((x - q P1) - q P2) - q P3 (Cody and Waite): P1 is pi/2 to 33 bits, P2
// the next 33, P3 the next 53 (the three within 1e-37 of pi/2); q P1 and q P2
// are exact, and so are the first two subtractions near a multiple of pi/2,
// by Sterbenz's lemma, so r keeps its relative accuracy even there. Then the
// series of sin and cos of r (|r| <= pi/4 + 1e-16), to r^17 and r^18, turned
// by q mod 4 quarter turns.
template <class D, class V = VecOf<D>>
HWY_INLINE void sin_cos_d(D d, V x, V& sin, V& cos) {
  const V q = Round(x * Set(d, 0.6366197723675814));  // 2 / pi
  const V r = ((x - q * Set(d, 1.5707963267341256)) - q * Set(d, 6.077100506303966e-11)) -
              q * Set(d, 2.0222662487959506e-21);
  const V z = r * r;
  // sin r = r + r z (-1/3! + z (1/5! + z (-1/7! + ...))), to 1/17!;
  // cos r = (1 - z/2) + z^2 (1/4! + z (-1/6! + ...)), to 1/18!.
  const V sr = r + (r * z) * series(d, z, {1.0 / 355687428096000.0, -1.0 / 1307674368000.0, 1.0 / 6227020800.0,
                                           -1.0 / 39916800.0, 1.0 / 362880.0, -1.0 / 5040.0, 1.0 / 120.0, -1.0 / 6.0});
  const V cr = (Set(d, 1.0) - Set(d, 0.5) * z) +
               (z * z) * series(d, z, {-1.0 / 6402373705728000.0, 1.0 / 20922789888000.0, -1.0 / 87178291200.0,
                                       1.0 / 479001600.0, -1.0 / 3628800.0, 1.0 / 40320.0, -1.0 / 720.0, 1.0 / 24.0});
  // q mod 4 (q - 4 floor(q / 4), exact for these small whole numbers).
  const V m = q - Set(d, 4.0) * Floor(q * Set(d, 0.25));
  quarter_turns(m == Set(d, 1.0), m == Set(d, 2.0), m == Set(d, 3.0), sr, cr, sin, cos);
}

// atan2(y, x) in [-pi, pi], as core/simd/sampling-inl.h's atan2_lanes in
// double (atan2_octants): the reduced r (|r| <= tan(pi/8)) halved in angle,
// atan r = 2 atan(r / (1 + sqrt(1 + r^2))), to |h| <= tan(pi/16) < 0.2, then
// the series h - h^3/3 + ... to h^25. (0, 0) gives 0 with y's sign (libm: pi
// for x = -0). A NaN gives NaN.
template <class D, class V = VecOf<D>>
HWY_INLINE V atan2_d(D d, V y, V x) {
  return atan2_octants(d, y, x, Set(d, 0.41421356237309503), Set(d, 0.7853981633974483), Set(d, 1.5707963267948966),
                       Set(d, 3.141592653589793), [&](V r) {
                         const V h = r / (Set(d, 1.0) + Sqrt(Set(d, 1.0) + r * r));
                         const V z = h * h;
                         const V p = series(d, z, {1.0 / 25.0, -1.0 / 23.0, 1.0 / 21.0, -1.0 / 19.0, 1.0 / 17.0,
                                                   -1.0 / 15.0, 1.0 / 13.0, -1.0 / 11.0, 1.0 / 9.0, -1.0 / 7.0,
                                                   1.0 / 5.0, -1.0 / 3.0});
                         return Set(d, 2.0) * (h + (h * z) * p);
                       });
}

// spherical_triangle_solid_angle: Van Oosterom & Strackee's
// tan(Omega / 2) = |a . (b x c)| / (|a||b||c| + (a.b)|c| + (a.c)|b| + (b.c)|a|).
template <class D, class V = VecOf<D>>
HWY_INLINE V spherical_triangle_solid_angle(D d, const Vec3<V>& a, const Vec3<V>& b, const Vec3<V>& c) {
  const V la = Sqrt(dot(a, a)), lb = Sqrt(dot(b, b)), lc = Sqrt(dot(c, c));
  const V det = Abs(dot(a, cross(b, c)));
  const V denom = ((la * lb * lc + dot(a, b) * lc) + dot(a, c) * lb) + dot(b, c) * la;
  return Set(d, 2.0) * atan2_d(d, det, denom);
}

// The component of v orthogonal to the unit vector a, normalised.
template <class D, class V = VecOf<D>>
HWY_INLINE Vec3<V> orthogonal_unit(D d, const Vec3<V>& v, const Vec3<V>& a) {
  return normalize(d, v - dot(v, a) * a);
}

// sample_spherical_triangle: Arvo's map of (ux, uy) to a direction of
// density 1 / omega in the spherical triangle of the unit vectors A, B, C.
template <class D, class V = VecOf<D>>
HWY_INLINE Vec3<V> sample_spherical_triangle(D d, const Vec3<V>& A, const Vec3<V>& B, const Vec3<V>& C, V omega, V ux,
                                             V uy) {
  // The corner angle alpha at A, from the tangents there towards B and C.
  const Vec3<V> tb = B - dot(A, B) * A, tc = C - dot(A, C) * A;
  const V lbc = Sqrt(dot(tb, tb)) * Sqrt(dot(tc, tc));
  const V cos_alpha = dot(tb, tc) / lbc;
  const Vec3<V> tbc = cross(tb, tc);
  const V sin_alpha = Sqrt(dot(tbc, tbc)) / lbc;
  const V cos_c = dot(A, B);  // the side A B
  // The sub-triangle A B C' of area ux omega: C' on the arc A C at
  // cos(arc A C') = q.
  V s, t;
  sin_cos_d(d, ux * omega - atan2_d(d, sin_alpha, cos_alpha), s, t);
  const V uu = t - cos_alpha;
  const V vv = s + sin_alpha * cos_c;
  const V denom = (vv * s + uu * t) * sin_alpha;
  V q = IfThenElse(denom == Zero(d), Set(d, 1.0), ((vv * t - uu * s) * cos_alpha - vv) / denom);
  q = IfThenElse(q < Set(d, -1.0), Set(d, -1.0), IfThenElse(Set(d, 1.0) < q, Set(d, 1.0), q));  // std::clamp
  const Vec3<V> c_prime = q * A + Sqrt(Max(Set(d, 1.0) - q * q, Zero(d))) * orthogonal_unit(d, C, A);
  // Then uniform in solid angle along the arc B C': the cosine to B is linear in uy.
  const V z = Set(d, 1.0) - uy * (Set(d, 1.0) - dot(c_prime, B));
  const Vec3<V> p = z * B + Sqrt(Max(Set(d, 1.0) - z * z, Zero(d))) * orthogonal_unit(d, c_prime, B);
  return normalize(d, p);
}

// triangle_barycentrics_along: where the ray (origin, dir) meets the plane
// of (p0, p1, p2), as barycentrics (b1, b2) clamped into the triangle; a
// plane the ray runs along (or a non-finite crossing) gives the centroid,
// (1/3, 1/3) as floats (the scalar function returns floats).
template <class D, class V = VecOf<D>>
HWY_INLINE void triangle_barycentrics_along(D d, const Vec3<V>& origin, const Vec3<V>& dir, const Vec3<V>& p0,
                                            const Vec3<V>& p1, const Vec3<V>& p2, V& b1, V& b2) {
  const Vec3<V> e1 = p1 - p0, e2 = p2 - p0;
  const Vec3<V> pv = cross(dir, e2);
  const V det = dot(e1, pv);
  const Vec3<V> tv = origin - p0;
  V u = dot(tv, pv) / det;
  V v = dot(dir, cross(tv, e1)) / det;
  const auto centroid = Or(Or(det == Zero(d), Not(IsFinite(det))), Not(And(IsFinite(u), IsFinite(v))));
  u = Max(u, Zero(d));  // std::max(0.0, u)
  v = Max(v, Zero(d));
  const V sum = u + v;
  const auto over = sum > Set(d, 1.0);
  u = IfThenElse(over, u / sum, u);
  v = IfThenElse(over, v / sum, v);
  const V third = Set(d, static_cast<double>(1.0f / 3.0f));
  b1 = IfThenElse(centroid, third, u);
  b2 = IfThenElse(centroid, third, v);
}

// sphere_cone's one_minus_cos_max, sin^2 theta_max / (1 + cos theta_max),
// for a sphere of radius r whose centre is at distance dist.
template <class D, class V = VecOf<D>>
HWY_INLINE V sphere_cone_one_minus_cos(D d, V dist, V r, V& sin2_max) {
  sin2_max = (r / dist) * (r / dist);
  const V cos_max = Sqrt(Max(Set(d, 1.0) - sin2_max, Zero(d)));
  return sin2_max / (Set(d, 1.0) + cos_max);
}

// sample_sphere_cone_normal: a direction uniform in the cone about `axis`
// (unit, towards the centre at distance dist) of 1 - cos theta_max =
// one_minus_cos_max, returned as the unit normal of the sphere where that
// direction first meets it.
template <class D, class V = VecOf<D>>
HWY_INLINE Vec3<V> sample_sphere_cone_normal(D d, const Vec3<V>& axis, V dist, V sin2_max, V one_minus_cos_max, V ux,
                                             V uy) {
  const V one_minus_cos = ux * one_minus_cos_max;
  const V cos_theta = Set(d, 1.0) - one_minus_cos;
  const V sin2 = one_minus_cos * (Set(d, 2.0) - one_minus_cos);
  const V sin_theta = Sqrt(sin2);
  // The nearest crossing at t = dist cos theta - s, s = dist sqrt(sin2_max -
  // sin2); relative to the centre its axial part is -(dist sin^2 + s cos).
  const V s = dist * Sqrt(Max(sin2_max - sin2, Zero(d)));
  const V t = dist * cos_theta - s;
  const V radial = t * sin_theta;
  const V axial = Neg(dist * sin2 + s * cos_theta);
  V sin_phi, cos_phi;
  sin_cos_d(d, Set(d, 6.283185307179586) * uy, sin_phi, cos_phi);  // 2 pi (2.0 * pi, exact)
  Vec3<V> bs, bt;
  frame(d, axis, bs, bt);
  const Vec3<V> n = radial * (cos_phi * bs + sin_phi * bt) + axial * axis;
  return normalize(d, n);
}

// solid_angle_draw's view of a triangle (p0, p1, p2) seen from o:
// its solid angle omega, and whether the fallback rule samples it in solid
// angle (kMinSphericalTriangle <= omega <= kMaxSphericalTriangle), with
// that density, 1 / omega (finite there).
template <class D, class V = VecOf<D>>
HWY_INLINE auto triangle_view(D d, const Vec3<V>& o, const Vec3<V>& p0, const Vec3<V>& p1, const Vec3<V>& p2,
                              V& omega, V& density) {
  omega = spherical_triangle_solid_angle(d, p0 - o, p1 - o, p2 - o);
  density = Set(d, 1.0) / omega;
  return And(omega >= Set(d, kMinSphericalTriangle), omega <= Set(d, kMaxSphericalTriangle));
}

// LightSampler::sample's point on a triangle sampled in solid angle from o
// (omega from triangle_view): Arvo's direction towards the triangle's
// corners, then where it meets the triangle, as barycentrics (b1, b2) of p1
// and p2 (floats held in doubles: the scalar function returns them so).
template <class D, class V = VecOf<D>>
HWY_INLINE void solid_angle_triangle_point(D d, const Vec3<V>& o, const Vec3<V>& p0, const Vec3<V>& p1,
                                           const Vec3<V>& p2, V omega, V ux, V uy, V& b1, V& b2) {
  const Vec3<V> dir = sample_spherical_triangle(d, normalize(d, p0 - o), normalize(d, p1 - o), normalize(d, p2 - o),
                                                omega, ux, uy);
  triangle_barycentrics_along(d, o, dir, p0, p1, p2, b1, b2);
}

// sphere_cone: the cone a sphere of radius r about `center` subtends from
// `ref` (axis, the distance to the centre, sin^2 and 1 - cos of its
// half-angle); true where ref lies outside the sphere by the rule's margin
// (|ref - centre|^2 > kSphereConeMargin r^2; else the sphere is sampled by
// area, and the cone is meaningless).
template <class D, class V = VecOf<D>>
HWY_INLINE auto sphere_cone(D d, const Vec3<V>& ref, const Vec3<V>& center, V r, Vec3<V>& axis, V& dist, V& sin2_max,
                            V& one_minus_cos_max) {
  const Vec3<V> to = center - ref;
  const V dd = dot(to, to);
  dist = Sqrt(dd);
  axis = to / dist;
  one_minus_cos_max = sphere_cone_one_minus_cos(d, dist, r, sin2_max);
  return dd > (Set(d, kSphereConeMargin) * r) * r;
}

// SphereCone::solid_angle's density, 1 / (2 pi (1 - cos theta_max)).
template <class D, class V = VecOf<D>>
HWY_INLINE V sphere_cone_density(D d, V one_minus_cos_max) {
  return Set(d, 1.0) / (Set(d, 6.283185307179586) * one_minus_cos_max);
}

// LightSampler's solid-angle rule for the area lights in the lanes of m,
// seen from o (triangles p0 p1 p2; where `sphere`, a sphere of centre p0
// and radius p1.x): `use` where the rule samples a light in the solid angle
// it subtends (a triangle's spherical triangle within the rule's bounds, a
// sphere's cone from outside it), with that density (1 / solid angle,
// without the pick probability; a density that is not finite falls back to
// area). With `draw`, the point drawn there with (ux, uy): a triangle's
// barycentrics (b1, b2), a sphere's unit normal n. Off `use`, 0.
template <class V, class M>
struct SolidAngleDraw {
  M use;
  V density, b1, b2;
  Vec3<V> n;
};
template <class D, class M, class V = VecOf<D>>
HWY_INLINE SolidAngleDraw<V, M> solid_angle_draw(D d, M m, M sphere, const Vec3<V>& o, const Vec3<V>& p0,
                                                 const Vec3<V>& p1, const Vec3<V>& p2, bool draw, V ux, V uy) {
  SolidAngleDraw<V, M> out{AndNot(m, m), Zero(d), Zero(d), Zero(d), {Zero(d), Zero(d), Zero(d)}};
  if (AllFalse(d, m)) return out;
  const M spheres = And(m, sphere), triangles = AndNot(sphere, m);
  M sampled = out.use;
  V density = Zero(d);
  if (!AllFalse(d, triangles)) {
    V omega, density_t;
    const M t = And(triangles, triangle_view(d, o, p0, p1, p2, omega, density_t));
    sampled = t;
    density = IfThenElse(t, density_t, density);
    if (draw && !AllFalse(d, t)) {
      V b1, b2;
      solid_angle_triangle_point(d, o, p0, p1, p2, omega, ux, uy, b1, b2);
      out.b1 = IfThenElseZero(t, b1);
      out.b2 = IfThenElseZero(t, b2);
    }
  }
  if (!AllFalse(d, spheres)) {
    Vec3<V> axis;
    V dist, sin2_max, one_minus_cos_max;
    const M s = And(spheres, sphere_cone(d, o, p0, p1.x, axis, dist, sin2_max, one_minus_cos_max));
    sampled = Or(sampled, s);
    density = IfThenElse(s, sphere_cone_density(d, one_minus_cos_max), density);
    if (draw && !AllFalse(d, s))
      out.n = select(s, sample_sphere_cone_normal(d, axis, dist, sin2_max, one_minus_cos_max, ux, uy), out.n);
  }
  out.use = And(sampled, IsFinite(density));
  out.density = IfThenElseZero(out.use, density);
  return out;
}

}  // namespace pathlab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // PATHLAB_CORE_SIMD_SPHERICAL_INL_H_
