#include "core/sampling_spherical.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace pathlab {
namespace {

constexpr double kPiD = std::numbers::pi;

// The component of `v` orthogonal to the unit vector `a`, normalised.
dvec3 orthogonal_unit(const dvec3& v, const dvec3& a) { return glm::normalize(v - glm::dot(v, a) * a); }

// An orthonormal basis (s, t) completing the unit vector n (Duff et al. 2017).
void basis(const dvec3& n, dvec3* s, dvec3* t) {
  const double sign = std::copysign(1.0, n.z);
  const double a = -1.0 / (sign + n.z);
  const double b = n.x * n.y * a;
  *s = dvec3(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
  *t = dvec3(b, sign + n.y * n.y * a, -n.y);
}

}  // namespace

double spherical_triangle_solid_angle(const dvec3& a, const dvec3& b, const dvec3& c) {
  const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
  const double det = std::abs(glm::dot(a, glm::cross(b, c)));
  const double denom = la * lb * lc + glm::dot(a, b) * lc + glm::dot(a, c) * lb + glm::dot(b, c) * la;
  return 2.0 * std::atan2(det, denom);
}

dvec3 sample_spherical_triangle(const dvec3& A, const dvec3& B, const dvec3& C, double omega, vec2 u) {
  // The corner angle alpha at A, between the arcs towards B and towards C,
  // from the tangents there (atan2-accurate for any size: no acos).
  const dvec3 tb = B - glm::dot(A, B) * A, tc = C - glm::dot(A, C) * A;
  const double lbc = glm::length(tb) * glm::length(tc);
  const double cos_alpha = glm::dot(tb, tc) / lbc;
  const double sin_alpha = glm::length(glm::cross(tb, tc)) / lbc;
  const double cos_c = glm::dot(A, B);  // the side A B
  // The sub-triangle A B C' of area u.x * omega: C' on the arc A C at
  // cos(arc A C') = q (Arvo 1995, eq. for q from the area's sine and cosine).
  const double area = double(u.x) * omega;
  const double s = std::sin(area - std::atan2(sin_alpha, cos_alpha));
  const double t = std::cos(area - std::atan2(sin_alpha, cos_alpha));
  const double uu = t - cos_alpha;
  const double vv = s + sin_alpha * cos_c;
  const double denom = (vv * s + uu * t) * sin_alpha;
  double q = denom != 0.0 ? ((vv * t - uu * s) * cos_alpha - vv) / denom : 1.0;
  q = std::clamp(q, -1.0, 1.0);
  const dvec3 c_prime = q * A + std::sqrt(std::max(0.0, 1.0 - q * q)) * orthogonal_unit(C, A);
  // Then uniformly in solid angle along the arc B C': the cosine to B is
  // linear in u.y.
  const double z = 1.0 - double(u.y) * (1.0 - glm::dot(c_prime, B));
  const dvec3 p = z * B + std::sqrt(std::max(0.0, 1.0 - z * z)) * orthogonal_unit(c_prime, B);
  return glm::normalize(p);
}

vec2 triangle_barycentrics_along(const dvec3& origin, const dvec3& dir, const dvec3& p0, const dvec3& p1,
                                 const dvec3& p2) {
  // Moeller-Trumbore without the range tests: the plane's crossing, in the
  // triangle's own coordinates.
  const dvec3 e1 = p1 - p0, e2 = p2 - p0;
  const dvec3 pv = glm::cross(dir, e2);
  const double det = glm::dot(e1, pv);
  if (det == 0.0 || !std::isfinite(det)) return vec2(1.0f / 3.0f);
  const dvec3 tv = origin - p0;
  double b1 = glm::dot(tv, pv) / det;
  double b2 = glm::dot(dir, glm::cross(tv, e1)) / det;
  if (!std::isfinite(b1) || !std::isfinite(b2)) return vec2(1.0f / 3.0f);
  b1 = std::max(0.0, b1);
  b2 = std::max(0.0, b2);
  const double sum = b1 + b2;
  if (sum > 1.0) b1 /= sum, b2 /= sum;
  return vec2(static_cast<float>(b1), static_cast<float>(b2));
}

double SphereCone::solid_angle() const { return 2.0 * kPiD * one_minus_cos_max; }

SphereCone sphere_cone(const dvec3& ref, const dvec3& center, double radius) {
  SphereCone c;
  const dvec3 to = center - ref;
  c.d = glm::length(to);
  c.axis = to / c.d;
  c.r = radius;
  c.sin2_max = (radius / c.d) * (radius / c.d);
  const double cos_max = std::sqrt(std::max(0.0, 1.0 - c.sin2_max));
  c.one_minus_cos_max = c.sin2_max / (1.0 + cos_max);
  return c;
}

dvec3 sample_sphere_cone_normal(const SphereCone& cone, vec2 u) {
  const double one_minus_cos = double(u.x) * cone.one_minus_cos_max;
  const double cos_theta = 1.0 - one_minus_cos;
  const double sin2 = one_minus_cos * (2.0 - one_minus_cos);
  const double sin_theta = std::sqrt(sin2);
  // The nearest crossing at distance t = d cos theta - s, with
  // s = sqrt(r^2 - d^2 sin^2 theta) = d sqrt(sin2_max - sin2). Relative to the
  // centre the point is t (sin theta, 0, cos theta) - (0, 0, d): its axial
  // part is -(d sin^2 theta + s cos theta), free of cancellation.
  const double s = cone.d * std::sqrt(std::max(0.0, cone.sin2_max - sin2));
  const double t = cone.d * cos_theta - s;
  const double radial = t * sin_theta;
  const double axial = -(cone.d * sin2 + s * cos_theta);
  const double phi = 2.0 * kPiD * double(u.y);
  dvec3 bs, bt;
  basis(cone.axis, &bs, &bt);
  const dvec3 n = radial * (std::cos(phi) * bs + std::sin(phi) * bt) + axial * cone.axis;
  return glm::normalize(n);
}

}  // namespace pathlab
