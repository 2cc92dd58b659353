// The two facts the tessellated-sphere bound rests on (derivation at the top
// of test_tessellated_sphere.cpp): the cosine-weighted fraction lost below a
// tilted geometric plane, and the tessellation angle theta_max bounding the
// shading normal's tilt.
#include "tests/stat_util.h"
#include "tests/test_scenes.h"

#include "core/geometry.h"
#include "core/rng.h"
#include "core/sampling.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <numbers>
#include <vector>

namespace pathlab {
namespace {

constexpr double kAlpha = 1e-4;

// 2. of test_tessellated_sphere.cpp's header: the cosine-weighted fraction of the shading hemisphere
// below a plane tilted by theta is (1 - cos theta) / 2. Cosine-weighted
// directions (the renderer's own mapping) below the tilted plane are counted
// and z-tested against the binomial (Sidak over the angles); the other
// candidate, (theta - sin theta cos theta) / pi, is rejected at the same level.
TEST(TessellationBound, LostFractionFormula) {
  constexpr int kSamples = 1 << 20;
  const std::vector<double> angles = {0.017354, 0.06936, 0.2742, 0.6, 1.2};
  const double threshold = test::sidak_z(kAlpha, static_cast<double>(angles.size()));
  for (const double theta : angles) {
    const dvec3 g(std::sin(theta), 0.0, std::cos(theta));
    long below = 0;
    for (std::uint64_t i = 0; i < kSamples; ++i) {
      const vec2 u(to_unit_float(mix64(2 * i)), to_unit_float(mix64(2 * i + 1)));
      if (glm::dot(dvec3(square_to_cosine_hemisphere(u)), g) < 0.0) ++below;
    }
    const auto z = [&](double p) { return (below - kSamples * p) / std::sqrt(kSamples * p * (1.0 - p)); };
    const double p = 0.5 * (1.0 - std::cos(theta));
    EXPECT_LT(std::abs(z(p)), threshold) << "theta " << theta << ": " << below << " of " << kSamples;
    if (theta > 0.05) {  // below that, 1M samples cannot tell the two apart
      EXPECT_GT(std::abs(z((theta - std::sin(theta) * std::cos(theta)) / std::numbers::pi)), threshold) << theta;
    }
  }
}

// 1. of test_tessellated_sphere.cpp's header: theta_max bounds the angle between the interpolated
// normal and the face normal everywhere on the mesh (sampled on a grid of
// barycentrics, the renderer's own shading_normal), is reached at the
// vertices, shrinks as 1 / n, and the mesh's faces lie at distance
// >= R cos theta_max from the centre.
TEST(TessellationBound, TessellationAngleBoundsTheShadingNormal) {
  double previous = std::numbers::pi;
  for (const int rings : {8, 32, 128}) {
    const TriangleMesh mesh = test::uv_sphere(vec3(0.0f), 1.0f, rings);
    const double theta_max = test::tessellation_angle(mesh, dvec3(0.0));
    EXPECT_LT(theta_max, previous / 3.0) << rings;
    EXPECT_NEAR(theta_max * rings, std::numbers::pi / std::sqrt(2.0), 0.05) << rings;
    previous = theta_max;
    // In cosines: float normalisations and dot products of unit vectors,
    // each a few ulps (2^-24) off.
    constexpr double kRounding = 16 * 0x1p-24;
    double worst = 1.0, nearest_plane = 1.0;  // smallest cos(ns, g); smallest plane distance
    for (const glm::uvec3& t : mesh.triangles) {
      const vec3 p0 = mesh.positions[t.x], p1 = mesh.positions[t.y], p2 = mesh.positions[t.z];
      const vec3 g = glm::normalize(glm::cross(p1 - p0, p2 - p0));
      nearest_plane = std::min(nearest_plane, double(glm::dot(g, p0)));
      for (int i = 0; i <= 8; ++i)
        for (int j = 0; i + j <= 8; ++j) {
          const float b1 = i / 8.0f, b2 = j / 8.0f;
          const vec3 sum = (1.0f - b1 - b2) * mesh.normals[t.x] + b1 * mesh.normals[t.y] + b2 * mesh.normals[t.z];
          worst = std::min(worst, double(glm::dot(shading_normal(g, sum), g)));
        }
    }
    EXPECT_GE(worst, std::cos(theta_max) - kRounding) << rings;
    EXPECT_LE(worst, std::cos(theta_max) + kRounding) << rings;  // reached (at the vertices)
    EXPECT_GE(nearest_plane, std::cos(theta_max) - kRounding) << rings;
  }
}

}  // namespace
}  // namespace pathlab
