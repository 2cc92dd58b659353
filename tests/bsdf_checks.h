// The BSDF checks, as functions, shared by the statistical suite
// (test_bsdf_stat.cpp: the whole parameter grid), the unit suite
// (test_bsdf.cpp) and the planted-fault suite (test_faults.cpp, which runs
// them against deliberately broken lobes and expects them to fail).
//
//   chi2_test      equal-area bins in (cos theta, phi) over the upper
//                  hemisphere plus one cell for samples lost below it;
//                  expected counts by adaptive quadrature of the pdf
//                  (core/bsdf/quadrature.h); cells expected < 5 pooled;
//                  on failure the histograms go to a TSV file for plotting.
//   consistency    per sample: weight = eval / pdf and pdf = pdf(wi) within
//                  1e-4 relative; reciprocity of eval / |cos theta_i|.
//   albedo         directional albedo by quadrature and by Monte Carlo.
//   extremes       random (direction, parameters) draws at the edges of
//                  every range: no NaN, no Inf, no negative value.
#pragma once

#include "core/bsdf/cospow.h"
#include "core/bsdf/disney.h"
#include "core/bsdf/quadrature.h"
#include "core/material.h"
#include "core/surfel.h"
#include "tests/stat_util.h"

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace pathlab::test::bsdf {

constexpr double kTwoPi = 6.283185307179586;

// Fixed-seed uniform numbers in [0,1) with 24 bits, like the renderer's.
class Uniform {
 public:
  explicit Uniform(std::uint64_t seed) : rng_(seed) {}
  float next() { return static_cast<float>(rng_() >> 40) * 0x1p-24f; }
  vec2 next2() {
    const float x = next();
    return vec2(x, next());
  }
  std::uint64_t bits() { return rng_(); }

 private:
  std::mt19937_64 rng_;
};

// A view direction of the given cosine, at an azimuth off the tangent axes
// (so that anisotropy is not aligned with the test).
inline vec3 view_dir(float cos_theta) {
  const float s = std::sqrt(std::max(0.0f, 1.0f - cos_theta * cos_theta));
  return vec3(s * std::cos(0.7f), s * std::sin(0.7f), cos_theta);
}

// A surfel at the origin with normal +z (the identity frame, so world =
// local exactly) made of `m`.
inline Surfel flat_surfel(const Material& m) {
  Surfel s;
  s.p = vec3(0.0f);
  s.n = vec3(0.0f, 0.0f, 1.0f);
  s.frame = Frame(s.n);
  s.material = &m;
  return s;
}

// A material configured as a compiled scene made only of it would be.
inline Material configured(Material m, BsdfSampling sampling, bool force_general = false) {
  m.shading.path = shading_path_for(m.lobes(), force_general);
  m.shading.sampling = sampling;
  return m;
}

// Where the lobes of `c` peak for view wo (the quadrature refines there).
// The quadrature trusts these widths: a cell many widths from a peak may be
// tall enough to step over it, so a width must never exceed the lobe's.
//  - A reflected microfacet lobe (f, and the vndf pdf) of width alpha is
//    squeezed across the plane of incidence by the Jacobian 1 / (4 wo.h):
//    at grazing views it is only ~2 alpha wo.z wide, so the width across
//    shrinks with wo.z (floored at 1e-4 of it).
//  - The cospow pdf is a round lobe about the mirror direction, ~1/sqrt(n)
//    wide both ways. Given the squeezed widths, the quadrature found 0.275
//    of a lobe that is 0.84 above the horizon (n = 1e6, wo.z = 1e-3).
inline std::vector<quadrature::Peak> peaks_of(const disney::Closure& c, const vec3& wo,
                                              std::optional<BsdfSampling> pdf_of = std::nullopt) {
  const vec3 r(-wo.x, -wo.y, wo.z);
  if (pdf_of == BsdfSampling::Cospow) {
    // cos^n vanishes at the lobe's rim, 90 degrees from r, except for n = 0
    // (alpha >= 1), a uniform hemisphere: a jump there.
    const auto peak = [&](float alpha) {
      const float n = cospow::exponent_from_alpha(alpha);
      const double w = 1.0 / std::sqrt(1.0 + n);
      return quadrature::Peak{r, w, w, n < 1.0f};
    };
    return {peak(std::sqrt(c.ax * c.ay)), peak(c.clearcoat_alpha)};
  }
  const double squeeze = std::max(1e-4, static_cast<double>(wo.z));
  const double a = std::min(c.ax, c.ay);
  return {{r, a, squeeze * a}, {r, static_cast<double>(c.clearcoat_alpha), squeeze * c.clearcoat_alpha}};
}

// A sampler and its claimed density.
struct Target {
  std::string name;
  std::function<std::optional<vec3>(float u_lobe, vec2 u)> sample;
  std::function<double(const vec3& wi)> pdf;
  std::vector<quadrature::Peak> peaks;
};

struct Chi2Result {
  double p = 1.0;
  double stat = 0.0;
  int dof = 0;
  std::string message;  // on failure: why, and where the histograms are
};

inline std::filesystem::path histogram_dir() { return std::filesystem::temp_directory_path() / "pathlab-chi2"; }

// Pearson chi-square of `n` samples of `t` against the quadrature of its pdf.
inline Chi2Result chi2_test(const Target& t, std::uint64_t seed, long n, double alpha, int nz = 10, int nphi = 20) {
  const int cells = nz * nphi;
  std::vector<double> observed(cells + 1, 0.0), expected(cells + 1, 0.0);
  Uniform u(seed);
  for (long i = 0; i < n; ++i) {
    const float ul = u.next();
    const auto wi = t.sample(ul, u.next2());
    if (!wi) {
      observed[cells] += 1.0;
      continue;
    }
    const double z = std::clamp(static_cast<double>(wi->z), 0.0, 1.0);
    double phi = std::atan2(static_cast<double>(wi->y), static_cast<double>(wi->x));
    if (phi < 0.0) phi += kTwoPi;
    const int iz = std::min(nz - 1, static_cast<int>(z * nz));
    const int ip = std::min(nphi - 1, static_cast<int>(phi / kTwoPi * nphi));
    observed[iz * nphi + ip] += 1.0;
  }
  const auto density = [&](double z, double phi) { return t.pdf(quadrature::dir_of(z, phi)); };
  // Every cell's quadrature error lands in the lost cell's expectation,
  // 1 - total, so each cell is integrated to a hundredth of a sample. (At a
  // fixed 2e-6 a cell, before the quadrature checked both splits, 2.5e-5 of
  // a cospow lobe seen head-on went uncounted: at 16x the samples the lost
  // cell expected 40 of 1.6M and saw none.)
  const double cell_tol = 0.01 / static_cast<double>(n);
  double total = 0.0;
  for (int iz = 0; iz < nz; ++iz)
    for (int ip = 0; ip < nphi; ++ip) {
      const double mass = quadrature::integrate_cell(density, static_cast<double>(iz) / nz, static_cast<double>(iz + 1) / nz,
                                                     kTwoPi * ip / nphi, kTwoPi * (ip + 1) / nphi, t.peaks, cell_tol);
      expected[iz * nphi + ip] = mass * static_cast<double>(n);
      total += mass;
    }
  // What the density does not cover on the hemisphere is what the sampler
  // loses below it (or a density that integrates above 1: caught here too).
  expected[cells] = std::max(0.0, 1.0 - total) * static_cast<double>(n);

  // Pool cells in increasing expected count to >= 5 each.
  std::vector<int> order(cells + 1);
  for (int i = 0; i <= cells; ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](int a, int b) { return expected[a] < expected[b]; });
  std::vector<std::pair<double, double>> pooled;
  double po = 0.0, pe = 0.0;
  std::ostringstream why;
  for (const int i : order) {
    po += observed[i];
    pe += expected[i];
    if (pe >= 5.0) {
      pooled.emplace_back(po, pe);
      po = pe = 0.0;
    }
  }
  if (pe > 0.0 || po > 0.0) {
    if (pooled.empty()) pooled.emplace_back(po, pe);
    else {
      pooled.back().first += po;
      pooled.back().second += pe;
    }
  }
  Chi2Result r;
  for (const auto& [o, e] : pooled) r.stat += e > 0.0 ? (o - e) * (o - e) / e : (o > 0.0 ? 1e300 : 0.0);
  r.dof = std::max(1, static_cast<int>(pooled.size()) - 1);
  r.p = pooled.size() < 2 ? 1.0 : chi2_sf(r.stat, r.dof);
  if (r.p < alpha) {
    std::filesystem::create_directories(histogram_dir());
    const std::filesystem::path file = histogram_dir() / (t.name + ".tsv");
    std::ofstream out(file);
    out << "# " << t.name << ": chi2(" << r.dof << ") = " << r.stat << ", p = " << r.p << " < " << alpha << "\n"
        << "# gnuplot: plot '" << file.string() << "' using 0:5 with steps title 'observed', '' using 0:6 with steps title 'expected'\n"
        << "# z_lo\tz_hi\tphi_lo\tphi_hi\tobserved\texpected   (last row: samples lost below the surface)\n";
    for (int iz = 0; iz < nz; ++iz)
      for (int ip = 0; ip < nphi; ++ip)
        out << static_cast<double>(iz) / nz << "\t" << static_cast<double>(iz + 1) / nz << "\t" << kTwoPi * ip / nphi << "\t"
            << kTwoPi * (ip + 1) / nphi << "\t" << observed[iz * nphi + ip] << "\t" << expected[iz * nphi + ip] << "\n";
    out << "lost\t-\t-\t-\t" << observed[cells] << "\t" << expected[cells] << "\n";
    why << "chi2(" << r.dof << ") = " << r.stat << ", p = " << r.p << " below the Sidak level " << alpha
        << "; density integrates to " << total << " over the hemisphere; histograms: " << file.string();
    r.message = why.str();
  }
  return r;
}

