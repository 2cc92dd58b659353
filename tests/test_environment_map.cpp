// Environment images (core/environment_map.h): the lat-long convention
// against known directions, the importance sampler against its pdf
// (chi-square, tests/envmap_checks.h), the pdf's integral, black regions,
// the scene keys, and the light sampler's use of the map.
#include "tests/envmap_checks.h"
#include "tests/temp_dir.h"

#include "core/compiled_scene.h"
#include "core/error.h"
#include "core/scene_loader.h"

#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include <string>

namespace pathlab {
namespace {

Image filled(int w, int h, Spectrum value) {
  Image image(w, h);
  for (vec3& t : image.pixels) t = value;
  return image;
}

// Every texel distinct: texel (x, y) holds (x, y, 1).
Image numbered(int w, int h) {
  Image image(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) image.at(x, y) = Spectrum(float(x), float(y), 1.0f);
  return image;
}

// A 6 x 3 map puts the horizon's axis directions at texel centres: +x is
// column 1.5 / 6 = 0.25 of the way, +z the middle, -x three quarters; the
// middle row is the horizon, row 0 the top (+y). -z is the seam between the
// last column and column 0.
TEST(EnvironmentMap, OrientationAtKnownDirections) {
  const EnvironmentMap map(numbered(6, 3), mat3(1.0f), "numbered");
  EXPECT_EQ(map.radiance(vec3(1, 0, 0)), Spectrum(1, 1, 1));   // +x
  EXPECT_EQ(map.radiance(vec3(0, 0, 1)), Spectrum(3, 1, 1));   // +z
  EXPECT_EQ(map.radiance(vec3(-1, 0, 0)), Spectrum(4, 1, 1));  // -x
  EXPECT_EQ(map.radiance(glm::normalize(vec3(0.01f, 0, -1))), Spectrum(0, 1, 1));  // just right of -z
  EXPECT_EQ(map.radiance(glm::normalize(vec3(-0.01f, 0, -1))), Spectrum(5, 1, 1));  // just left of it
  EXPECT_EQ(map.radiance(vec3(0, 1, 0)).y, 0.0f);   // up: the top row
  EXPECT_EQ(map.radiance(vec3(0, -1, 0)).y, 2.0f);  // down: the bottom row
  EXPECT_EQ(map.radiance(glm::normalize(vec3(1, 1.5f, 0))), Spectrum(1, 0, 1));  // 34 degrees from +y: row 0
}

// The centre of every texel of a larger map (by the convention's formula,
// written out in envmap_checks.h) looks up that texel, and one marked texel
// lights exactly the directions of its cell.
TEST(EnvironmentMap, TexelCentresLookUpTheirTexel) {
  const EnvironmentMap map(numbered(32, 16), mat3(1.0f), "numbered");
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 32; ++x) {
      const vec3 d(test::latlong_direction(glm::dvec2((x + 0.5) / 32.0, (y + 0.5) / 16.0)));
      ASSERT_EQ(map.radiance(d), Spectrum(float(x), float(y), 1.0f)) << x << ", " << y;
    }
  Image marked = filled(32, 16, Spectrum(0.0f));
  marked.at(9, 4) = Spectrum(5.0f);
  const EnvironmentMap one(marked, mat3(1.0f), "marked");
  // Texel (9, 4): phi in [2 pi 9/32, 2 pi 10/32), theta in [pi 4/16, pi 5/16).
  const double phi = 2.0 * M_PI * 9.5 / 32.0, theta = M_PI * 4.5 / 16.0;
  const vec3 centre(float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)), float(-std::sin(theta) * std::cos(phi)));
  EXPECT_EQ(one.radiance(centre), Spectrum(5.0f));
  EXPECT_GT(one.pdf(centre), 0.0f);
  EXPECT_EQ(one.radiance(vec3(0, 0, 1)), Spectrum(0.0f));
  EXPECT_EQ(one.pdf(vec3(0, 0, 1)), 0.0f);
}

// A rotation of the map: the world direction of local d is to_world d.
TEST(EnvironmentMap, RotationTurnsTheMap) {
  const mat3 turn(glm::rotate(mat4(1.0f), glm::radians(90.0f), vec3(0, 1, 0)));  // +x -> -z
  const EnvironmentMap map(numbered(6, 3), turn, "numbered");
  EXPECT_EQ(map.radiance(glm::normalize(turn * vec3(1, 0, 0))), Spectrum(1, 1, 1));
  EXPECT_EQ(map.radiance(vec3(0, 0, -1)), Spectrum(1, 1, 1));
  EXPECT_TRUE(test::sampler_matches_pdf(map, 12, 6, 50000, 0.01));
}

