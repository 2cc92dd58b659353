// A sphere light seen from outside does not shadow itself: next-event
// estimation of the irradiance it sends to a point, with the shadow ray each
// light sample casts (Surfel::spawn_to, ending just before the sphere),
// against the closed form pi L (r/d)^2 cos(theta) (a uniform sphere wholly
// above the point's horizon). Embree's own sphere kernels blocked 8 % of
// the shadow rays aimed at the bulb in the Cornell box under area sampling
// and 12 % under cone sampling (their crossing lies within float rounding of
// tmax), a bias this test sees at many standard errors (Embree's float
// arithmetic put back: 1,033 and 3,424 of 40,000 blocked at distance 1.3,
// the estimate 9 % low); sphere_crossing (core/geometry.h) blocks none.
//
// Receivers far away too: the float shadow ray (origin, rounded direction,
// tmax its rounded length) reaches tmax within gamma(2) |end - origin| of
// the end Surfel::spawn_to aimed at, which grows with the ray's length.
// spawn_to moves the end off the light by that much more than the target's
// own error; before it did, 885 of 40,000 area-sampled shadow rays from
// distance 8 ended inside the sphere and were blocked (estimate 3 % low).
#include "core/compiled_scene.h"
#include "core/light_sampler.h"
#include "core/rng.h"
#include "core/sample_dims.h"
#include "tests/stat_util.h"

#include <gtest/gtest.h>

#include <cmath>

namespace pathlab {
namespace {

struct Receiver {
  const char* name;
  float distance;  // from the sphere's centre
  float theta;     // between the point's normal and the direction to the centre, radians
};

TEST(SphereLightVisibility, NextEventEstimateMatchesTheClosedForm) {
  constexpr float kRadius = 0.1f, kL = 2.0f;
  const vec3 center(0.3f, 0.5f, 0.2f);
  const Receiver receivers[] = {{"near, facing", 0.25f, 0.0f}, {"near, tilted", 0.3f, 0.8f},
                                {"bulb's distance", 1.3f, 0.4f}, {"far", 8.0f, 1.2f}, {"farther", 60.0f, 0.3f}};
  const LightSampling samplings[] = {LightSampling::Area, LightSampling::SolidAngle};
  constexpr std::uint32_t kSamples = 40000;
  // Family-wise false-alarm rate 1e-3 over every receiver and sampling.
  const double z_max = test::sidak_z(1e-3, static_cast<double>(std::size(receivers) * std::size(samplings)));
  for (const LightSampling sampling : samplings) {
    Scene scene;
    scene.name = "bulb";
    Material light{"light", MaterialType::Emissive, Spectrum(0.0f), Spectrum(kL), false};
    scene.materials.push_back(light);
    Shape bulb;
    bulb.description = "bulb";
    bulb.kind = Shape::Kind::Sphere;
    bulb.center = center;
    bulb.radius = kRadius;
    scene.shapes.push_back(bulb);
    scene.render.light_sampling = sampling;
    const CompiledScene compiled(std::move(scene));
    for (std::uint32_t k = 0; k < std::size(receivers); ++k) {
      const Receiver& r = receivers[k];
      SCOPED_TRACE(testing::Message() << r.name << (sampling == LightSampling::Area ? ", area" : ", solid angle"));
      ASSERT_LT(r.theta + std::asin(kRadius / r.distance), 0.5f * kPi) << "the sphere must lie above the horizon";
      // The point, off the centre along a fixed direction; its normal
      // tilted by theta from the direction back to the centre.
      const vec3 out = glm::normalize(vec3(0.36f, -0.48f, 0.8f));
      const Frame frame(-out);
      Surfel s;
      s.p = center + r.distance * out;
      s.n = std::cos(r.theta) * -out + std::sin(r.theta) * frame.s;
      double sum = 0.0, sum2 = 0.0;
      std::uint32_t blocked = 0;
      for (std::uint32_t i = 0; i < kSamples; ++i) {
        const auto ls = compiled.lights().sample(s.p, sample_u(7, k, i, 1, Dim::LightChoice),
                                                 vec2(sample_u(7, k, i, 1, Dim::LightX), sample_u(7, k, i, 1, Dim::LightY)));
        if (!ls) continue;
        const double cos_theta = glm::dot(s.n, ls->wi);
        if (cos_theta <= 0.0) continue;
        if (compiled.occluded(s.spawn_to(ls->p, ls->p_error, ls->n))) {
          ++blocked;
          continue;
        }
        const double e = static_cast<double>(ls->Le.x) * cos_theta / static_cast<double>(ls->pdf);
        sum += e;
        sum2 += e * e;
      }
      const double n = kSamples, mean = sum / n, var = (sum2 / n - mean * mean) / (n - 1.0);
      const double sin_alpha = kRadius / static_cast<double>(r.distance);
      const double exact = kPi * kL * sin_alpha * sin_alpha * std::cos(static_cast<double>(r.theta));
      const double z = (mean - exact) / std::sqrt(var);
      EXPECT_LT(std::abs(z), z_max) << "estimate " << mean << ", closed form " << exact << ", " << blocked << " of "
                                    << kSamples << " shadow rays blocked";
      EXPECT_EQ(blocked, 0u);
    }
  }
}

}  // namespace
}  // namespace pathlab
