// Deterministic quadrature over cells of the sphere in (z = cos theta, phi),
// where d(omega) = dz dphi, for peaked BSDF lobes: adaptive 2x2 Gauss-Legendre
// binary refinement, plus forced refinement near a known peak (a GGX lobe of
// alpha 1e-3 is a spike ~1e-3 rad wide that a coarse rule would step over).
// Used by the analytic rough-conductor model (directional albedo) and by the
// BSDF tests (chi-square expected counts, energy).
#pragma once

#include "core/math.h"

#include <initializer_list>
#include <utility>
#include <vector>

namespace pathlab::quadrature {

struct Peak {
  vec3 dir{0.0f, 0.0f, 1.0f};  // unit direction of the spike
  double width = 0.0;          // its angular width along theta (radians); 0: no peak
  double width_phi = 0.0;      // ... and across, along phi (radians of arc); 0: = width
  bool rim = false;            // the integrand jumps 90 degrees from dir (a lobe cut off there)
};

inline vec3 dir_of(double z, double phi) {
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  return vec3(static_cast<float>(r * std::cos(phi)), static_cast<float>(r * std::sin(phi)), static_cast<float>(z));
}

inline double angle_between(const vec3& a, const vec3& b) {
  // atan2 of |a x b| and a.b: accurate for tiny angles, unlike acos.
  return std::atan2(static_cast<double>(glm::length(glm::cross(a, b))), static_cast<double>(glm::dot(a, b)));
}

namespace detail {

// The integrand may be a number or an RGB triple (dvec3): one pass for all
// three channels.
inline double magnitude(double v) { return std::abs(v); }
inline double magnitude(const dvec3& v) { return std::max(std::abs(v.x), std::max(std::abs(v.y), std::abs(v.z))); }
template <typename F> using value_of = decltype(std::declval<const F&>()(0.0, 0.0));

template <typename F> value_of<F> gauss2x2(const F& f, double z0, double z1, double p0, double p1) {
  constexpr double g = 0.5773502691896257;  // 1/sqrt(3)
  const double zc = 0.5 * (z0 + z1), zh = 0.5 * (z1 - z0), pc = 0.5 * (p0 + p1), ph = 0.5 * (p1 - p0);
  value_of<F> s{0.0};
  for (const double a : {-g, g})
    for (const double b : {-g, g}) s += f(zc + a * zh, pc + b * ph);
  return s * zh * ph;
}

// Binary refinement. Far from every peak the cell splits along whichever
// side is longer as an angle (near the pole a cell's phi side is short
// however wide it is in phi; a z side is split at its mid-angle, not its
// mid-z, so that cells shrink there too) until the estimate settles:
// both its halvings, along theta and along phi, agree with the whole (the
// leaf then returns their extrapolation; see below).
// Around each peak the mesh is graded, anisotropically: measured in units
// of the peak's widths along theta and phi, a cell is trusted only once it
// is smaller than a quarter of its distance to the peak (and of one width).
// A reflected GGX lobe at a grazing view is a ridge ~alpha long and
// ~alpha wo.z wide, and its 1/theta^4 tail keeps 1 % of the mass beyond
// 10 alpha: a coarse cell there sees nearly nothing at its Gauss points and
// agrees with its equally blind children.
template <typename F>
value_of<F> refine(const F& f, double z0, double z1, double p0, double p1, const value_of<F>& coarse,
                   const std::vector<Peak>& peaks, double tol, int depth) {
  const double t0 = std::acos(z0), t1 = std::acos(z1);  // t0 >= t1
  const double side_theta = t0 - t1;
  const double side_phi = (p1 - p0) * std::sqrt(std::max(0.0, 1.0 - std::min(z0 * z0, z1 * z1)));
  const double tc = 0.5 * (t0 + t1), pc = 0.5 * (p0 + p1);
  bool near_peak = false, peak_wants_z = false;
  for (const Peak& pk : peaks) {
    if (!(pk.width > 0.0)) continue;
    const double wt = pk.width, wp = pk.width_phi > 0.0 ? pk.width_phi : pk.width;
    const double tp = std::acos(std::clamp(static_cast<double>(pk.dir.z), -1.0, 1.0));
    double dist;  // from the cell to the peak, in widths
    if (std::sin(tp) < 1e-3) {  // a peak at the pole is round
      dist = std::max(0.0, tc - 0.5 * side_theta - tp) / std::min(wt, wp);
    } else {
      double dphi = std::abs(pc - std::atan2(static_cast<double>(pk.dir.y), static_cast<double>(pk.dir.x)));
      dphi = std::fmod(dphi, 2.0 * 3.14159265358979323846);
      dphi = std::min(dphi, 2.0 * 3.14159265358979323846 - dphi);
      const double dt = std::max(0.0, std::abs(tc - tp) - 0.5 * side_theta) / wt;
      const double dp = std::max(0.0, dphi * std::sin(tc) - 0.5 * side_phi) / wp;
      dist = std::hypot(dt, dp);
    }
    const double st = side_theta / wt, sp = side_phi / wp;
    if (std::max(st, sp) > 0.25 * std::max(1.0, dist)) {
      near_peak = true;
      peak_wants_z = st >= sp;
    }
  }
  // A cell across a peak's rim (a jump in the integrand) is not trusted to
  // have converged: there the 2x2 rules of a cell and of its halves can
  // agree by accident while both are off. They did, by 12 % of a
  // chi-square cell, at the rim of a cospow lobe of exponent 0. Such a cell
  // is refined down to the 1e-4 rad floor below. The probes are the cell's
  // centre and its corners pulled 1 % inside.
  bool straddles = false;
  for (const Peak& pk : peaks) {
    if (!pk.rim || straddles) continue;
    const dvec3 axis(pk.dir);
    int inside = 0;
    for (const auto& [fz, fp] : {std::pair{0.01, 0.01}, {0.01, 0.99}, {0.99, 0.01}, {0.99, 0.99}, {0.5, 0.5}})
      inside += glm::dot(dvec3(dir_of(z0 + fz * (z1 - z0), p0 + fp * (p1 - p0))), axis) > 0.0 ? 1 : 0;
    straddles = inside > 0 && inside < 5;
  }
  bool split_z = near_peak ? peak_wants_z : side_theta >= side_phi;
  const double zm = std::cos(tc), pm = pc;
  const auto halves = [&](bool along_z, value_of<F>& a, value_of<F>& b) {
    a = along_z ? gauss2x2(f, z0, zm, p0, p1) : gauss2x2(f, z0, z1, p0, pm);
    b = along_z ? gauss2x2(f, zm, z1, p0, p1) : gauss2x2(f, z0, z1, pm, p1);
  };
  value_of<F> a, b;
  halves(split_z, a, b);
  value_of<F> fine = a + b;
  if (depth >= 96) return fine;
  if (!near_peak && !straddles && depth >= 4 && magnitude(fine - coarse) <= std::max(tol, 1e-4 * magnitude(fine))) {
    // The cell has settled only if its split along the other side agrees
    // too. One split is not enough: a lobe about the pole does not vary
    // along phi, so a phi split always agrees with its parent, and cells
    // trusted on that alone were up to 5 % off along z (2.5e-5 of a cospow
    // lobe seen head-on went missing, 40 samples of a chi-square of 1.6M).
    // If it does not, the cell splits along that side instead. If it does,
    // the two splits also measure the error of each side's 2-point rule
    // (the rule's error goes as the fourth power of the side: a split
    // removes 15/16 of it), and the leaf returns the cell's rule plus both:
    // Richardson's extrapolation. A Gauss rule misses a peak's mass from
    // below in every cell; the leaves' 1e-4 relative errors, all of one
    // sign, had added up to 3e-5 of a GTR1 lobe seen head-on, 1e-7 now.
    value_of<F> a2, b2;
    halves(!split_z, a2, b2);
    if (magnitude(a2 + b2 - coarse) <= std::max(tol, 1e-4 * magnitude(a2 + b2)))
      return coarse + (16.0 / 15.0) * ((fine - coarse) + (a2 + b2 - coarse));
    split_z = !split_z, a = a2, b = b2, fine = a2 + b2;
  }
  // Away from the peaks, cells below 1e-4 rad are not refined further: an
  // integrable singularity (GTR1's reflection Jacobian 1 / (4 wo.h) where h
  // turns perpendicular to a grazing wo) would otherwise take the
  // refinement to the depth cap for a vanishing mass.
  if (!near_peak && 0.5 * std::hypot(side_theta, side_phi) < 1e-4) return fine;
  // The tolerance shrinks by sqrt(2) per binary level (by 2 per halving of
  // both sides): along a discontinuity (a lobe cut by the horizon, a cospow
  // lobe's rim) the error of a straddling cell only halves per halving, and
  // a faster-shrinking tolerance would refine it to the depth cap.
  constexpr double kShrink = 0.7071067811865476;
  return split_z ? refine(f, z0, zm, p0, p1, a, peaks, kShrink * tol, depth + 1) +
                       refine(f, zm, z1, p0, p1, b, peaks, kShrink * tol, depth + 1)
                 : refine(f, z0, z1, p0, pm, a, peaks, kShrink * tol, depth + 1) +
                       refine(f, z0, z1, pm, p1, b, peaks, kShrink * tol, depth + 1);
}

}  // namespace detail

// Integral of f(z, phi) over [z0, z1] x [phi0, phi1] to about `tol` absolute
// or 1e-4 relative.
template <typename F>
detail::value_of<F> integrate_cell(const F& f, double z0, double z1, double phi0, double phi1,
                                   const std::vector<Peak>& peaks, double tol) {
  return detail::refine(f, z0, z1, phi0, phi1, detail::gauss2x2(f, z0, z1, phi0, phi1), peaks, tol, 0);
}

// Integral over the upper hemisphere (z in [0, 1]) on an nz x nphi grid of
// cells, each integrated adaptively.
template <typename F>
detail::value_of<F> integrate_hemisphere(const F& f, const std::vector<Peak>& peaks, double tol, int nz = 8,
                                         int nphi = 16) {
  detail::value_of<F> sum{0.0};
  const double cell_tol = tol / (nz * nphi);
  for (int i = 0; i < nz; ++i)
    for (int j = 0; j < nphi; ++j)
      sum += integrate_cell(f, static_cast<double>(i) / nz, static_cast<double>(i + 1) / nz, 2.0 * 3.14159265358979323846 * j / nphi,
                            2.0 * 3.14159265358979323846 * (j + 1) / nphi, peaks, cell_tol);
  return sum;
}

// The same, for an integrand of the direction (a unit vec3 from dir_of): the
// form every BSDF integral takes (albedos, densities, moments).
template <typename F>
auto integrate_directions(const F& f, const std::vector<Peak>& peaks, double tol, int nz = 8, int nphi = 16) {
  return integrate_hemisphere([&](double z, double phi) { return f(dir_of(z, phi)); }, peaks, tol, nz, nphi);
}

}  // namespace pathlab::quadrature
