// core's scalar code calling the generic per-lane functions of
// core/simd/lanes-inl.h at width 1, through lane1's plain scalars
// (core/simd/lane1.h): one source for a step that the reference tracer and
// the wavefront's lanes both take. Include only from core's .cpp files (it
// includes the generic headers at the build's static target): core's
// scalar functions that have a generic form, and core/bsdf's width-1 headers.
#pragma once

// In a foreach_target translation unit HWY_NAMESPACE would name the first
// target's namespace (AVX-512 code) for the scalar callers below.
#ifdef HWY_TARGET_INCLUDE
#error "core/simd/width1.h is for core's scalar .cpp files, not foreach_target translation units"
#endif

#include "core/math.h"
#include "core/mesh.h"
#include "core/sampling.h"
#include "core/simd/lane1.h"
#include "core/simd/environment-inl.h"
#include "core/simd/lanes-inl.h"
#include "core/simd/light_bvh-inl.h"
#include "core/simd/lights-inl.h"
#include "core/simd/sampling-inl.h"
#include "core/simd/shading_frame-inl.h"
#include "core/simd/spherical-inl.h"
#include "core/simd/texture_inputs-inl.h"

namespace pathlab::width1 {

namespace generic = pathlab::HWY_NAMESPACE;
using F = lane1::V<float>;
using F3 = generic::Vec3<F>;
inline constexpr lane1::One<float> kScalar{};  // the descriptor: one plain float

inline F3 lanes(const vec3& v) { return {{v.x}, {v.y}, {v.z}}; }
inline vec3 scalars(const F3& v) { return vec3(v.x.raw, v.y.raw, v.z.raw); }

// One plain double (core/simd/spherical-inl.h).
using D1 = lane1::V<double>;
using D3 = generic::Vec3<D1>;
inline constexpr lane1::One<double> kScalarD{};
inline D3 lanes(const dvec3& v) { return {{v.x}, {v.y}, {v.z}}; }
inline dvec3 scalars(const D3& v) { return dvec3(v.x.raw, v.y.raw, v.z.raw); }

// One index into a table (a light's entry, a node of the light BVH).
using Index = lane1::I64;
inline constexpr lane1::One<std::int64_t> kIndex{};

// The texture coordinates of triangle t's corners (TriangleMesh::uvs) as
// the generic texture inputs read them (core/simd/texture_inputs-inl.h); 0
// on a mesh without them, which those ignore.
inline generic::CornerUvs<F> corner_uvs(const TriangleMesh& mesh, std::uint32_t t) {
  if (!mesh.has_uvs()) return {{F{0.0f}, F{0.0f}, F{0.0f}}, {F{0.0f}, F{0.0f}, F{0.0f}}};
  const glm::uvec3 v = mesh.triangles[t];
  const vec2 a = mesh.uvs[v.x], b = mesh.uvs[v.y], c = mesh.uvs[v.z];
  return {{F{a.x}, F{b.x}, F{c.x}}, {F{a.y}, F{b.y}, F{c.y}}};
}

// Entry i (a whole float) of a cdf in a lane of m, as the generic samplers
// read it (core/simd/lights-inl.h); 0 off the mask, as a masked gather reads.
inline F cdf_entry(std::span<const float> cdf, lane1::M m, F i) {
  return F{m.raw ? cdf[static_cast<std::size_t>(i.raw)] : 0.0f};
}
// A Distribution2D's cdfs as distribution2d_sample and env_lookup read them.
struct Cdfs2D {
  const Distribution2D& d;
  F row(lane1::M m, F i) const { return cdf_entry(d.marginal().cdf(), m, i); }
  F column(lane1::M m, F y, F i) const { return cdf_entry(d.conditional(static_cast<std::size_t>(y.raw)).cdf(), m, i); }
};

}  // namespace pathlab::width1
