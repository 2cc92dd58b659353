// The checker must catch real bugs: each classic mistake, planted through a
// test-only fault switch (core/faults.h), makes `check` fail on a scene
// where the mistake matters; with no fault the same checks pass.
#include "core/faults.h"
#include "tests/bsdf_checks.h"
#include "tests/bsdf_extremes.h"
#include "tests/check_util.h"
#include "tests/temp_dir.h"

#include <gtest/gtest.h>

namespace pathlab {
namespace {

struct FaultCase {
  Fault fault;
  const char* name;
  const char* scene;
  Strategy strategy;
};

class PlantedFault : public testing::TestWithParam<FaultCase> {
 protected:
  void TearDown() override { g_fault = Fault::None; }
};

TEST_P(PlantedFault, IsCaughtByCheck) {
  const FaultCase c = GetParam();
  g_fault = Fault::None;
  EXPECT_TRUE(test::run_check(c.scene, c.strategy).pass) << "the unfaulted control must pass";
  g_fault = c.fault;
  const test::ScopedTempDir folder(std::string("fault-") + c.name);
  const std::filesystem::path dir = folder.path() / "out";
  const CheckResult r = test::run_check(test::load_with_strategy(c.scene, c.strategy), dir);
  EXPECT_FALSE(r.pass) << c.name << " went unnoticed: worst z " << r.worst.front().z << ", bias z " << r.bias_z;
  // A failed check leaves the four images a person needs to see why.
  for (const char* f : {"rendered.exr", "expected.exr", "error.exr", "zscore.exr"})
    EXPECT_TRUE(std::filesystem::exists(dir / f)) << f;
}

// Each fault on a scene and strategy that exercise the broken code.
const FaultCase kCases[] = {
    {Fault::BsdfPdfOff5Percent, "bsdf_pdf_off_5_percent_bsdf", "furnace-sphere.json", Strategy::Bsdf},
    {Fault::BsdfPdfOff5Percent, "bsdf_pdf_off_5_percent_mis", "white-sphere-emissive-room.json", Strategy::Mis},
    {Fault::CosineDropped, "cosine_dropped_light", "white-sphere-emissive-room.json", Strategy::Light},
    {Fault::CosineDropped, "cosine_dropped_bsdf", "sphere-in-environment.json", Strategy::Bsdf},
    {Fault::EmissionAfterNee, "emission_after_nee_light", "furnace-sphere.json", Strategy::Light},
    {Fault::EmissionAfterNee, "emission_after_nee_mis", "white-sphere-emissive-room.json", Strategy::Mis},
    {Fault::LightPdfWithoutArea, "light_pdf_without_area_light", "furnace-sphere.json", Strategy::Light},
    {Fault::LightPdfWithoutArea, "light_pdf_without_area_mis", "white-sphere-emissive-room.json", Strategy::Mis},
    {Fault::LightPdfWithoutDistance, "light_pdf_without_distance_light", "white-sphere-emissive-room.json", Strategy::Light},
    {Fault::LightPdfWithoutDistance, "light_pdf_without_distance_mis", "furnace-box.json", Strategy::Mis},
    {Fault::LightPdfWithoutDistance, "light_pdf_without_distance_penumbra", "penumbra-box.json", Strategy::Light},
    {Fault::CosineDropped, "cosine_dropped_penumbra", "penumbra-box.json", Strategy::Mis},
    {Fault::EmissionAfterNee, "emission_after_nee_penumbra", "penumbra-box.json", Strategy::LightBsdf},
    {Fault::RouletteNotReweighted, "roulette_not_reweighted_cosine", "furnace-box.json", Strategy::Cosine},
    {Fault::RouletteNotReweighted, "roulette_not_reweighted_mis", "mirror-sphere-gray-room.json", Strategy::Mis},
    {Fault::DielectricFresnelIgnored, "dielectric_fresnel_ignored_mis", "glass-sphere-tinted.json", Strategy::Mis},
    {Fault::AlphaKeysNotSet, "alpha_keys_not_set_mis", "penumbra-alpha.json", Strategy::Mis},
};

INSTANTIATE_TEST_SUITE_P(Checker, PlantedFault, testing::ValuesIn(kCases),
                         [](const testing::TestParamInfo<FaultCase>& p) { return std::string(p.param.name); });

// --- the BSDF checks against planted BSDF errors ----------------------------------

class PlantedBsdfFault : public testing::Test {
 protected:
  void TearDown() override { g_fault = Fault::None; }
};

// A few grid points where the specular lobe matters, chi-square tested;
// returns the smallest p-value.
double worst_chi2_p(BsdfSampling sampling) {
  double worst = 1.0;
  int i = 0;
  for (const float r : {0.1f, 0.5f})
    for (const float v : {1.0f, 0.5f}) {
      DisneyParams p;
      p.roughness = r;
      p.metallic = 1.0f;
      const Material m = test::bsdf::configured(disney_material(p), sampling);
      const auto t = test::bsdf::material_target("fault_probe_" + std::to_string(i), m, test::bsdf::view_dir(v));
      worst = std::min(worst, test::bsdf::chi2_test(t, 7 + i++, 100000, 1e-3).p);
    }
  return worst;
}

TEST_F(PlantedBsdfFault, Chi2CatchesSpecularPdfOff5Percent) {
  g_fault = Fault::None;
  EXPECT_GT(worst_chi2_p(BsdfSampling::Vndf), 1e-3 / 4) << "the unfaulted control must pass";
  g_fault = Fault::SpecularPdfOff5Percent;
  const double p = worst_chi2_p(BsdfSampling::Vndf);
  std::printf("[ fault    ] specular pdf x 1.05: worst chi-square p %.3g\n", p);
  EXPECT_LT(p, 1e-3 / 4);
}

TEST_F(PlantedBsdfFault, Chi2CatchesVndfPdfWithoutJacobian) {
  g_fault = Fault::VndfPdfWithoutJacobian;
  const double p = worst_chi2_p(BsdfSampling::Vndf);
  std::printf("[ fault    ] VNDF pdf without 1/(4 wo.h): worst chi-square p %.3g\n", p);
  EXPECT_LT(p, 1e-3 / 4);
}

TEST_F(PlantedBsdfFault, ConsistencyCatchesSmithG1Dropped) {
  DisneyParams p;
  p.roughness = 0.5f;
  p.metallic = 1.0f;
  const Material m = test::bsdf::configured(disney_material(p), BsdfSampling::Vndf);
  test::bsdf::ConsistencyResult control, faulty;
  test::bsdf::consistency(m, test::bsdf::view_dir(0.5f), 2000, 3, control);
  EXPECT_EQ(control.reciprocity_mismatch, 0) << control.first_failure;
  g_fault = Fault::SmithG1Dropped;
  test::bsdf::consistency(m, test::bsdf::view_dir(0.5f), 2000, 3, faulty);
  std::printf("[ fault    ] G1(wi) dropped: %ld channel mismatches in reciprocity over %ld samples (worst relative %.3g)\n", faulty.reciprocity_mismatch,
              faulty.samples, faulty.worst_reciprocity);
  EXPECT_GT(faulty.reciprocity_mismatch, 0);
}

// The energy check (albedo by quadrature <= 1 for a GGX metal) against a
// specular f that lost its 1 / (4 cos_i cos_o).
TEST_F(PlantedBsdfFault, EnergyCatchesSpecularWithoutDenominator) {
  DisneyParams p;
  p.roughness = 0.5f;
  p.metallic = 1.0f;
  p.base_color = Spectrum(1.0f);
  const Material m = test::bsdf::configured(disney_material(p), BsdfSampling::Vndf);
  const double control = test::bsdf::albedo_quadrature(m, test::bsdf::view_dir(1.0f)).x;
  EXPECT_LE(control, 1.0 + 1e-4);
  g_fault = Fault::SpecularNoDenominator;
  const double faulty = test::bsdf::albedo_quadrature(m, test::bsdf::view_dir(1.0f)).x;
  std::printf("[ fault    ] specular without 1/(4 cos cos): albedo of a white metal at normal view %.4f (control %.4f)\n",
              faulty, control);
  EXPECT_GT(faulty, 1.0 + 1e-4);
}

// The energy check with compensation on (albedo <= 1 for every
// configuration) against a coupling that forgets one of its layers: the
// control passes, the fault pushes a white material above 1 at view cos 0.1.
void expect_energy_check_catches(Fault fault, float metallic, float clearcoat, const char* what) {
  const auto albedo = [&] {
    DisneyParams p;
    p.base_color = Spectrum(1.0f);
    p.metallic = metallic;
    p.clearcoat = clearcoat;
    p.roughness = 0.1f;
    p.energy_compensation = true;
    const Material m = test::bsdf::configured(disney_material(p), BsdfSampling::Vndf);
    const dvec3 a = test::bsdf::albedo_quadrature(m, test::bsdf::view_dir(0.1f));
    return std::max(a.x, std::max(a.y, a.z));
  };
  const double control = albedo();
  EXPECT_LE(control, 1.0 + 1e-4);
  g_fault = fault;
  const double faulty = albedo();
  std::printf("[ fault    ] %s: albedo at view cos 0.1 %.4f (control %.4f)\n", what, faulty, control);
  EXPECT_GT(faulty, 1.0 + 1e-4);
}

TEST_F(PlantedBsdfFault, EnergyCatchesCoatNotCoupled) {
  expect_energy_check_catches(Fault::CoatNotCoupled, 1.0f, 1.0f, "clearcoat not coupled, coated white metal");
}

TEST_F(PlantedBsdfFault, EnergyCatchesDiffuseNotCoupled) {
  expect_energy_check_catches(Fault::DiffuseNotCoupled, 0.0f, 0.0f, "diffuse not coupled, white dielectric");
}

TEST_F(PlantedBsdfFault, ExtremesCatchHorizonUnclamped) {
  g_fault = Fault::HorizonUnclamped;
  const test::bsdf::ExtremesResult r = test::bsdf::run_extremes(200000, 5);
  std::printf("[ fault    ] horizon unclamped: %ld draws, %ld NaN, %ld Inf, %ld negative\n", r.draws, r.nan, r.inf, r.negative);
  EXPECT_GT(r.nan + r.inf + r.negative, 0);
}

}  // namespace
}  // namespace pathlab
