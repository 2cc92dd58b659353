#include "core/sampling.h"

#include "core/simd/width1.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace pathlab {

// The warps are written once for every SIMD width (core/simd/sampling-inl.h)
// and called here at width 1 (core/simd/width1.h).

SinCos sin_cos_quarter(float x) {
  using namespace width1;
  F s, c;
  generic::sin_cos_quarter(kScalar, F{x}, s, c);
  return {s.raw, c.raw};
}

vec2 square_to_concentric_disk(vec2 u) {
  using namespace width1;
  F x, y;
  generic::concentric_disk(kScalar, F{u.x}, F{u.y}, x, y);
  return vec2(x.raw, y.raw);
}

vec2 concentric_disk_to_square(vec2 p) {
  const float r = std::sqrt(p.x * p.x + p.y * p.y);
  float phi = std::atan2(p.y, p.x);
  if (phi < -kPi / 4.0f) phi += 2.0f * kPi;  // phi in [-pi/4, 7pi/4)
  float a, b;
  if (phi < kPi / 4.0f) {  // right wedge: r = a, theta = pi/4 * b/a
    a = r;
    b = phi * a / (kPi / 4.0f);
  } else if (phi < 3.0f * kPi / 4.0f) {  // top wedge: r = b
    b = r;
    a = -(phi - kPi / 2.0f) * b / (kPi / 4.0f);
  } else if (phi < 5.0f * kPi / 4.0f) {  // left wedge: r = a < 0
    a = -r;
    b = (phi - kPi) * a / (kPi / 4.0f);
  } else {  // bottom wedge: r = b < 0
    b = -r;
    a = -(phi - 3.0f * kPi / 2.0f) * b / (kPi / 4.0f);
  }
  // (x + 1) / 2 can round up to exactly 1 for the last float below 1; keep
  // the result in [0, 1) like the square it inverts.
  return glm::clamp((vec2(a, b) + vec2(1.0f)) * 0.5f, vec2(0.0f), vec2(kOneMinusEpsilon));
}

vec3 square_to_cosine_hemisphere(vec2 u) {
  using namespace width1;
  F x, y, z;
  generic::cosine_hemisphere(kScalar, F{u.x}, F{u.y}, x, y, z);
  return vec3(x.raw, y.raw, z.raw);
}

float cosine_hemisphere_pdf(const vec3& w) {
  using namespace width1;
  return generic::cosine_hemisphere_pdf(kScalar, F{w.z}).raw;
}

vec2 cosine_hemisphere_to_square(const vec3& w) { return concentric_disk_to_square(vec2(w.x, w.y)); }

vec3 square_to_uniform_sphere(vec2 u) {
  using namespace width1;
  F x, y, z;
  generic::uniform_sphere(kScalar, F{u.x}, F{u.y}, x, y, z);
  return vec3(x.raw, y.raw, z.raw);
}

vec2 uniform_sphere_to_square(const vec3& w) {
  float phi = std::atan2(w.y, w.x);
  if (phi < 0.0f) phi += 2.0f * kPi;
  return vec2((1.0f - w.z) * 0.5f, phi * kInv2Pi);
}

// These two are the generic functions of core/simd/lanes-inl.h at width 1:
// the wavefront's lanes run the same source.
float power_heuristic(float pdf_a, float pdf_b) {
  using namespace width1;
  return generic::power_heuristic(kScalar, F{pdf_a}, F{pdf_b}).raw;
}

float area_to_solid_angle(float pdf_area, float dist, float cos_light) {
  using namespace width1;
  return generic::area_to_solid_angle(kScalar, F{pdf_area}, F{dist}, F{cos_light}).raw;
}

vec2 square_to_uniform_triangle(vec2 u) {
  // (b1, b2) = (u.y sqrt(u.x), 1 - sqrt(u.x)); b0 = sqrt(u.x) (1 - u.y).
  using namespace width1;
  F b1, b2;
  generic::uniform_triangle(kScalar, F{u.x}, F{u.y}, b1, b2);
  return vec2(b1.raw, b2.raw);
}

