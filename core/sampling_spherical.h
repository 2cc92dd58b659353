// Sampling uniformly in the solid angle an emitter subtends, for
// `light_sampling: solid_angle` (core/light_sampler.h):
//
// - a triangle by Arvo's stratified sampling of spherical triangles
//   (J. Arvo, "Stratified sampling of spherical triangles", SIGGRAPH 1995):
//   the first number picks the sub-triangle A B C' of area u.x * Omega, the
//   second a point on the arc B C' so that the density is 1 / Omega;
// - a sphere seen from outside uniformly in the cone of directions it
//   subtends, the point being the nearest crossing of that direction.
//
// Everything is computed in double from the float inputs: the spherical
// formulas subtract nearly equal angles for a small or distant emitter, and
// double keeps them about 1e-10 accurate down to the smallest solid angle
// the fallback rule (kMinSphericalTriangle) lets through. The sines, cosines
// and arctangents are pathlab's own (core/simd/spherical-inl.h), within a few
// ulp of libm's and the same bits at every SIMD width. The pure functions
// here take the shading point and the emitter and know nothing of scenes;
// LightSampler decides, by the rule below, which of them to call.
#pragma once

#include "core/math.h"

namespace pathlab {

// The fallback rule (docs/scene-format.md, "Light sampling"). A triangle is
// sampled in solid angle when the solid angle Omega it subtends from the
// shading point (spherical_triangle_solid_angle, in double) satisfies
// kMinSphericalTriangle <= Omega <= kMaxSphericalTriangle, else by area:
// below, the triangle is so small or so far that its area density in solid
// angle is constant across it to within ~0.3 % (unless grazing) and the
// spherical formulas are all cancellation; above (nearly a hemisphere: the
// shading point almost in the triangle's plane, inside its outline) the
// corner angles approach pi and Arvo's map divides by their sines. A point
// in the plane (Omega = 0 or 2 pi) always takes the area branch. The rule is
// a function of (shading point, triangle) alone, evaluated by the same code
// in sample() and pdf(), so MIS sees the density really used.
inline constexpr double kMinSphericalTriangle = 1e-6;
inline constexpr double kMaxSphericalTriangle = 6.2;  // 2 pi - 0.083
// A sphere is sampled in its cone when the shading point lies outside it:
// |ref - centre|^2 > kSphereConeMargin * r^2 (in double), else by area.
inline constexpr double kSphereConeMargin = 1.0002;  // about 1.0001 r

// Solid angle of the triangle (a, b, c) seen from the origin (the vectors need
// not be unit): Van Oosterom & Strackee (1983),
// tan(Omega / 2) = |a . (b x c)| / (|a||b||c| + (a.b)|c| + (a.c)|b| + (b.c)|a|),
// by atan2, so in [0, 2 pi]. 0 for a degenerate triangle or a point in its plane
// outside it, 2 pi for a point in its plane inside it.
double spherical_triangle_solid_angle(const dvec3& a, const dvec3& b, const dvec3& c);

// Arvo's map: a direction uniformly distributed (density 1 / omega) in the
// spherical triangle of the unit vectors A, B, C, whose solid angle is
// `omega` (as spherical_triangle_solid_angle gives it). u.x = 0 gives the arc
// A B, u.x = 1 the arc A C; u.y = 0 gives B. Unit length.
dvec3 sample_spherical_triangle(const dvec3& A, const dvec3& B, const dvec3& C, double omega, vec2 u);

// Where the ray from `origin` along `dir` meets the plane of the triangle
// (p0, p1, p2), as barycentrics (b1, b2) of p1 and p2, clamped into the
// triangle (a direction sampled inside the spherical triangle may round to
// just outside it). Double throughout.
vec2 triangle_barycentrics_along(const dvec3& origin, const dvec3& dir, const dvec3& p0, const dvec3& p1,
                                 const dvec3& p2);

// A sphere of radius r whose centre lies at distance d > r from the shading
// point subtends the cone of half-angle theta_max, sin theta_max = r / d.
struct SphereCone {
  dvec3 axis;             // unit, from the shading point to the centre
  double d = 0.0;         // distance to the centre
  double r = 0.0;
  double sin2_max = 0.0;  // (r / d)^2
  double one_minus_cos_max = 0.0;  // 1 - cos theta_max = sin2 / (1 + cos), without cancellation
  // ref lies outside the sphere by the rule's margin (kSphereConeMargin):
  // else the sphere is sampled by area and the rest is meaningless.
  bool outside = false;
  double solid_angle() const;      // 2 pi (1 - cos theta_max)
};
// The scalar functions here are core/simd/spherical-inl.h's generic code at
// width 1 (the wavefront's lanes run the same source).
SphereCone sphere_cone(const dvec3& ref, const dvec3& center, double radius);

}  // namespace pathlab