// The full material through the Surfel, as a tracer sees it.
inline Target material_target(const std::string& name, const Material& m, const vec3& wo) {
  auto mat = std::make_shared<Material>(m);
  return Target{name,
                [mat, wo](float ul, vec2 u) -> std::optional<vec3> {
                  const Surfel s = flat_surfel(*mat);
                  const auto bs = s.scatter(wo, ul, u);
                  if (!bs) return std::nullopt;
                  return bs->wi;
                },
                [mat, wo](const vec3& wi) { return static_cast<double>(flat_surfel(*mat).pdf(wi, wo)); },
                peaks_of(mat->closure, wo, mat->shading.sampling)};
}

// One lobe family alone.
inline Target lobe_target(const std::string& name, const disney::Closure& c, disney::SampledLobe lobe, const vec3& wo,
                          BsdfSampling sampling) {
  return Target{name,
                [c, lobe, wo, sampling](float, vec2 u) { return disney::lobe_sample(c, lobe, wo, u, sampling); },
                [c, lobe, wo, sampling](const vec3& wi) { return static_cast<double>(disney::lobe_pdf(c, lobe, wo, wi, sampling)); },
                peaks_of(c, wo, sampling)};
}

// --- consistency ---------------------------------------------------------------

inline double rel_diff(double a, double b) {
  const double m = std::max(std::abs(a), std::abs(b));
  return m > 0.0 ? std::abs(a - b) / m : 0.0;
}

