// Small math vocabulary shared by every pathlab module: GLM vectors, RGB
// radiance, orthonormal frames and the constants the estimators need.
#pragma once

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

namespace pathlab {

using vec2 = glm::vec2;
using vec3 = glm::vec3;
using vec4 = glm::vec4;
using dvec3 = glm::dvec3;
using mat3 = glm::mat3;
using mat4 = glm::mat4;

// Linear RGB radiance, irradiance or throughput. One type keeps every
// estimator's arithmetic explicit; spectral rendering is out of scope.
using Spectrum = glm::vec3;

inline constexpr float kPi = 3.14159265358979323846f;
inline constexpr float kInvPi = 1.0f / kPi;
inline constexpr float kInv2Pi = 1.0f / (2.0f * kPi);
inline constexpr float kInv4Pi = 1.0f / (4.0f * kPi);
inline constexpr float kInfinity = std::numeric_limits<float>::infinity();
inline constexpr float kOneMinusEpsilon = 0x1.fffffep-1f;  // the largest float below 1

inline float max_component(const vec3& v) { return std::max(v.x, std::max(v.y, v.z)); }
inline float average(const vec3& v) { return (v.x + v.y + v.z) * (1.0f / 3.0f); }
// Rec. 709 luminance: the scalar "power" of a colour used to pick lights.
inline float luminance(const Spectrum& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }
// In double, for powers: a float sum overflows near FLT_MAX radiance, and
// pi times it already above 1.1e38.
inline double luminance_double(const Spectrum& c) {
  return 0.2126 * double(c.x) + 0.7152 * double(c.y) + 0.0722 * double(c.z);
}
inline bool is_black(const Spectrum& c) { return c.x == 0.0f && c.y == 0.0f && c.z == 0.0f; }
inline bool is_finite(const vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
inline float sqr(float x) { return x * x; }

// Whole numbers up to this are exact as floats: the most entries code that
// indexes with float lanes (pick_cdf, core/simd/lights-inl.h) addresses.
inline constexpr std::size_t kMaxExactFloatIndex = std::size_t{1} << 24;

// gamma(n) of Higham / PBR: a bound on the relative error of n float
// operations, n * eps / (1 - n * eps) with eps = 2^-24.
constexpr float gamma_bound(int n) {
  constexpr float eps = 0x1p-24f;
  return (static_cast<float>(n) * eps) / (1.0f - static_cast<float>(n) * eps);
}

// Orthonormal basis with `n` as its z axis (Duff et al. 2017, "Building an
// Orthonormal Basis, Revisited": branchless and continuous except at n.z = -1).
struct Frame {
  vec3 s, t, n;

  Frame() : s(1, 0, 0), t(0, 1, 0), n(0, 0, 1) {}
  // Duff et al.'s orthonormal basis about the unit normal (core/math.cpp:
  // the generic frame() of core/simd/lanes-inl.h at width 1).
  explicit Frame(const vec3& normal);
  // The frame of a unit tangent `tangent` perpendicular to `normal`: s along
  // it, t = handedness * cross(n, s), so that a mesh's bitangent (handedness
  // w = +-1, glTF's convention) is the t axis. With w = -1 the frame is
  // left-handed; the reflection models only read directions in it.
  Frame(const vec3& normal, const vec3& tangent, float handedness)
      : s(tangent), t(handedness * glm::cross(normal, tangent)), n(normal) {}
  // v's coordinates in the frame, and back (core/math.cpp: the generic
  // to_local and to_world of core/simd/lanes-inl.h at width 1).
  vec3 to_local(const vec3& v) const;
  vec3 to_world(const vec3& v) const;
};

}  // namespace pathlab
