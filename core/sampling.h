// Warps from the unit square to the domains the estimators sample, each with
// its density and its inverse (the inverses make the warps testable and let
// a recorded direction be mapped back to the random numbers that made it).
#pragma once

#include "core/math.h"

#include <cstddef>
#include <span>
#include <vector>

namespace pathlab {

// sin and cos of x for |x| <= pi/4, by fixed polynomials in plain float
// arithmetic (the coefficients of Cephes' sinf and cosf), within 2 ulp of
// the true values. Unlike libm's, the result is the same bits in any build
// and on any machine, and a vector lane that evaluates the same expression
// gets it too: the warps below use it so that the wavefront's vectorised
// stages (wavefront/vector_stages.h) draw the directions the reference draws.
struct SinCos {
  float sin, cos;
};
SinCos sin_cos_quarter(float x);

// Shirley-Chiu concentric map: square [0,1)^2 -> unit disk, area-preserving.
vec2 square_to_concentric_disk(vec2 u);
vec2 concentric_disk_to_square(vec2 p);

// Cosine-weighted hemisphere about +z (Malley's method on the concentric
// disk). Density cos(theta)/pi in solid angle.
vec3 square_to_cosine_hemisphere(vec2 u);
float cosine_hemisphere_pdf(const vec3& w);
vec2 cosine_hemisphere_to_square(const vec3& w);

// Uniform directions on the unit sphere. Density 1/(4 pi).
vec3 square_to_uniform_sphere(vec2 u);
inline float uniform_sphere_pdf() { return kInv4Pi; }
vec2 uniform_sphere_to_square(const vec3& w);

// Uniform point on a triangle as barycentrics (b1, b2); b0 = 1 - b1 - b2.
// Density 1/area in area measure.
vec2 square_to_uniform_triangle(vec2 u);
vec2 uniform_triangle_to_square(vec2 b);

// Veach's power heuristic (beta = 2) for two one-sample techniques: 1 for
// an infinite pdf_a (a delta the other technique cannot sample), 0 unless
// pdf_a > 0, else a^2 / (a^2 + b^2) through the ratio b / a (squaring the
// pdfs themselves would overflow above ~1.8e19 and underflow below ~1e-23).
float power_heuristic(float pdf_a, float pdf_b);

// Solid-angle density of a point sampled on a surface with area density
// `pdf_area`, seen from distance `dist` at cosine `cos_light` to its normal.
// Returns 0 when the surface is seen edge-on (the sample carries no energy).
float area_to_solid_angle(float pdf_area, float dist, float cos_light);

// A piecewise-constant density on [0, 1) over n equal cells, proportional
// to non-negative weights (pbrt-v4's PiecewiseConstant1D). The density of a
// cell is read from the cdf as stored (float), not from the weights, so it is
// exactly the probability with which sample() lands there (for a continuous
// u): a cell whose weight is lost to rounding has density 0 and is never
// sampled. All weights 0: no density at all (sample() gives pdf 0).
class Distribution1D {
 public:
  Distribution1D() = default;
  explicit Distribution1D(std::span<const float> weights);

  std::size_t size() const { return n_; }
  // Sum of the weights (in double), 0 for a distribution with no density.
  double total() const { return total_; }
  // Probability of cell i, and the density on [0, 1) inside it.
  float pmf(std::size_t i) const { return cdf_[i + 1] - cdf_[i]; }
  float pdf(std::size_t i) const { return pmf(i) * static_cast<float>(n_); }

  struct Sample {
    float x = 0.0f;       // in [0, 1), uniform inside its cell
    float pdf = 0.0f;     // density at x
    std::size_t cell = 0;
  };
  // The cell i with cdf[i] <= u < cdf[i + 1] (zero-width cells skipped),
  // and x placed in it by where u falls between the two.
  Sample sample(float u) const;
  // n + 1 entries from 0 to 1 (all 0 without density): cell i spans [cdf[i], cdf[i + 1]).
  std::span<const float> cdf() const { return cdf_; }

 private:
  std::size_t n_ = 0;
  double total_ = 0.0;
  std::vector<float> cdf_;  // n + 1 entries, 0 ... 1
};

// A piecewise-constant density on [0, 1)^2 over a grid of width x height
// cells, row-major weights: the rows by their sums (the marginal), then a
// column of the row (its conditional), as pbrt-v4's PiecewiseConstant2D.
class Distribution2D {
 public:
  Distribution2D() = default;
  Distribution2D(std::span<const float> weights, std::size_t width, std::size_t height);

  std::size_t width() const { return conditional_.empty() ? 0 : conditional_[0].size(); }
  std::size_t height() const { return marginal_.size(); }
  // Density on [0, 1)^2 in cell (x, y).
  float pdf(std::size_t x, std::size_t y) const { return marginal_.pdf(y) * conditional_[y].pdf(x); }

  struct Sample {
    vec2 p{0.0f};  // in [0, 1)^2
    float pdf = 0.0f;
    std::size_t x = 0, y = 0;  // its cell
  };
  // u.y picks the row, u.x the column within it (width and height at most
  // kMaxExactFloatIndex, the generic search's float indices).
  Sample sample(vec2 u) const;
  // The rows' distribution and each row's columns', for code that samples
  // it in bulk (the wavefront's lanes).
  const Distribution1D& marginal() const { return marginal_; }
  const Distribution1D& conditional(std::size_t y) const { return conditional_[y]; }

 private:
  Distribution1D marginal_;
  std::vector<Distribution1D> conditional_;
};

}  // namespace pathlab
