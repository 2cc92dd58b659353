// The BSDFs, fast checks (label "unit"): per-sample consistency of weight,
// pdf and eval, reciprocity, the general path against the specialised one,
// the dielectric's impulses, and the firefly controls' plumbing.
#include "core/compiled_scene.h"
#include "core/render.h"
#include "core/scene_loader.h"
#include "reference/reference_tracer.h"
#include "tests/bsdf_checks.h"

#include <gtest/gtest.h>

#include <limits>

namespace pathlab {
namespace {

using namespace test::bsdf;

std::vector<Material> materials_over_the_grid(BsdfSampling sampling) {
  std::vector<Material> out;
  const auto add = [&](float r, float a, float m, float c, bool compensated) {
    DisneyParams p;
    p.base_color = Spectrum(0.9f, 0.6f, 0.3f);
    p.subsurface = 0.3f;
    p.sheen = 0.5f;
    p.specular_tint = 0.2f;
    p.roughness = r;
    p.anisotropic = a;
    p.metallic = m;
    p.clearcoat = c;
    p.energy_compensation = compensated;
    out.push_back(configured(disney_material(p), sampling));
  };
  for (const float r : {0.001f, 0.01f, 0.1f, 0.5f, 1.0f})
    for (const float a : {0.0f, 0.5f, 0.9f})
      for (const float m : {0.0f, 1.0f})
        for (const float c : {0.0f, 1.0f}) add(r, a, m, c, false);
  // Energy compensation changes eval and the lobe choice: a sub-grid.
  for (const float r : {0.01f, 0.5f, 1.0f})
    for (const float a : {0.0f, 0.9f})
      for (const float m : {0.0f, 1.0f})
        for (const float c : {0.0f, 1.0f}) add(r, a, m, c, true);
  out.push_back(configured(diffuse_material(Spectrum(0.2f, 0.5f, 0.8f)), sampling));
  return out;
}

// The energy tables hold upper bounds of each layer's albedo (what makes
// albedo <= 1 hold with compensation), finite and in [0, 1] at the ends of
// every parameter's range; lookups are safe for any cosine.
TEST(EnergyTables, BoundTheLayersAlbedoAtEveryView) {
  double tightest = 1.0;  // smallest table - albedo seen
  int checked = 0;
  for (const float r : {0.0f, 1e-7f, 0.05f, 0.3f, 1.0f})
    for (const float a : {0.0f, 0.999f}) {
      DisneyParams p;
      p.base_color = Spectrum(1.0f, 0.5f, 0.0f);
      p.metallic = 0.5f;
      p.specular = 1.0f;
      p.roughness = r;
      p.anisotropic = a;
      p.clearcoat = 1.0f;
      p.clearcoat_gloss = 1.0f - r;
      const disney::Closure c = disney::make_closure(p);
      const disney::EnergyTables t = disney::make_energy_tables(c);
      ASSERT_TRUE(t.on);
      for (int i = 0; i < disney::kEnergyTableSize; ++i) {
        for (int k = 0; k < 3; ++k) EXPECT_TRUE(t.specular[i][k] >= 0.0f && t.specular[i][k] <= 1.0f) << i;
        EXPECT_TRUE(t.coat[i] >= 0.0f && t.coat[i] <= 1.0f) << i;
      }
      for (int k = 0; k < 3; ++k) EXPECT_TRUE(t.diffuse_scale[k] > 0.0f && t.diffuse_scale[k] <= 1.0f);
      for (const float mu : {0.0f, 1e-40f, -1.0f, 2.0f, std::numeric_limits<float>::quiet_NaN()}) {
        const Spectrum ts = t.specular_transmit(mu);
        EXPECT_TRUE(ts.x >= 0.0f && ts.x <= 1.0f && t.coat_transmit(mu) >= 0.0f && t.coat_transmit(mu) <= 1.0f) << mu;
      }
      // Between the entries, at an azimuth the tables did not measure.
      disney::Closure bare = c;
      bare.energy = disney::EnergyTables{};
      for (const float mu : {3e-4f, 2e-3f, 0.013f, 0.07f, 0.2f, 0.45f, 0.83f}) {
        const float s = std::sqrt(1.0f - mu * mu);
        const vec3 wo(s * std::cos(0.3f), s * std::sin(0.3f), mu);
        for (const auto lobe : {disney::SampledLobe::Specular, disney::SampledLobe::Clearcoat}) {
          const dvec3 albedo = quadrature::integrate_directions(
              [&](const vec3& wi) { return dvec3(disney::lobe_eval(bare, lobe, wo, wi)); }, peaks_of(bare, wo), 1e-6);
          const Spectrum bound = lobe == disney::SampledLobe::Specular ? Spectrum(1.0f) - t.specular_transmit(mu)
                                                                        : Spectrum(1.0f - t.coat_transmit(mu));
          for (int k = 0; k < 3; ++k) {
            EXPECT_GE(bound[k], albedo[k] - 1e-5) << "roughness " << r << " anisotropic " << a << " view cos " << mu
                                                   << " lobe " << static_cast<int>(lobe) << " channel " << k;
            tightest = std::min(tightest, static_cast<double>(bound[k]) - albedo[k]);
          }
          ++checked;
        }
      }
    }
  std::printf("[ energy   ] %d table lookups bound their lobe's albedo by quadrature; tightest margin %.2g\n", checked,
              tightest);
}

TEST(BsdfConsistency, WeightIsEvalOverPdfAndPdfMatchesEverySample) {
  ConsistencyResult r;
  for (const BsdfSampling s : {BsdfSampling::Vndf, BsdfSampling::Cospow})
    for (const Material& m : materials_over_the_grid(s))
      for (const float v : {1.0f, 0.5f, 0.1f, 0.001f}) consistency(m, view_dir(v), 500, 11, r);
  std::printf("[ consist  ] %ld samples: worst weight %.2g, pdf %.2g, reciprocity %.2g (relative)\n", r.samples,
              r.worst_weight, r.worst_pdf, r.worst_reciprocity);
  EXPECT_GT(r.samples, 100000);
  EXPECT_EQ(r.weight_mismatch, 0) << r.first_failure;
  EXPECT_EQ(r.pdf_mismatch, 0) << r.first_failure;
  EXPECT_EQ(r.reciprocity_mismatch, 0) << r.first_failure;
}

// A Lambert material through the general (Disney-capable) path gives the
// Lambert path's answer: the same directions, and eval, pdf and weight equal
// to float rounding.
TEST(BsdfSpecialisation, GeneralPathEqualsLambertPath) {
  const Material lam = configured(diffuse_material(Spectrum(0.2f, 0.5f, 0.8f)), BsdfSampling::Vndf);
  const Material gen = configured(diffuse_material(Spectrum(0.2f, 0.5f, 0.8f)), BsdfSampling::Vndf, true);
  ASSERT_EQ(lam.shading.path, ShadingPath::LambertOnly);
  ASSERT_EQ(gen.shading.path, ShadingPath::General);
  const Surfel a = flat_surfel(lam), b = flat_surfel(gen);
  Uniform u(3);
  for (int i = 0; i < 10000; ++i) {
    const vec3 wo = view_dir(u.next());
    const float ul = u.next();
    const vec2 uu = u.next2();
    const auto sa = a.scatter(wo, ul, uu), sb = b.scatter(wo, ul, uu);
    ASSERT_EQ(sa.has_value(), sb.has_value());
    if (!sa) continue;
    EXPECT_EQ(sa->wi, sb->wi);
    EXPECT_EQ(sa->lobe, sb->lobe);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(sa->weight[c], sb->weight[c], 1e-6f * sa->weight[c]);
    EXPECT_NEAR(a.pdf(sa->wi, wo), b.pdf(sa->wi, wo), 1e-6f * a.pdf(sa->wi, wo));
    const Spectrum fa = a.eval(sa->wi, wo), fb = b.eval(sa->wi, wo);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(fa[c], fb[c]);
  }
}

// The Disney paths with and without GTR1 agree for a material without clearcoat.
TEST(BsdfSpecialisation, ClearcoatFreePathEqualsFullPath) {
  DisneyParams p;
  p.roughness = 0.3f;
  p.sheen = 0.4f;
  Material m1 = configured(disney_material(p), BsdfSampling::Vndf);
  Material m2 = m1;
  m2.shading.path = ShadingPath::DisneyClearcoat;
  ASSERT_EQ(m1.shading.path, ShadingPath::Disney);
  const Surfel a = flat_surfel(m1), b = flat_surfel(m2);
  Uniform u(4);
  for (int i = 0; i < 10000; ++i) {
    const vec3 wo = view_dir(u.next()), wi = view_dir(u.next());
    EXPECT_EQ(a.eval(wi, wo), b.eval(wi, wo));
    EXPECT_EQ(a.pdf(wi, wo), b.pdf(wi, wo));
  }
}

TEST(Dielectric, EntersAndLeavesByTheGeometricNormal) {
  const Material glass = dielectric_material({1.5f, Spectrum(1.0f), Spectrum(1.0f)});
  const Surfel s = flat_surfel(glass);
  const vec3 wo = view_dir(0.6f);  // outside
  // u_lobe just above F: refraction into the inside (-z), bent towards the normal.
  const auto t = s.scatter(wo, 0.99f, vec2(0.5f));
  ASSERT_TRUE(t);
  EXPECT_TRUE(t->impulse);
  EXPECT_EQ(t->lobe, Lobe::DielectricTransmission);
  EXPECT_LT(t->wi.z, 0.0f);
  const float sin_o = std::sqrt(1.0f - 0.36f), sin_t = std::sqrt(1.0f - t->wi.z * t->wi.z);
  EXPECT_NEAR(sin_t, sin_o / 1.5f, 1e-5f);
  EXPECT_EQ(t->weight, Spectrum(1.0f));
  // Reflection with probability F.
  const auto r = s.scatter(wo, 0.0f, vec2(0.5f));
  ASSERT_TRUE(r);
  EXPECT_EQ(r->lobe, Lobe::DielectricReflection);
  EXPECT_NEAR(r->wi.z, 0.6f, 1e-6f);
  // From inside beyond the critical angle: total internal reflection, always.
  const vec3 inside(std::sqrt(1.0f - 0.3f * 0.3f), 0.0f, -0.3f);  // sin 0.95 > 1/1.5
  for (const float ul : {0.0f, 0.5f, 0.999f}) {
    const auto tir = s.scatter(inside, ul, vec2(0.5f));
    ASSERT_TRUE(tir);
    EXPECT_EQ(tir->lobe, Lobe::DielectricReflection);
    EXPECT_NEAR(tir->wi.z, -0.3f, 1e-6f);
  }
}

TEST(FireflyControls, ClampCountsAndRemovesEnergy) {
  Scene scene = builtin_cornell_box();
  scene.film.width = scene.film.height = 16;
  scene.render.spp = 4;
  scene.render.clamp = 0.05f;
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  const ReferenceTracer tracer(compiled, settings);
  Film film(16, 16, compiled.scene().film.filter);
  const RenderStats stats = render(tracer, film);
  EXPECT_GT(stats.clamped_samples, 0u);
  EXPECT_GT(stats.energy_clamped.value(), 0.0);
  EXPECT_LT(stats.energy_clamped.value(), stats.energy_total.value());
}

TEST(FireflyControls, MinPdfDiscardsSamplesBelowIt) {
  Material m = configured(diffuse_material(Spectrum(0.5f)), BsdfSampling::Vndf);
  m.shading.min_pdf = 0.2f;  // cos / pi < 0.2 below cos 0.63
  const Surfel s = flat_surfel(m);
  Uniform u(9);
  for (int i = 0; i < 1000; ++i) {
    const auto bs = s.scatter(view_dir(0.5f), u.next(), u.next2());
    if (bs) {
      EXPECT_GE(bs->pdf, 0.2f);
    }
  }
}

}  // namespace
}  // namespace pathlab
