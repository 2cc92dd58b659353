#include "core/sampling_spherical.h"

#include "core/simd/width1.h"

#include <numbers>

namespace pathlab {
namespace {

constexpr double kPiD = std::numbers::pi;

}  // namespace

// Each is core/simd/spherical-inl.h's generic code at width 1: the
// wavefront's vectorised stages run the same source in double lanes.

double spherical_triangle_solid_angle(const dvec3& a, const dvec3& b, const dvec3& c) {
  using namespace width1;
  return generic::spherical_triangle_solid_angle(kScalarD, lanes(a), lanes(b), lanes(c)).raw;
}

dvec3 sample_spherical_triangle(const dvec3& A, const dvec3& B, const dvec3& C, double omega, vec2 u) {
  using namespace width1;
  return scalars(generic::sample_spherical_triangle(kScalarD, lanes(A), lanes(B), lanes(C), D1{omega}, D1{double(u.x)},
                                                    D1{double(u.y)}));
}

vec2 triangle_barycentrics_along(const dvec3& origin, const dvec3& dir, const dvec3& p0, const dvec3& p1,
                                 const dvec3& p2) {
  using namespace width1;
  D1 b1, b2;
  generic::triangle_barycentrics_along(kScalarD, lanes(origin), lanes(dir), lanes(p0), lanes(p1), lanes(p2), b1, b2);
  return vec2(static_cast<float>(b1.raw), static_cast<float>(b2.raw));
}

double SphereCone::solid_angle() const { return 2.0 * kPiD * one_minus_cos_max; }

SphereCone sphere_cone(const dvec3& ref, const dvec3& center, double radius) {
  using namespace width1;
  SphereCone c;
  D3 axis;
  D1 dist, sin2_max, one_minus_cos_max;
  c.outside =
      generic::sphere_cone(kScalarD, lanes(ref), lanes(center), D1{radius}, axis, dist, sin2_max, one_minus_cos_max).raw;
  c.axis = scalars(axis);
  c.d = dist.raw;
  c.r = radius;
  c.sin2_max = sin2_max.raw;
  c.one_minus_cos_max = one_minus_cos_max.raw;
  return c;
}

}  // namespace pathlab