// Structured: every texel a different brightness, with a bright one.
Image structured(int w, int h) {
  Image image(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) image.at(x, y) = Spectrum(0.1f + float((x * 7 + y * 3) % 11), 0.5f, float(y));
  image.at(3, 1) = Spectrum(400.0f);
  return image;
}

// Bins finer than the texels (3 x 3 per texel) check the placement within a
// texel too; coarser bins straddling texels, the mass of each.
TEST(EnvironmentMap, SamplerMatchesPdfOnAStructuredMap) {
  const EnvironmentMap map(structured(16, 8), mat3(1.0f), "structured");
  EXPECT_TRUE(test::sampler_matches_pdf(map, 48, 24, 200000, 0.01));
  EXPECT_TRUE(test::sampler_matches_pdf(map, 5, 3, 50000, 0.01, 2));
  // The sampler agreeing with its own pdf says nothing of what the pdf
  // follows: a texel's probability is its luminance times sin theta at its
  // centre (over the sum of those), and the map's (u, v) -> direction
  // density is 1 / (2 pi^2 sin theta), so at every texel centre the density
  // in solid angle is the luminance times one constant. To within the
  // float cdfs the distribution keeps: a cell's probability p is a product
  // of two differences of floats in [0, 1], each good to 2^-24, so about
  // 2 * 2^-24 / p relatively (doubled here for the rest of the rounding).
  double ratio = 0.0;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 16; ++x) {
      const glm::dvec2 uv((x + 0.5) / 16.0, (y + 0.5) / 8.0);
      const vec3 d(test::latlong_direction(uv));
      const double pdf = map.pdf(d);
      const double r = pdf / luminance(map.radiance(d));
      if (ratio == 0.0) ratio = r;
      const double p_cell = pdf * 2.0 * kPi * kPi * std::sin(kPi * uv.y) / (16.0 * 8.0);
      EXPECT_NEAR(r, ratio, (4.0 * std::ldexp(1.0, -24) / p_cell + 1e-6) * ratio) << "texel " << x << ", " << y;
    }
}

// One bright texel among dim ones: nearly every draw lands in it, the rest
// in proportion.
TEST(EnvironmentMap, SamplerMatchesPdfWithASingleBrightTexel) {
  Image image = filled(16, 8, Spectrum(0.01f));
  image.at(11, 5) = Spectrum(3e4f, 2e4f, 1e4f);
  const EnvironmentMap map(image, mat3(1.0f), "sun");
  EXPECT_TRUE(test::sampler_matches_pdf(map, 64, 32, 200000, 0.01));
}

// The lower hemisphere black: no direction sampled there, density 0 there.
TEST(EnvironmentMap, BlackHemisphereIsNeverSampled) {
  Image image = structured(16, 8);
  for (int y = 4; y < 8; ++y)
    for (int x = 0; x < 16; ++x) image.at(x, y) = Spectrum(0.0f);
  const EnvironmentMap map(image, mat3(1.0f), "half");
  EXPECT_TRUE(test::sampler_matches_pdf(map, 32, 16, 100000, 0.01));
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  for (int k = 0; k < 100000; ++k) {
    const auto s = map.sample(vec2(uniform(rng), uniform(rng)));
    ASSERT_TRUE(s);
    ASSERT_GE(s->wi.y, 0.0f) << k;
    ASSERT_FALSE(is_black(s->radiance)) << k;
  }
  for (const vec3& d : {vec3(0, -1, 0), glm::normalize(vec3(1, -0.2f, 0.3f)), glm::normalize(vec3(-0.4f, -0.9f, -0.1f))})
    EXPECT_EQ(map.pdf(d), 0.0f);
}

// A black map is no light: no sample, density 0 everywhere.
TEST(EnvironmentMap, BlackMapIsNoLight) {
  const EnvironmentMap map(filled(8, 4, Spectrum(0.0f)), mat3(1.0f), "black");
  EXPECT_TRUE(map.is_black());
  EXPECT_EQ(map.luminance_integral(), 0.0);
  EXPECT_FALSE(map.sample(vec2(0.3f, 0.6f)));
  EXPECT_EQ(map.pdf(vec3(0, 0, 1)), 0.0f);
}