struct ConsistencyResult {
  long samples = 0;
  long weight_mismatch = 0, pdf_mismatch = 0, reciprocity_mismatch = 0;
  double worst_weight = 0.0, worst_pdf = 0.0, worst_reciprocity = 0.0;
  std::string first_failure;
};

// `n` samples of `m` seen from wo, and `n` random direction pairs for reciprocity.
inline void consistency(const Material& m, const vec3& wo, long n, std::uint64_t seed, ConsistencyResult& r) {
  constexpr double kTol = 1e-4;
  const Surfel s = flat_surfel(m);
  Uniform u(seed);
  for (long i = 0; i < n; ++i) {
    const float ul = u.next();
    const auto bs = s.scatter(wo, ul, u.next2());
    if (!bs || bs->impulse) continue;
    ++r.samples;
    const Spectrum f = s.eval(bs->wi, wo);
    const float pdf = s.pdf(bs->wi, wo);
    for (int c = 0; c < 3; ++c) {
      const double d = rel_diff(bs->weight[c], static_cast<double>(f[c]) / pdf);
      r.worst_weight = std::max(r.worst_weight, d);
      if (d > kTol && ++r.weight_mismatch == 1 && r.first_failure.empty())
        r.first_failure = "weight " + std::to_string(bs->weight[c]) + " vs eval/pdf " + std::to_string(f[c] / pdf);
    }
    const double dp = rel_diff(bs->pdf, pdf);
    r.worst_pdf = std::max(r.worst_pdf, dp);
    if (dp > kTol && ++r.pdf_mismatch == 1 && r.first_failure.empty())
      r.first_failure = "sample pdf " + std::to_string(bs->pdf) + " vs pdf(wi) " + std::to_string(pdf);
    // Reciprocity: f(wi, wo) = f(wo, wi), with f = eval / |cos theta_i|.
    // Directions within 1e-2 of the surface are left out: there f cos is a
    // difference of nearly equal floats and 1e-4 is below its rounding.
    const vec3 a = glm::normalize(vec3(u.next() * 2 - 1, u.next() * 2 - 1, u.next()));
    if (a.z < 1e-2f || wo.z < 1e-2f) continue;
    const Spectrum fa = s.eval(a, wo) / a.z, fb = s.eval(wo, a) / wo.z;
    for (int c = 0; c < 3; ++c) {
      const double d = rel_diff(fa[c], fb[c]);
      r.worst_reciprocity = std::max(r.worst_reciprocity, d);
      if (d > kTol && ++r.reciprocity_mismatch == 1 && r.first_failure.empty())
        r.first_failure = "f(wi, wo) " + std::to_string(fa[c]) + " vs f(wo, wi) " + std::to_string(fb[c]);
    }
  }
}

