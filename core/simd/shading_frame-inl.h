// The shading frame at a hit written once over Highway's vectors: the
// vertex normals each placed by an instance, blended and turned into the
// shading normal, the frame about it (Frame(ns), or a mesh's tangents'
// with a placement's mirroring and the normal their handedness refers to),
// whether the Surfel has a shading normal, and a normal map's tilt of that
// frame. core/compiled_scene.cpp (CompiledScene::shading_frame and
// read_textures) calls them at width 1 (core/simd/width1.h) for both
// tracers' scalar code, the wavefront's resolve (wavefront/vector_stages.cpp)
// at its SIMD width for the hits whose frame the lanes make (kFramed). What
// the two store differently, a mesh's vertex normals and tangents and an
// instance's placement, each reads through the lookups it passes.
//
// Highway's "-inl.h" convention: no include guard but the toggle below.
#if defined(PATHLAB_CORE_SIMD_SHADING_FRAME_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef PATHLAB_CORE_SIMD_SHADING_FRAME_INL_H_
#undef PATHLAB_CORE_SIMD_SHADING_FRAME_INL_H_
#else
#define PATHLAB_CORE_SIMD_SHADING_FRAME_INL_H_
#endif

#include <hwy/highway.h>

#include "core/math.h"
#include "core/simd/lane1.h"
#include "core/simd/lanes-inl.h"

HWY_BEFORE_NAMESPACE();
namespace pathlab::HWY_NAMESPACE {

// Surfel::shading_normal: where the frame's normal ns is not the geometric
// normal ng, in some component (glm's vec3 !=; NaN differs from itself, so
// a normal that is not finite counts as a shading normal, which Surfel
// absorbs).
template <class V>
HWY_INLINE auto differs(const Vec3<V>& ns, const Vec3<V>& ng) {
  return Or(ns.x != ng.x, Or(ns.y != ng.y, ns.z != ng.z));
}

// The lookups below, each asked only in the lanes of a mask m where some
// lane needs it (unspecified elsewhere):
//   normals(m, n): the triangle's vertex normals n[0..2] (the mesh's own
//     space: a group's, for a shape in one);
//   tangents(m, t, w): its vertices' tangents t[0..2] (xyz) and their
//     handedness w[0..2];
//   flipped(m): where the shape has flip_normals;
//   place.to_normal(m, c): the columns c[0..2] of an instance's inverse
//     transpose (texture_inputs-inl.h's placement lookup), place.linear(m, c)
//     those of its linear part, place.mirrors(m) where that has a negative
//     determinant (CompiledScene::Placement::mirrors, false off m).

// CompiledScene::shading_frame at a hit at the barycentrics (b1, b2) of a
// mesh's triangle (or any hit where neither `smooth` nor `tangents`: a
// sphere's, a flat mesh's) whose geometric normal ng is in world space.
// The shading normal ns: where `smooth` (the mesh has vertex normals), their
// sum - each placed first by the instance's inverse transpose where
// `placed`, as a copy of the mesh placed by transform_mesh would blend
// them: under a non-uniform scale, blending first and placing the sum
// points elsewhere - blended (blend_normals) and turned to ng's side
// (shading_normal); ng elsewhere. Its frame (fs, ft, ns): Frame(ns), or,
// where `tangents`, tangent_frame's: the vertices' tangents placed by the
// instance's linear part (the identity's columns where not placed, as in
// world space), their handedness turned where the placement mirrors and
// referring to the mesh's own normal, the vertex normals' sum or, on a flat
// mesh, ng before flip_normals. Returns Surfel::shading_normal (differs).
template <class D, class M, class Normals, class Tangents, class Flipped, class Place, class V = VecOf<D>>
HWY_INLINE M surface_frame(D d, V b1, V b2, const Vec3<V>& ng, M smooth, const Normals& normals, M tangents,
                           const Tangents& vertex_tangents, const Flipped& flipped, M placed, const Place& place,
                           Vec3<V>& fs, Vec3<V>& ft, Vec3<V>& ns) {
  Vec3<V> sum = ng;
  ns = ng;
  if (!AllFalse(d, smooth)) {
    Vec3<V> n[3];
    normals(smooth, n);
    if (const M on = And(smooth, placed); !AllFalse(d, on)) {
      Vec3<V> c[3];
      place.to_normal(on, c);
      for (Vec3<V>& v : n) v = select(on, place_normal(d, c[0], c[1], c[2], v), v);
    }
    sum = select(smooth, blend_normals(d, b1, b2, n[0], n[1], n[2]), ng);
    ns = select(smooth, shading_normal(d, ng, sum), ng);
  }
  frame(d, ns, fs, ft);
  if (!AllFalse(d, tangents)) {
    Vec3<V> t[3];
    V w[3];
    vertex_tangents(tangents, t, w);
    Vec3<V> c[3] = {splat3(d, 1.0f, 0.0f, 0.0f), splat3(d, 0.0f, 1.0f, 0.0f), splat3(d, 0.0f, 0.0f, 1.0f)};
    M mirrors = And(tangents, Not(tangents));
    if (const M on = And(tangents, placed); !AllFalse(d, on)) {
      Vec3<V> l[3];
      place.linear(on, l);
      for (int k = 0; k < 3; ++k) c[k] = select(on, l[k], c[k]);
      mirrors = place.mirrors(on);
    }
    const Vec3<V> n_mesh = select(smooth, sum, select(flipped(tangents), -ng, ng));
    Vec3<V> tfs, tft;
    tangent_frame(d, b1, b2, t, w, c[0], c[1], c[2], mirrors, n_mesh, ns, tfs, tft);
    fs = select(tangents, tfs, fs);
    ft = select(tangents, tft, ft);
  }
  return differs(ns, ng);
}

// CompiledScene::read_textures' normal map: normal_map_frame's tilt of the
// shading frame (fs, ft, fn) at a hit with geometric normal ng by the
// map's texel c (times `scale`), and Surfel::shading_normal after it in
// `shading` (differs: where fn is not ng; where the frame did not tilt,
// what surface_frame said). Returns where it tilted.
template <class D, class M, class V = VecOf<D>>
HWY_INLINE M normal_mapped_frame(D d, const Vec3<V>& c, V scale, const Vec3<V>& ng, Vec3<V>& fs, Vec3<V>& ft,
                                 Vec3<V>& fn, M& shading) {
  const M tilted = normal_map_frame(d, c, scale, ng, fs, ft, fn);
  shading = differs(fn, ng);
  return tilted;
}

}  // namespace pathlab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // PATHLAB_CORE_SIMD_SHADING_FRAME_INL_H_ toggle