// The poles: density 0 exactly there, and finite next to them.
TEST(EnvironmentMap, PolesHaveNoDensity) {
  const EnvironmentMap map(filled(8, 4, Spectrum(1.0f)), mat3(1.0f), "flat");
  EXPECT_EQ(map.pdf(vec3(0, 1, 0)), 0.0f);
  EXPECT_EQ(map.pdf(vec3(0, -1, 0)), 0.0f);
  const float near_pole = map.pdf(glm::normalize(vec3(1e-3f, 1, 0)));
  EXPECT_TRUE(std::isfinite(near_pole) && near_pole > 0.0f);
  // The luminance integral of a constant map is 4 pi Y.
  EXPECT_NEAR(map.luminance_integral(), 4.0 * M_PI, 1e-5);
  EXPECT_EQ(map.constant(), Spectrum(1.0f));
}

// ------------------------------------------------------------ the scene keys

class EnvironmentMapFile : public test::TempDirTest {
 protected:
  Scene load(const std::string& light) {
    return parse_scene(R"({"pathlab_scene": 1, "camera": {"position": [0, 0, 4], "look_at": [0, 0, 0]},
      "materials": {}, "shapes": [], "lights": [)" + light + "]}",
                       dir_ / "scene.json");
  }
};

TEST_F(EnvironmentMapFile, LoadsScalesAndRotates) {
  write_exr(dir_ / "map.exr", numbered(6, 3), {});
  const Scene s = load(R"({"type": "environment", "file": "map.exr", "scale": 2,
                           "transform": {"rotate": {"axis": [0, 1, 0], "angle": 90}}})");
  ASSERT_TRUE(s.environment_map);
  EXPECT_FALSE(s.environment);
  // Local +x, texel (1, 1) = (1, 1, 1), turned to -z and scaled by 2.
  EXPECT_EQ(s.environment_map->radiance(vec3(0, 0, -1)), Spectrum(2.0f));
  const CompiledScene compiled{Scene(s)};
  EXPECT_TRUE(compiled.lights().samples_environment());
  EXPECT_EQ(compiled.lights().environment(vec3(0, 0, -1)), Spectrum(2.0f));
}

TEST_F(EnvironmentMapFile, OneGreyChannelIsGrey) {
  Image grey = numbered(8, 4);
  std::vector<float> values;
  for (const vec3& t : grey.pixels) values.push_back(t.x);
  write_exr_channels(dir_ / "grey.exr", 8, 4, {{"Y", values}}, {});
  const Scene s = load(R"({"type": "environment", "file": "grey.exr"})");
  EXPECT_EQ(s.environment_map->radiance(vec3(1, 0, 0)), Spectrum(2.0f));  // column 2 of 8
}

// Negative components are read as 0 with a warning that says how many and
// where the worst one is (the default), or refused with clamp_negative false.
TEST_F(EnvironmentMapFile, ClampNegativeReadsThemAsZeroAndWarns) {
  Image image = numbered(8, 4);
  image.at(5, 2) = Spectrum(1.0f, -0.5f, 2.0f);
  image.at(6, 3).z = -0.01f;
  write_exr(dir_ / "map.exr", image, {});
  EXPECT_THROW(load(R"({"type": "environment", "file": "map.exr", "clamp_negative": false})"), InputError);
  const Scene s = load(R"({"type": "environment", "file": "map.exr"})");
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("2 texel component(s) are negative, the most texel (column 5, row 2) channel G (-0.5)"),
            std::string::npos) << s.warnings[0];
  EXPECT_EQ(s.environment_map->texels().at(5, 2), Spectrum(1.0f, 0.0f, 2.0f));
  EXPECT_EQ(s.environment_map->texels().at(6, 3), Spectrum(6.0f, 3.0f, 0.0f));
}

// The light sampler's environment samples carry the map's radiance and
// density (times the pick probability), as a BSDF-sampled ray that escapes
// the same way finds them (the density up to float rounding of sin theta).
TEST_F(EnvironmentMapFile, LightSamplerAgreesWithTheEscape) {
  write_exr(dir_ / "map.exr", structured(16, 8), {});
  Scene s = load(R"({"type": "environment", "file": "map.exr"})");
  const CompiledScene compiled(std::move(s));
  const LightSampler& lights = compiled.lights();
  ASSERT_EQ(lights.pmf().size(), 1u);
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  for (int k = 0; k < 1000; ++k) {
    const auto ls = lights.sample(vec3(0.0f), uniform(rng), vec2(uniform(rng), uniform(rng)));
    ASSERT_TRUE(ls);
    EXPECT_TRUE(ls->infinite);
    EXPECT_NEAR(ls->pdf, lights.pdf_environment(ls->wi), 1e-5f * ls->pdf);
    EXPECT_EQ(ls->Le, lights.environment(ls->wi));
  }
}

}  // namespace
}  // namespace pathlab