// --- energy --------------------------------------------------------------------

// Directional albedo of the material seen from wo, per channel, by quadrature.
inline dvec3 albedo_quadrature(const Material& m, const vec3& wo) {
  const Surfel s = flat_surfel(m);
  return quadrature::integrate_directions([&](const vec3& wi) { return dvec3(s.eval(wi, wo)); }, peaks_of(m.closure, wo),
                                          1e-5);
}

// The second moment of a sample's weight, E[w^2] = integral of (f cos)^2 /
// pdf, by quadrature: the standard error of the Monte Carlo albedo without
// trusting the sample. Where most weights are equal and a rare few are not
// (a near-mirror metal: w = F G1(wi) = 1 except for the 1e-4 of samples
// that masking or the horizon takes), 20,000 samples may see none of the
// rare ones and report a standard error of ~0.
inline dvec3 weight_second_moment_quadrature(const Material& m, const vec3& wo) {
  const Surfel s = flat_surfel(m);
  return quadrature::integrate_directions(
      [&](const vec3& wi) {
        const double pdf = s.pdf(wi, wo);
        const dvec3 f(s.eval(wi, wo));
        return pdf > 0.0 ? f * f / pdf : dvec3(0.0);
      },
      peaks_of(m.closure, wo, m.shading.sampling), 1e-5);
}

// ... and by Monte Carlo (mean weight), with its standard error.
inline std::pair<dvec3, dvec3> albedo_monte_carlo(const Material& m, const vec3& wo, long n, std::uint64_t seed) {
  const Surfel s = flat_surfel(m);
  Uniform u(seed);
  dvec3 sum(0.0), sum2(0.0);
  for (long i = 0; i < n; ++i) {
    const float ul = u.next();
    const auto bs = s.scatter(wo, ul, u.next2());
    if (!bs) continue;
    const dvec3 w(bs->weight);
    sum += w;
    sum2 += w * w;
  }
  const double nd = static_cast<double>(n);
  const dvec3 mean = sum / nd;
  return {mean, glm::sqrt(glm::max(dvec3(0.0), sum2 / nd - mean * mean) / nd)};
}

}  // namespace pathlab::test::bsdf
