// The BSDF lobes against their published formulas (label "unit"), value by
// value: every expected number below is computed in double from the formula
// as the paper writes it, never from the implementation's helpers.
//
// Sources, written out where they are used:
//  [B12]  B. Burley, "Physically-Based Shading at Disney", SIGGRAPH 2012
//         course notes, sections 5.3-5.6 and appendix B, and its reference
//         implementation disney.brdf (github.com/wdas/brdf, BRDF "disney").
//  [B15]  B. Burley, "Extending the Disney BRDF to a BSDF with Integrated
//         Subsurface Scattering", SIGGRAPH 2015 course notes (section 3:
//         the same diffuse, sheen, specular and clearcoat lobes).
//  [W07]  B. Walter, S. Marschner, H. Li, K. Torrance, "Microfacet Models for
//         Refraction through Rough Surfaces", EGSR 2007 (GGX, eq. 33, and the
//         normalisation integral of D(m) (m.n) = 1, eq. 4).
//  [Sch]  C. Schlick, "An Inexpensive BRDF Model for Physically-based
//         Rendering", 1994: F = F0 + (1 - F0) (1 - cos)^5.
//  [BW]   Born & Wolf, Principles of Optics, 1.5.2: the Fresnel equations of
//         a smooth dielectric, unpolarised reflectance (r_s^2 + r_p^2) / 2.
//
// One deliberate difference from [B12] is pinned here: the tint colour
// Ctint = Cd / lum(Cd) uses Rec. 709 luminance weights (0.2126, 0.7152,
// 0.0722), pathlab's luminance() everywhere, where disney.brdf writes
// .3 R + .6 G + .1 B. kTintLuminance below states it.
#include "core/bsdf/disney.h"
#include "core/bsdf/fresnel.h"
#include "core/bsdf/gtr1.h"
#include "core/bsdf/microfacet.h"
#include "tests/bsdf_checks.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

