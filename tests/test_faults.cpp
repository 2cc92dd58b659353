// The checker must catch real bugs: each classic mistake, planted through a
// test-only fault switch (core/faults.h), makes `check` fail on a scene
// where the mistake matters; with no fault the same checks pass.
#include "core/faults.h"
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
};

INSTANTIATE_TEST_SUITE_P(Checker, PlantedFault, testing::ValuesIn(kCases),
                         [](const testing::TestParamInfo<FaultCase>& p) { return std::string(p.param.name); });

}  // namespace
}  // namespace pathlab