vec2 uniform_triangle_to_square(vec2 b) {
  // s = 1 - b2 cancels when s is tiny, so b1 / s can come out a little
  // above 1: clamp to the square the forward warp reads.
  const float s = 1.0f - b.y;
  return glm::clamp(vec2(s * s, s > 0.0f ? b.x / s : 0.0f), vec2(0.0f), vec2(kOneMinusEpsilon));
}

Distribution1D::Distribution1D(std::span<const float> weights) : n_(weights.size()), cdf_(weights.size() + 1, 0.0f) {
  double running = 0.0;
  for (std::size_t i = 0; i < n_; ++i) {
    running += weights[i];
    cdf_[i + 1] = static_cast<float>(running);
  }
  total_ = running;
  if (!(total_ > 0.0)) {
    total_ = 0.0;
    std::fill(cdf_.begin(), cdf_.end(), 0.0f);
    return;
  }
  // Normalised from the double sums, so that the cdf is non-decreasing and
  // ends at exactly 1.
  running = 0.0;
  for (std::size_t i = 0; i < n_; ++i) {
    running += weights[i];
    cdf_[i + 1] = std::min(1.0f, static_cast<float>(running / total_));
  }
  cdf_[n_] = 1.0f;
}

Distribution1D::Sample Distribution1D::sample(float u) const {
  if (!(total_ > 0.0)) return {};
  if (n_ > kMaxExactFloatIndex) {
    // Beyond the float indices of the generic search (no lane reads a cdf
    // this long): the last i with cdf[i] <= u, std::upper_bound's answer.
    const auto it = std::upper_bound(cdf_.begin(), cdf_.end(), u);
    const std::size_t i = std::min<std::size_t>(static_cast<std::size_t>(it - cdf_.begin()) - 1, n_ - 1);
    using namespace width1;
    const F x = generic::piecewise_point(kScalar, F{u}, F{cdf_[i]}, F{cdf_[i + 1]}, F{static_cast<float>(i)},
                                         F{static_cast<float>(n_)});
    return {x.raw, pdf(i), i};
  }
  // core/simd/lights-inl.h's cdf_sample, which the wavefront's lanes run on
  // the same cdf.
  using namespace width1;
  F cell, density;
  const F x = generic::cdf_sample(kScalar, lane1::M{true}, n_, F{u},
                                  [this](lane1::M m, F i) { return cdf_entry(cdf_, m, i); }, cell, density);
  return {x.raw, density.raw, static_cast<std::size_t>(cell.raw)};
}

Distribution2D::Distribution2D(std::span<const float> weights, std::size_t width, std::size_t height) {
  if (width > kMaxExactFloatIndex || height > kMaxExactFloatIndex)
    throw std::length_error("Distribution2D: more than 2^24 rows or columns");
  std::vector<float> row_sums(height);
  conditional_.reserve(height);
  for (std::size_t y = 0; y < height; ++y) {
    conditional_.emplace_back(weights.subspan(y * width, width));
    row_sums[y] = static_cast<float>(conditional_.back().total());
  }
  marginal_ = Distribution1D(row_sums);
}

Distribution2D::Sample Distribution2D::sample(vec2 u) const {
  // core/simd/lights-inl.h's distribution2d_sample, as the wavefront's lanes
  // run it on the same cdfs.
  using namespace width1;
  lane1::M ok{true};
  F px, py, density, x, y;
  generic::distribution2d_sample(kScalar, ok, width(), height(), F{u.x}, F{u.y}, Cdfs2D{*this}, px, py, density, x, y);
  if (!ok.raw) return {};
  return {vec2(px.raw, py.raw), density.raw, static_cast<std::size_t>(x.raw), static_cast<std::size_t>(y.raw)};
}

}  // namespace pathlab
