// The texture inputs at a hit written once over Highway's vectors: where a
// textured surface is read (its texture coordinates) and the uv area per
// world area that turns the ray cone's width into a footprint there
// (footprint_width, core/simd/lanes-inl.h), on a mesh's triangle and on a
// sphere, placed by an instance or not. core/compiled_scene.cpp
// (CompiledScene::read_textures) and core/mesh_io.cpp (TriangleMesh::uv_at)
// call them at width 1 (core/simd/width1.h) for both tracers' scalar code,
// the wavefront's resolve (wavefront/vector_stages.cpp) at its SIMD width
// for the hits on textured meshes and spheres. What the two store
// differently, an instance's placement and a mesh's texture coordinates,
// each reads through the lookup it passes.
//
// Highway's "-inl.h" convention: no include guard but the toggle below.
#if defined(PATHLAB_CORE_SIMD_TEXTURE_INPUTS_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef PATHLAB_CORE_SIMD_TEXTURE_INPUTS_INL_H_
#undef PATHLAB_CORE_SIMD_TEXTURE_INPUTS_INL_H_
#else
#define PATHLAB_CORE_SIMD_TEXTURE_INPUTS_INL_H_
#endif

#include <hwy/highway.h>

#include "core/math.h"
#include "core/simd/environment-inl.h"
#include "core/simd/lane1.h"
#include "core/simd/lanes-inl.h"

HWY_BEFORE_NAMESPACE();
namespace pathlab::HWY_NAMESPACE {

// A triangle's texture coordinates (u[k], v[k]) at its corner k (the mesh's
// uvs of its vertices).
template <class V>
struct CornerUvs {
  V u[3], v[3];
};

// TriangleMesh::uv_at (core/mesh.h): the texture coordinates at the
// barycentrics (b1, b2) of a triangle, its corners' blended as blend_normals
// blends normals, (b0 c0 + b1 c1) + b2 c2 with b0 = (1 - b1) - b2, where
// `uvs` (the mesh has them); (b1, b2) itself elsewhere.
template <class D, class M, class V = VecOf<D>>
HWY_INLINE void uv_at(D d, M uvs, V b1, V b2, const CornerUvs<V>& c, V& u, V& v) {
  const V b0 = Set(d, 1.0f) - b1 - b2;
  u = IfThenElse(uvs, (b0 * c.u[0] + b1 * c.u[1]) + b2 * c.u[2], b1);
  v = IfThenElse(uvs, (b0 * c.v[0] + b1 * c.v[1]) + b2 * c.v[2], b2);
}

// What CompiledScene::read_textures reads a hit's textures at: the texture
// coordinates (u, v) and the uv area per world area (footprint_width's).
template <class V>
struct TextureInputs {
  V u, v, uv_per_area;
};

// The lookups below read an instance's placement (CompiledScene::Placement)
// through `place`, in the lanes of a mask m: place.linear(m, c) the columns
// c[0..2] of its linear part (to_world's), place.to_local(m, c) the columns
// c[0..3] of its inverse (an affine map: affine_point), place.to_normal(m, c)
// the columns c[0..2] of its linear part's inverse transpose. Each is asked
// only where some lane is placed.

// CompiledScene::read_textures on a mesh's triangle p0 p1 p2 (in its group's
// space) at the barycentrics (b1, b2): uv_at, and triangle_uv_per_area of
// the triangle's edges (p1 - p0, p2 - p0; placed by the instance's linear
// part where `placed`) and of its uv edges. corner_uvs(m) gives the corners'
// CornerUvs in the lanes of m, asked only where the mesh has texture
// coordinates (`uvs`; 0 elsewhere, which triangle_uv_per_area ignores).
template <class D, class M, class Uvs, class Place, class V = VecOf<D>>
HWY_INLINE TextureInputs<V> triangle_texture_inputs(D d, V b1, V b2, const Vec3<V>& p0, const Vec3<V>& p1,
                                                    const Vec3<V>& p2, M uvs, const Uvs& corner_uvs, M placed,
                                                    const Place& place) {
  Vec3<V> e1 = p1 - p0, e2 = p2 - p0;
  if (!AllFalse(d, placed)) {
    Vec3<V> c[3];
    place.linear(placed, c);
    e1 = select(placed, to_world(c[0], c[1], c[2], e1.x, e1.y, e1.z), e1);
    e2 = select(placed, to_world(c[0], c[1], c[2], e2.x, e2.y, e2.z), e2);
  }
  const V zero = Zero(d);
  CornerUvs<V> c{{zero, zero, zero}, {zero, zero, zero}};
  if (!AllFalse(d, uvs)) c = corner_uvs(uvs);
  TextureInputs<V> in;
  uv_at(d, uvs, b1, b2, c, in.u, in.v);
  in.uv_per_area = triangle_uv_per_area(d, e1, e2, uvs, c.u[1] - c.u[0], c.v[1] - c.v[0], c.u[2] - c.u[0],
                                        c.v[2] - c.v[0]);
  return in;
}

// CompiledScene::read_textures on a sphere (center, radius, in its own
// space) at the world point p: sphere_uv of the direction from the centre to
// p, taken back to the sphere's space first where `placed` (the placement's
// to_local), and sphere_uv_per_area, per world area where placed (the
// instance scales the sphere's areas there by placed_area_scale).
template <class D, class M, class Place, class V = VecOf<D>>
HWY_INLINE TextureInputs<V> sphere_texture_inputs(D d, const Vec3<V>& p, const Vec3<V>& center, V radius, M placed,
                                                  const Place& place) {
  const bool any_placed = !AllFalse(d, placed);
  Vec3<V> local = p;
  if (any_placed) {
    Vec3<V> c[4];
    place.to_local(placed, c);
    local = select(placed, affine_point(c[0], c[1], c[2], c[3], p), p);
  }
  const Vec3<V> off = local - center;
  const Vec3<V> dir = off / radius;
  TextureInputs<V> in;
  V sin_theta;
  sphere_uv(d, dir, in.u, in.v, sin_theta);
  in.uv_per_area = sphere_uv_per_area(d, radius, sin_theta);
  if (any_placed) {
    Vec3<V> l[3], t[3];
    place.linear(placed, l);
    place.to_normal(placed, t);
    in.uv_per_area =
        IfThenElse(placed, in.uv_per_area / placed_area_scale(l[0], l[1], l[2], t[0], t[1], t[2], dir), in.uv_per_area);
  }
  return in;
}

}  // namespace pathlab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // PATHLAB_CORE_SIMD_TEXTURE_INPUTS_INL_H_ toggle