namespace pathlab {
namespace {

using test::bsdf::configured;
using test::bsdf::flat_surfel;

constexpr double kPiD = 3.14159265358979323846;
constexpr double kTintLuminance[3] = {0.2126, 0.7152, 0.0722};  // see the header comment

double sq(double x) { return x * x; }
double mixd(double a, double b, double t) { return a + (b - a) * t; }
double pow5(double x) { return x * x * x * x * x; }

// A unit direction at polar cosine `c` and azimuth `phi`.
dvec3 dir(double c, double phi) {
  const double s = std::sqrt(std::max(0.0, 1.0 - c * c));
  return {s * std::cos(phi), s * std::sin(phi), c};
}

// --- [B12] disney.brdf, transcribed (BRDF value f, not f cos) ---------------
struct BurleyLobes {
  dvec3 diffuse{0.0};    // (1/pi) mix(Fd, ss, subsurface) Cd (1 - metallic)
  dvec3 sheen{0.0};      // FH sheen Csheen (1 - metallic)
  dvec3 specular{0.0};   // Gs Fs Ds
  double clearcoat = 0;  // .25 clearcoat Gr Fr Dr
  dvec3 total() const { return diffuse + sheen + specular + dvec3(clearcoat); }
};

// smithG_GGX(NdotV, alphaG) = 1 / (NdotV + sqrt(a + b - a b)), a = alphaG^2, b = NdotV^2
double smithG_GGX(double NdotV, double alphaG) {
  const double a = alphaG * alphaG, b = NdotV * NdotV;
  return 1.0 / (NdotV + std::sqrt(a + b - a * b));
}
// smithG_GGX_aniso(NdotV, VdotX, VdotY, ax, ay) = 1 / (NdotV + sqrt((VdotX ax)^2 + (VdotY ay)^2 + NdotV^2))
double smithG_GGX_aniso(double NdotV, double VdotX, double VdotY, double ax, double ay) {
  return 1.0 / (NdotV + std::sqrt(sq(VdotX * ax) + sq(VdotY * ay) + sq(NdotV)));
}
// GTR1(NdotH, a) = (a^2 - 1) / (pi log(a^2) (1 + (a^2 - 1) NdotH^2))   [B12 eq. 4, B.2]
double GTR1(double NdotH, double a) {
  const double a2 = a * a;
  return (a2 - 1.0) / (kPiD * std::log(a2) * (1.0 + (a2 - 1.0) * NdotH * NdotH));
}
// GTR2_aniso(NdotH, HdotX, HdotY, ax, ay) = 1 / (pi ax ay (HdotX^2/ax^2 + HdotY^2/ay^2 + NdotH^2)^2)   [B12 eq. 13]
double GTR2_aniso(double NdotH, double HdotX, double HdotY, double ax, double ay) {
  return 1.0 / (kPiD * ax * ay * sq(sq(HdotX / ax) + sq(HdotY / ay) + NdotH * NdotH));
}
// The anisotropic alphas [B12 5.4 / disney.brdf]: aspect = sqrt(1 - .9 anisotropic),
// ax = max(.001, roughness^2 / aspect), ay = max(.001, roughness^2 aspect);
// X is the tangent, Y the bitangent.
void burley_alphas(double roughness, double anisotropic, double* ax, double* ay) {
  const double aspect = std::sqrt(1.0 - 0.9 * anisotropic);
  *ax = std::max(0.001, sq(roughness) / aspect);
  *ay = std::max(0.001, sq(roughness) * aspect);
}

// L, V in the local frame (X = tangent, Y = bitangent, N = +z).
BurleyLobes burley(const DisneyParams& p, const dvec3& L, const dvec3& V) {
  BurleyLobes out;
  const double NdotL = L.z, NdotV = V.z;
  if (NdotL < 0 || NdotV < 0) return out;
  const dvec3 H = glm::normalize(L + V);
  const double NdotH = H.z, LdotH = glm::dot(L, H);
  const dvec3 Cdlin(p.base_color);
  const double Cdlum = kTintLuminance[0] * Cdlin.x + kTintLuminance[1] * Cdlin.y + kTintLuminance[2] * Cdlin.z;
  const dvec3 Ctint = Cdlum > 0.0 ? Cdlin / Cdlum : dvec3(1.0);
  const dvec3 Cspec0 = glm::mix(p.specular * 0.08 * glm::mix(dvec3(1.0), Ctint, double(p.specular_tint)), Cdlin,
                                double(p.metallic));
  const dvec3 Csheen = glm::mix(dvec3(1.0), Ctint, double(p.sheen_tint));
  // Diffuse fresnel - go from 1 at normal incidence to .5 at grazing,
  // and mix in diffuse retro-reflection based on roughness.
  const double FL = pow5(1.0 - NdotL), FV = pow5(1.0 - NdotV);
  const double Fd90 = 0.5 + 2.0 * LdotH * LdotH * p.roughness;
  const double Fd = mixd(1.0, Fd90, FL) * mixd(1.0, Fd90, FV);
  // Based on Hanrahan-Krueger brdf approximation of isotropic bssrdf.
  const double Fss90 = LdotH * LdotH * p.roughness;
  const double Fss = mixd(1.0, Fss90, FL) * mixd(1.0, Fss90, FV);
  const double ss = 1.25 * (Fss * (1.0 / (NdotL + NdotV) - 0.5) + 0.5);
  // specular
  double ax, ay;
  burley_alphas(p.roughness, p.anisotropic, &ax, &ay);
  const double Ds = GTR2_aniso(NdotH, H.x, H.y, ax, ay);
  const double FH = pow5(1.0 - LdotH);
  const dvec3 Fs = glm::mix(Cspec0, dvec3(1.0), FH);
  const double Gs = smithG_GGX_aniso(NdotL, L.x, L.y, ax, ay) * smithG_GGX_aniso(NdotV, V.x, V.y, ax, ay);
  // sheen
  const dvec3 Fsheen = FH * double(p.sheen) * Csheen;
  // clearcoat (ior = 1.5 -> F0 = 0.04)
  const double Dr = GTR1(NdotH, mixd(0.1, 0.001, p.clearcoat_gloss));
  const double Fr = mixd(0.04, 1.0, FH);
  const double Gr = smithG_GGX(NdotL, 0.25) * smithG_GGX(NdotV, 0.25);
  const double dielectric = 1.0 - p.metallic;
  out.diffuse = (1.0 / kPiD) * mixd(Fd, ss, p.subsurface) * Cdlin * dielectric;
  out.sheen = Fsheen * dielectric;
  out.specular = Gs * Fs * Ds;
  out.clearcoat = 0.25 * p.clearcoat * Gr * Fr * Dr;
  return out;
}

// Relative agreement (absolute below `floor`).
testing::AssertionResult close(double got, double want, double rel, double floor = 1e-6) {
  if (std::abs(got - want) <= rel * std::max(std::abs(want), floor)) return testing::AssertionSuccess();
  return testing::AssertionFailure() << "got " << got << ", the published formula gives " << want << " (relative "
                                     << (got - want) / std::max(std::abs(want), floor) << ")";
}

// The configurations every parameter set is checked at: normal incidence,
// grazing on either side, half-vector aligned (mirror pairs, h = n), retro-
// reflection (wi = wo, h = wo), and off-axis pairs along and across the
// tangent.
struct Config {
  const char* name;
  dvec3 wo, wi;
};
std::vector<Config> configurations() {
  return {
      {"normal incidence (wo = wi = n)", dir(1.0, 0.0), dir(1.0, 0.0)},
      {"grazing view, light at the pole", dir(0.02, 0.3), dir(1.0, 0.0)},
      {"grazing light, view at the pole", dir(1.0, 0.0), dir(0.03, 2.0)},
      {"both grazing, mirror pair (h = n)", dir(0.05, 0.0), dir(0.05, kPiD)},
      {"mirror pair at 60 degrees (h = n)", dir(0.5, 0.4), dir(0.5, 0.4 + kPiD)},
      {"retro-reflection at 80 degrees (h = wo)", dir(0.17, 1.1), dir(0.17, 1.1)},
      {"retro-reflection grazing (h = wo)", dir(0.03, 0.0), dir(0.03, 0.0)},
      {"h tilted along the tangent", dir(0.8, 0.0), dir(0.6, 0.0)},
      {"h tilted along the bitangent", dir(0.8, 0.5 * kPiD), dir(0.6, 0.5 * kPiD)},
      {"off-axis pair", dir(0.7, 0.3), dir(0.4, 2.5)},
  };
}

// Parameter sets: the defaults, then each parameter moved on its own (so a
// wrong term in one parameter cannot hide behind another), then a mixture.
std::vector<std::pair<std::string, DisneyParams>> parameter_sets() {
  std::vector<std::pair<std::string, DisneyParams>> out;
  DisneyParams base;
  base.base_color = Spectrum(0.9f, 0.5f, 0.2f);
  out.emplace_back("defaults", base);
  const auto with = [&](const char* name, auto set) {
    DisneyParams p = base;
    set(p);
    out.emplace_back(name, p);
  };
  with("roughness 0", [](DisneyParams& p) { p.roughness = 0.0f; });
  with("roughness 0.2", [](DisneyParams& p) { p.roughness = 0.2f; });
  with("roughness 1", [](DisneyParams& p) { p.roughness = 1.0f; });
  with("metallic 1", [](DisneyParams& p) { p.metallic = 1.0f; });
  with("metallic 0.4", [](DisneyParams& p) { p.metallic = 0.4f; });
  with("subsurface 1", [](DisneyParams& p) { p.subsurface = 1.0f; });
  with("subsurface 0.5, roughness 0.9", [](DisneyParams& p) { p.subsurface = 0.5f; p.roughness = 0.9f; });
  with("specular 0", [](DisneyParams& p) { p.specular = 0.0f; });
  with("specular 1", [](DisneyParams& p) { p.specular = 1.0f; });
  with("specular_tint 1", [](DisneyParams& p) { p.specular_tint = 1.0f; });
  with("anisotropic 0.8, roughness 0.4", [](DisneyParams& p) { p.anisotropic = 0.8f; p.roughness = 0.4f; });
  with("anisotropic 1, roughness 0.6", [](DisneyParams& p) { p.anisotropic = 1.0f; p.roughness = 0.6f; });
  with("sheen 1, sheen_tint 0", [](DisneyParams& p) { p.sheen = 1.0f; p.sheen_tint = 0.0f; });
  with("sheen 0.7, sheen_tint 1", [](DisneyParams& p) { p.sheen = 0.7f; p.sheen_tint = 1.0f; });
  with("clearcoat 1, gloss 0", [](DisneyParams& p) { p.clearcoat = 1.0f; p.clearcoat_gloss = 0.0f; });
  with("clearcoat 0.6, gloss 0.5", [](DisneyParams& p) { p.clearcoat = 0.6f; p.clearcoat_gloss = 0.5f; });
  with("everything", [](DisneyParams& p) {
    p.metallic = 0.3f;
    p.subsurface = 0.4f;
    p.specular = 0.8f;
    p.specular_tint = 0.6f;
    p.roughness = 0.45f;
    p.anisotropic = 0.5f;
    p.sheen = 0.8f;
    p.sheen_tint = 0.3f;
    p.clearcoat = 0.9f;
    p.clearcoat_gloss = 0.7f;
  });
  return out;
}

// Each lobe (disney::lobe_eval) and the whole material through the Surfel,
// as the tracers call it, against [B12]'s disney.brdf, f cos(theta_i) = f NL.
TEST(BsdfClosedForm, EveryDisneyLobeAndParameterMatchesBurley2012) {
  int checked = 0;
  for (const auto& [pname, p] : parameter_sets()) {
    const disney::Closure c = disney::make_closure(p);
    const Material m = configured(disney_material(p), BsdfSampling::Vndf, true);
    const Surfel s = flat_surfel(m);
    for (const Config& cfg : configurations()) {
      const BurleyLobes want = burley(p, cfg.wi, cfg.wo);
      const double NL = cfg.wi.z;
      const vec3 wo(cfg.wo), wi(cfg.wi);
      const Spectrum diffuse_sheen = disney::lobe_eval(c, disney::SampledLobe::Diffuse, wo, wi);
      const Spectrum spec = disney::lobe_eval(c, disney::SampledLobe::Specular, wo, wi);
      const Spectrum coat = disney::lobe_eval(c, disney::SampledLobe::Clearcoat, wo, wi);
      const Spectrum total = s.eval(wi, wo);
      for (int k = 0; k < 3; ++k) {
        const std::string where = pname + ", " + cfg.name + ", channel " + std::to_string(k);
        EXPECT_TRUE(close(diffuse_sheen[k], (want.diffuse[k] + want.sheen[k]) * NL, 2e-5)) << "diffuse+sheen: " << where;
        EXPECT_TRUE(close(spec[k], want.specular[k] * NL, 5e-5)) << "specular: " << where;
        EXPECT_TRUE(close(coat[k], want.clearcoat * NL, 5e-5)) << "clearcoat: " << where;
        EXPECT_TRUE(close(total[k], want.total()[k] * NL, 5e-5)) << "whole material (Surfel::eval): " << where;
        ++checked;
      }
    }
  }
  std::printf("[ closed   ] %d (parameter set, configuration, channel) values against disney.brdf\n", checked);
}

// The retro-reflection term by hand [B12 5.3]: at h = wo = wi (L.H = 1) and
// both cosines -> 0, FL = FV -> 1 and Fd -> Fd90^2 = (0.5 + 2 roughness)^2:
// a rough surface is 6.25x brighter than Lambert at grazing retro-reflection
// (roughness 1), a smooth one 0.25x (roughness 0). At normal incidence
// Fd = 1 for every roughness: the Lambert value.
TEST(BsdfClosedForm, BurleyDiffuseRetroReflectionByHand) {
  for (const float r : {0.0f, 0.5f, 1.0f}) {
    DisneyParams p;
    p.base_color = Spectrum(1.0f);
    p.roughness = r;
    p.specular = 0.0f;
    const disney::Closure c = disney::make_closure(p);
    const vec3 pole(0, 0, 1);
    const Spectrum at_pole = disney::lobe_eval(c, disney::SampledLobe::Diffuse, pole, pole);
    EXPECT_TRUE(close(at_pole.x, 1.0 / kPiD, 1e-6)) << "roughness " << r << " at normal incidence";
    const double mu = 1e-4;  // grazing retro-reflection
    const vec3 w(dir(mu, 0.0));
    const double f = disney::lobe_eval(c, disney::SampledLobe::Diffuse, w, w).x / w.z;
    const double fd90 = 0.5 + 2.0 * r;
    const double limit = sq(mixd(1.0, fd90, pow5(1.0 - mu))) / kPiD;
    EXPECT_TRUE(close(f, limit, 1e-4)) << "roughness " << r;
    EXPECT_NEAR(f * kPiD, fd90 * fd90, 2e-3 * fd90 * fd90) << "roughness " << r;
  }
}

// Sheen [B12 5.3]: f = sheen Csheen (1 - L.H)^5, no 1/pi; 0 at h = wi, its
// maximum sheen Csheen at L.H = 0. Checked at L.H = cos 60 (wo and wi 120
// degrees apart in the plane): f = sheen Csheen / 32.
TEST(BsdfClosedForm, SheenByHand) {
  DisneyParams p;
  p.base_color = Spectrum(0.0f);  // no diffuse: the Diffuse family is sheen alone
  p.sheen = 1.0f;
  p.sheen_tint = 0.0f;
  const disney::Closure c = disney::make_closure(p);
  // Directions 120 degrees apart: L.H = cos(60) = 0.5, FH = 1/32.
  const vec3 wo(dir(std::cos(kPiD / 3.0), 0.0)), wi(dir(std::cos(kPiD / 3.0), kPiD));
  const double f = disney::lobe_eval(c, disney::SampledLobe::Diffuse, wo, wi).x / wi.z;
  EXPECT_TRUE(close(f, 1.0 / 32.0, 1e-5));
  // h = wi: no sheen at all.
  EXPECT_EQ(disney::lobe_eval(c, disney::SampledLobe::Diffuse, vec3(0, 0, 1), vec3(0, 0, 1)).x, 0.0f);
}

// [W07 eq. 4], [B12 B.2]: the projected area of the microfacets is the
// macro-surface's, integral over the hemisphere of D(h) cos(theta_h) = 1, for
// GTR2 (GGX, isotropic and anisotropic) and GTR1 (the clearcoat). The
// integral in s = 1 - cos^2(theta_h) on a logarithmic grid (both
// distributions are peaks of width alpha^2 in s at s = 0):
//   integral D cos dw = integral_0^2pi dphi integral_0^1 D / 2 ds.
double projected_area(const std::function<double(const dvec3&)>& D, int nphi, int ns) {
  const double lo = std::log(1e-14);
  double total = 0.0;
  for (int j = 0; j < nphi; ++j) {
    const double phi = (j + 0.5) * 2.0 * kPiD / nphi;
    double inner = 0.0;
    for (int i = 0; i < ns; ++i) {  // midpoint in ln s, ds = s d(ln s)
      const double ls = lo + (i + 0.5) * (-lo) / ns;
      const double s = std::exp(ls);
      const double c = std::sqrt(1.0 - s), sn = std::sqrt(s);
      inner += D(dvec3(sn * std::cos(phi), sn * std::sin(phi), c)) * 0.5 * s;
    }
    total += inner * (-lo) / ns;
  }
  // + the part below s = 1e-14, D(n) (1e-14) / 2 per radian
  return total * 2.0 * kPiD / nphi + D(dvec3(0, 0, 1)) * 0.5 * 1e-14 * 2.0 * kPiD;
}

TEST(BsdfClosedForm, Gtr1AndGtr2AreNormalisedAndTakeTheirPublishedValues) {
  for (const float gloss : {0.0f, 0.5f, 1.0f}) {
    const float a = gtr1::alpha_from_gloss(gloss);
    // Float rounding of 0.1 + (0.001 - 0.1) gloss: within 1e-8 absolute.
    EXPECT_NEAR(a, mixd(0.1, 0.001, gloss), 1e-8) << "GTR1 alpha = mix(.1, .001, gloss), gloss " << gloss;
    const double area = projected_area([&](const dvec3& h) { return gtr1::D(vec3(h), a); }, 1, 40000);
    EXPECT_NEAR(area, 1.0, 2e-4) << "GTR1 alpha " << a;
    // (D is 0 for h exactly in the surface, cos 0: a set of measure zero.)
    // Near the peak too: at gloss 1 (a^2 = 1e-6) a half vector 1e-4 rad
    // off the normal has 1 - cos = 5e-9, below the spacing of floats under
    // 1; D must still see its sine.
    for (const double th : {0.0, 1e-4, 3e-4, 1e-3, 0.0141, 0.451, 1.0472, 1.5608}) {
      const vec3 h(static_cast<float>(std::sin(th)), 0.0f, static_cast<float>(std::cos(th)));
      // the formula at the float direction the implementation is given
      const double ch = h.z / glm::length(dvec3(h));
      EXPECT_TRUE(close(gtr1::D(h, a), GTR1(ch, a), 2e-5)) << "GTR1 alpha " << a << " theta_h " << th;
    }
  }
  for (const auto& [ax, ay] : std::vector<std::pair<float, float>>{{0.5f, 0.5f}, {0.05f, 0.05f}, {0.3f, 0.06f}, {0.02f, 0.4f}}) {
    const microfacet::Ggx ggx{ax, ay};
    const double area =
        projected_area([&](const dvec3& h) { return ggx.D(vec3(h)); }, ax == ay ? 1 : 256, ax == ay ? 40000 : 8000);
    EXPECT_NEAR(area, 1.0, 2e-4) << "GGX alphas " << ax << ", " << ay;
    for (const auto& h : {dvec3(0, 0, 1), glm::normalize(dvec3(0.3, 0, 1)), glm::normalize(dvec3(0, 0.3, 1)),
                          glm::normalize(dvec3(0.2, -0.1, 1))})
      EXPECT_TRUE(close(ggx.D(vec3(h)), GTR2_aniso(h.z, h.x, h.y, ax, ay), 2e-5))
          << "GGX alphas " << ax << ", " << ay << " at h " << h.x << "," << h.y << "," << h.z;
  }
}

// The densities of the clearcoat's two samplers seen head-on (wo = n),
// over the hemisphere, by the quadrature the chi-square tests take their
// expected counts from (core/bsdf/quadrature.h):
//  - vndf draws GTR1 half vectors with density D cos [B12 B.2], whose
//    cos^2 = (1 - a^2^(1 - u)) / (1 - a^2); the reflection of wo = n
//    leaves the hemisphere when cos^2 < 1/2, that is with probability
//    ln((1 + a^2) / 2) / ln(a^2) (0.0502 at gloss 1, 0.1484 at gloss 0);
//  - cospow's lobe about the mirror direction n lies wholly above the
//    surface: it integrates to 1.
// The quadrature comes within 1e-7 of both (the densities are floats);
// the bound is 1e-6. Both failed before: a staircase in D at the peak
// (1 - cos taken in float) put the GTR1 lobe 1.8e-4 off, and the
// quadrature trusted cells that only their phi split had checked, losing
// 2.5e-5 of a cospow lobe.
TEST(BsdfClosedForm, ClearcoatDensitiesSeenHeadOnIntegrateToTheirClosedForms) {
  const vec3 wo(0.0f, 0.0f, 1.0f);
  for (const float gloss : {0.0f, 0.5f, 1.0f}) {
    DisneyParams p;
    p.clearcoat = 1.0f;
    p.clearcoat_gloss = gloss;
    const disney::Closure c = disney::make_closure(p);
    const double a2 = static_cast<double>(c.clearcoat_alpha) * c.clearcoat_alpha;
    for (const BsdfSampling s : {BsdfSampling::Vndf, BsdfSampling::Cospow}) {
      const double mass = quadrature::integrate_directions(
          [&](const vec3& wi) {
            return static_cast<double>(disney::lobe_pdf(c, disney::SampledLobe::Clearcoat, wo, wi, s));
          },
          test::bsdf::peaks_of(c, wo, s), 1e-7);
      const double want = s == BsdfSampling::Vndf ? 1.0 - std::log((1.0 + a2) / 2.0) / std::log(a2) : 1.0;
      EXPECT_NEAR(mass, want, 1e-6) << bsdf_sampling_name(s) << ", gloss " << gloss;
    }
  }
}

// [B12 5.4]: aspect = sqrt(1 - 0.9 anisotropic), ax = r^2 / aspect (the
// TANGENT direction, X in disney.brdf), ay = r^2 aspect (the bitangent).
// Checked on the closure and through a Surfel whose tangent is world +y: a
// half vector tilted towards the tangent sees the wide alpha, one tilted
// across it the narrow one.
TEST(BsdfClosedForm, AnisotropyStretchesAlongTheTangentByBurleysAspect) {
  for (const float an : {0.0f, 0.5f, 0.9f, 1.0f})
    for (const float r : {0.01f, 0.3f, 0.8f}) {
      DisneyParams p;
      p.roughness = r;
      p.anisotropic = an;
      const disney::Closure c = disney::make_closure(p);
      double ax, ay;
      burley_alphas(r, an, &ax, &ay);
      EXPECT_TRUE(close(c.ax, ax, 1e-6)) << "alpha x, roughness " << r << " anisotropic " << an;
      EXPECT_TRUE(close(c.ay, ay, 1e-6)) << "alpha y, roughness " << r << " anisotropic " << an;
    }
  DisneyParams p;
  p.roughness = 0.5f;
  p.anisotropic = 0.9f;
  p.base_color = Spectrum(0.0f);
  p.specular = 1.0f;
  const Material m = configured(disney_material(p), BsdfSampling::Vndf);
  Surfel s = flat_surfel(m);
  s.frame = Frame(vec3(0, 0, 1), vec3(0, 1, 0), 1.0f);  // tangent = world +y, bitangent = world -x
  double ax, ay;
  burley_alphas(0.5, 0.9, &ax, &ay);
  ASSERT_GT(ax, 3.0 * ay);
  // wo, wi in the world's y-z plane: h tilts towards the tangent.
  const dvec3 wo_t(0.0, std::sin(0.5), std::cos(0.5)), wi_t(0.0, -std::sin(0.1), std::cos(0.1));
  // The same pair turned 90 degrees (the x-z plane): h tilts across it.
  const dvec3 wo_b(std::sin(0.5), 0.0, std::cos(0.5)), wi_b(-std::sin(0.1), 0.0, std::cos(0.1));
  const auto spec_only = [&](const dvec3& wo_w, const dvec3& wi_w) {
    const dvec3 h = glm::normalize(wo_w + wi_w);
    // Local: X = tangent = world y, Y = bitangent = cross(n, t) = world -x.
    const dvec3 L(wi_w.y, -wi_w.x, wi_w.z), V(wo_w.y, -wo_w.x, wo_w.z), Hl(h.y, -h.x, h.z);
    const double FH = pow5(1.0 - glm::dot(L, Hl));
    const double F0 = 0.08;  // specular 1, no tint, no metal
    return GTR2_aniso(Hl.z, Hl.x, Hl.y, ax, ay) * mixd(F0, 1.0, FH) * smithG_GGX_aniso(L.z, L.x, L.y, ax, ay) *
           smithG_GGX_aniso(V.z, V.x, V.y, ax, ay) * L.z;
  };
  const double along = s.eval(vec3(wi_t), vec3(wo_t)).x, across = s.eval(vec3(wi_b), vec3(wo_b)).x;
  EXPECT_TRUE(close(along, spec_only(wo_t, wi_t), 5e-5)) << "h tilted along the tangent";
  EXPECT_TRUE(close(across, spec_only(wo_b, wi_b), 5e-5)) << "h tilted across the tangent";
  EXPECT_GT(along, 2.0 * across) << "the lobe must be wide along the tangent";
}

// [Sch] and [BW]: Schlick's weight and the exact dielectric reflectance at
// normal incidence ((eta - 1) / (eta + 1))^2, at Brewster's angle
// (tan theta = eta, r_p = 0: F = r_s^2 / 2), at grazing (1), and under total
// internal reflection (1), against the Fresnel equations written out.
double fresnel_exact(double ci, double eta) {
  const double si2 = 1.0 - ci * ci, st2 = si2 / (eta * eta);
  if (st2 >= 1.0) return 1.0;
  const double ct = std::sqrt(1.0 - st2);
  const double rs = (ci - eta * ct) / (ci + eta * ct), rp = (eta * ci - ct) / (eta * ci + ct);
  return 0.5 * (rs * rs + rp * rp);
}

TEST(BsdfClosedForm, FresnelSchlickAndDielectric) {
  for (const double c : {1.0, 0.8, 0.5, 0.1, 0.0}) {
    EXPECT_TRUE(close(fresnel::schlick_weight(float(c)), pow5(1.0 - c), 1e-6, 1e-12)) << c;
    EXPECT_TRUE(close(fresnel::schlick(0.04f, float(c)), 0.04 + 0.96 * pow5(1.0 - c), 1e-6)) << c;
  }
  for (const double eta : {1.33, 1.5, 2.4}) {
    EXPECT_TRUE(close(fresnel::dielectric(1.0f, float(eta)), sq((eta - 1) / (eta + 1)), 1e-5)) << "normal, eta " << eta;
    const double brewster = std::cos(std::atan(eta));
    const double ct = std::sqrt(1.0 - (1.0 - sq(brewster)) / sq(eta));
    const double rs = (brewster - eta * ct) / (brewster + eta * ct);
    EXPECT_TRUE(close(fresnel::dielectric(float(brewster), float(eta)), 0.5 * rs * rs, 1e-4)) << "Brewster, eta " << eta;
    EXPECT_TRUE(close(fresnel::dielectric(0.0f, float(eta)), 1.0, 1e-6)) << "grazing, eta " << eta;
    for (const double c : {0.9, 0.6, 0.3, 0.05})
      EXPECT_TRUE(close(fresnel::dielectric(float(c), float(eta)), fresnel_exact(c, eta), 1e-5)) << c << " " << eta;
    // From inside: eta' = 1 / eta; beyond the critical angle, total reflection.
    const double critical = std::sqrt(1.0 - 1.0 / sq(eta));
    EXPECT_EQ(fresnel::dielectric(float(critical * 0.9), float(1.0 / eta)), 1.0f) << eta;
    EXPECT_TRUE(close(fresnel::dielectric(0.95f, float(1.0 / eta)), fresnel_exact(0.95, 1.0 / eta), 1e-5)) << eta;
  }
}

// The smooth dielectric through the Surfel [BW]: reflection chosen with
// probability F avg(reflectance), weight reflectance F / p_r; refraction with
// (1 - F) avg(transmittance), Snell's law sin_t = sin_i / eta, weight
// transmittance (1 - F) / p_t, from outside and from inside.
TEST(BsdfClosedForm, DielectricImpulses) {
  const DielectricParams glass{1.5f, Spectrum(0.9f, 0.6f, 0.3f), Spectrum(0.2f, 0.8f, 1.0f)};
  const Material m = dielectric_material(glass);
  const Surfel s = flat_surfel(m);
  const double avg_r = (0.9 + 0.6 + 0.3) / 3.0, avg_t = (0.2 + 0.8 + 1.0) / 3.0;
  for (const double c : {1.0, 0.7, 0.2}) {
    for (const double side : {1.0, -1.0}) {
      const dvec3 wo(std::sqrt(1.0 - c * c), 0.0, side * c);
      const double eta = side > 0 ? 1.5 : 1.0 / 1.5;
      const double F = fresnel_exact(c, eta);
      const double p_r = F * avg_r, p_t = (1.0 - F) * avg_t;
      const std::string where = "cos " + std::to_string(c) + (side > 0 ? " outside" : " inside");
      const auto r = s.scatter(vec3(wo), 0.5f * float(p_r), vec2(0.5f));
      ASSERT_TRUE(r) << where;
      EXPECT_EQ(r->lobe, Lobe::DielectricReflection) << where;
      EXPECT_TRUE(r->impulse);
      EXPECT_TRUE(close(r->pdf, p_r, 2e-5)) << "reflection probability, " << where;
      EXPECT_TRUE(close(r->wi.x, -wo.x, 1e-6)) << where;
      EXPECT_TRUE(close(r->wi.z, wo.z, 1e-6)) << where;
      for (int k = 0; k < 3; ++k) EXPECT_TRUE(close(r->weight[k], glass.reflectance[k] * F / p_r, 2e-5)) << where;
      if (F >= 1.0) continue;
      const auto t = s.scatter(vec3(wo), float(p_r + 0.5 * p_t), vec2(0.5f));
      ASSERT_TRUE(t) << where;
      EXPECT_EQ(t->lobe, Lobe::DielectricTransmission) << where;
      EXPECT_TRUE(close(t->pdf, p_t, 2e-5)) << "transmission probability, " << where;
      const double sin_t = std::sqrt(1.0 - c * c) / eta;
      EXPECT_TRUE(close(t->wi.x, -sin_t, 1e-5, 1e-3)) << "Snell, " << where;
      EXPECT_TRUE(close(t->wi.z, -side * std::sqrt(1.0 - sin_t * sin_t), 1e-5)) << "Snell, " << where;
      for (int k = 0; k < 3; ++k)
        EXPECT_TRUE(close(t->weight[k], glass.transmittance[k] * (1.0 - F) / p_t, 2e-5)) << where;
      // Past p_r + p_t: absorbed.
      EXPECT_FALSE(s.scatter(vec3(wo), float(p_r + p_t) + 1e-3f, vec2(0.5f))) << where;
    }
  }
  EXPECT_EQ(s.eval(vec3(0, 0, 1), vec3(0, 0, 1)), Spectrum(0.0f));
  EXPECT_EQ(s.pdf(vec3(0, 0, 1), vec3(0, 0, 1)), 0.0f);
}

// The mirror: wi = reflect(wo) about n, chosen with probability
// min(1, avg(reflectance)), weight reflectance / that; eval and pdf 0.
// Lambert: f cos = albedo cos / pi, pdf cos / pi, weight albedo.
TEST(BsdfClosedForm, MirrorImpulseAndLambert) {
  Material mirror;
  mirror.type = MaterialType::Mirror;
  mirror.albedo = Spectrum(0.9f, 0.5f, 0.1f);
  mirror = configured(mirror, BsdfSampling::Vndf);
  const Surfel sm = flat_surfel(mirror);
  const dvec3 wo = dir(0.3, 0.8);
  const double prob = (0.9 + 0.5 + 0.1) / 3.0;
  const auto r = sm.scatter(vec3(wo), float(prob) - 1e-3f, vec2(0.3f));
  ASSERT_TRUE(r);
  EXPECT_TRUE(r->impulse);
  EXPECT_EQ(r->lobe, Lobe::MirrorImpulse);
  EXPECT_TRUE(close(r->pdf, prob, 1e-6));
  EXPECT_TRUE(close(r->wi.x, -wo.x, 1e-6) && close(r->wi.y, -wo.y, 1e-6) && close(r->wi.z, wo.z, 1e-6));
  for (int k = 0; k < 3; ++k) EXPECT_TRUE(close(r->weight[k], mirror.albedo[k] / prob, 1e-6)) << k;
  EXPECT_FALSE(sm.scatter(vec3(wo), float(prob) + 1e-3f, vec2(0.3f)));
  EXPECT_EQ(sm.eval(vec3(0, 0, 1), vec3(wo)), Spectrum(0.0f));

  for (const bool general : {false, true}) {
    const Material lam = configured(diffuse_material(Spectrum(0.2f, 0.5f, 0.8f)), BsdfSampling::Vndf, general);
    const Surfel s = flat_surfel(lam);
    for (const double c : {1.0, 0.5, 0.01}) {
      const vec3 wi(dir(c, 2.0));
      const Spectrum f = s.eval(wi, vec3(wo));
      for (int k = 0; k < 3; ++k) EXPECT_TRUE(close(f[k], lam.albedo[k] * c / kPiD, 1e-5)) << c << (general ? " general" : "");
      EXPECT_TRUE(close(s.pdf(wi, vec3(wo)), c / kPiD, 1e-5)) << c;
      // Below the surface: nothing.
      EXPECT_EQ(s.eval(vec3(wi.x, wi.y, -wi.z), vec3(wo)), Spectrum(0.0f));
    }
  }
}

}  // namespace
}  // namespace pathlab
