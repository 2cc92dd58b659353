// Warps from the unit square to the domains the estimators sample, each with
// its density and its inverse (the inverses make the warps testable and let
// a recorded direction be mapped back to the random numbers that made it).
#pragma once

#include "core/math.h"

namespace pathlab {

// sin and cos of x for |x| <= pi/4, by fixed polynomials in plain float
// arithmetic (the coefficients of Cephes' sinf and cosf), within 2 ulp of
// the true values. Unlike libm's, the result is the same bits in any build
// and on any machine, and a vector lane that evaluates the same expression
// gets it too: the warps below use it so that the wavefront's AVX-512 stages
// (wavefront/vector_stages.h) draw the directions the reference draws.
struct SinCos {
  float sin, cos;
};
SinCos sin_cos_quarter(float x);

// Shirley-Chiu concentric map: square [0,1)^2 -> unit disk, area-preserving.
vec2 square_to_concentric_disk(vec2 u);
vec2 concentric_disk_to_square(vec2 p);

// Cosine-weighted hemisphere about +z (Malley's method on the concentric
// disk). Density cos(theta)/pi in solid angle.
vec3 square_to_cosine_hemisphere(vec2 u);
float cosine_hemisphere_pdf(const vec3& w);
vec2 cosine_hemisphere_to_square(const vec3& w);

// Uniform directions on the unit sphere. Density 1/(4 pi).
vec3 square_to_uniform_sphere(vec2 u);
inline float uniform_sphere_pdf() { return kInv4Pi; }
vec2 uniform_sphere_to_square(const vec3& w);

// Uniform point on a triangle as barycentrics (b1, b2); b0 = 1 - b1 - b2.
// Density 1/area in area measure.
vec2 square_to_uniform_triangle(vec2 u);
vec2 uniform_triangle_to_square(vec2 b);

// Veach's power heuristic (beta = 2) for two one-sample techniques.
inline float power_heuristic(float pdf_a, float pdf_b) {
  if (std::isinf(pdf_a)) return 1.0f;  // a delta the other technique cannot sample
  if (!(pdf_a > 0.0f)) return 0.0f;
  // a^2 / (a^2 + b^2) through the ratio: squaring the pdfs themselves would
  // overflow above ~1.8e19 and underflow below ~1e-23.
  const float r = pdf_b / pdf_a;
  return 1.0f / (1.0f + r * r);
}

// Solid-angle density of a point sampled on a surface with area density
// `pdf_area`, seen from distance `dist` at cosine `cos_light` to its normal.
// Returns 0 when the surface is seen edge-on (the sample carries no energy).
inline float area_to_solid_angle(float pdf_area, float dist, float cos_light) {
  const float c = std::abs(cos_light);
  return c > 0.0f ? pdf_area * dist * dist / c : 0.0f;
}

}  // namespace pathlab
