// The light BVH's walks (core/light_bvh.cpp: importance, LightBvh::split,
// pick and share) over Highway's double lanes, for the wavefront's
// vectorised stages: each lane walks its own path down the tree and gets
// the bits the scalar walk gets (IEEE double + - * / sqrt and floor, in the
// scalar order; std::max(a, b) is hn::Max(b, a), std::clamp and the
// comparisons as selects). VectorStages.* holds them to the scalar bits.
//
// The tree is read from LightBvh::node_table(): kBvhFields doubles per node
// (BvhField, core/light_bvh.h).
//
// Highway's "-inl.h" convention: no include guard but the toggle below.
#if defined(PATHLAB_CORE_SIMD_LIGHT_BVH_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef PATHLAB_CORE_SIMD_LIGHT_BVH_INL_H_
#undef PATHLAB_CORE_SIMD_LIGHT_BVH_INL_H_
#else
#define PATHLAB_CORE_SIMD_LIGHT_BVH_INL_H_
#endif

#include <hwy/highway.h>

#include "core/light_bvh.h"
#include "core/simd/lanes-inl.h"

#include <cfloat>
#include <cstdint>

HWY_BEFORE_NAMESPACE();
namespace pathlab::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;


// std::clamp(c, -1, 1), then {c, sqrt(max(0, 1 - c c))} (from_cos).
template <class DD, class VD = hn::Vec<DD>>
HWY_INLINE void bvh_from_cos(DD dd, VD c, VD& cos, VD& sin) {
  const VD one = hn::Set(dd, 1.0), minus_one = hn::Set(dd, -1.0);
  c = hn::IfThenElse(c < minus_one, minus_one, hn::IfThenElse(one < c, one, c));
  cos = c;
  sin = hn::Sqrt(hn::Max(one - c * c, hn::Zero(dd)));
}
// minus_clamped: cos and sin of max(0, a - b).
template <class DD, class VD = hn::Vec<DD>>
HWY_INLINE void bvh_minus_clamped(DD dd, VD a_cos, VD a_sin, VD b_cos, VD b_sin, VD& cos, VD& sin) {
  const auto le = a_cos >= b_cos;
  cos = hn::IfThenElse(le, hn::Set(dd, 1.0), a_cos * b_cos + a_sin * b_sin);
  sin = hn::IfThenElseZero(hn::Not(le), a_sin * b_cos - a_cos * b_sin);
}

// Field f of each lane's node (node: the node's index; 0 for a lane off m).
template <class DD, class VD = hn::Vec<DD>>
HWY_INLINE VD bvh_field(DD dd, const double* table, hn::Vec<hn::RebindToSigned<DD>> node, int f) {
  const hn::RebindToSigned<DD> di;
  return hn::GatherIndex(dd, table, node * hn::Set(di, kBvhFields) + hn::Set(di, f));
}

// importance(bounds of `node`, {p, n}): n = 0 (every lane's, has_n false)
// for a query without a normal.
template <class DD, class VD = hn::Vec<DD>>
HWY_INLINE VD bvh_importance(DD dd, const double* table, hn::Vec<hn::RebindToSigned<DD>> node, const Vec3<VD>& p,
                             const Vec3<VD>& n) {
  auto field3 = [&](int f) { return Vec3<VD>{bvh_field(dd, table, node, f), bvh_field(dd, table, node, f + 1),
                                             bvh_field(dd, table, node, f + 2)}; };
  const VD zero = hn::Zero(dd), half_ = hn::Set(dd, 0.5);
  const Vec3<VD> lo = field3(kBvhLo), hi = field3(kBvhHi), axis = field3(kBvhAxis);
  const VD phi = bvh_field(dd, table, node, kBvhPhi);
  const Vec3<VD> c = half_ * (lo + hi);
  const Vec3<VD> half = half_ * (hi - lo);
  const VD r2 = dot(half, half);
  const Vec3<VD> d = p - c;
  const VD d2 = dot(d, d);
  // std::max({d2, r2 / 4, DBL_MIN}): the first largest.
  VD dist2 = d2;
  dist2 = hn::IfThenElse(dist2 < hn::Set(dd, 0.25) * r2, hn::Set(dd, 0.25) * r2, dist2);
  dist2 = hn::IfThenElse(dist2 < hn::Set(dd, DBL_MIN), hn::Set(dd, DBL_MIN), dist2);
  auto finite_or_max = [&](VD v) { return hn::IfThenElse(hn::IsFinite(v), v, hn::Set(dd, DBL_MAX)); };
  // Inside the bounding sphere: phi / d^2.
  const auto inside = hn::Not(d2 > r2);
  const VD inside_imp = finite_or_max(phi / dist2);

  const VD sin2_b = r2 / d2;
  const VD tb_cos = hn::Sqrt(hn::Max(hn::Set(dd, 1.0) - sin2_b, zero)), tb_sin = hn::Sqrt(sin2_b);
  const Vec3<VD> wi = d / hn::Sqrt(d2);
  VD cos_w = dot(axis, wi);
  cos_w = hn::IfThenElse(bvh_field(dd, table, node, kBvhTwoSided) != zero, hn::Abs(cos_w), cos_w);
  VD w_cos, w_sin, o_cos, o_sin, x_cos, x_sin, p_cos, p_sin;
  bvh_from_cos(dd, cos_w, w_cos, w_sin);
  bvh_from_cos(dd, bvh_field(dd, table, node, kBvhCosO), o_cos, o_sin);
  bvh_minus_clamped(dd, w_cos, w_sin, o_cos, o_sin, x_cos, x_sin);
  bvh_minus_clamped(dd, x_cos, x_sin, tb_cos, tb_sin, p_cos, p_sin);
  auto zero_imp = p_cos <= bvh_field(dd, table, node, kBvhCosE);
  VD imp = phi * p_cos / dist2;
  // The receiver, when the query has a normal.
  const auto has_n = hn::Not(hn::And(hn::And(n.x == zero, n.y == zero), n.z == zero));
  VD i_cos, i_sin, pi_cos, pi_sin;
  bvh_from_cos(dd, dot(n, -wi), i_cos, i_sin);
  bvh_minus_clamped(dd, i_cos, i_sin, tb_cos, tb_sin, pi_cos, pi_sin);
  zero_imp = hn::Or(zero_imp, hn::And(has_n, pi_cos <= zero));
  imp = hn::IfThenElse(has_n, imp * pi_cos, imp);
  zero_imp = hn::Or(zero_imp, hn::Not(imp >= zero));
  const VD outside_imp = hn::IfThenZeroElse(zero_imp, finite_or_max(imp));
  return hn::IfThenElse(inside, inside_imp, outside_imp);
}

// LightBvh::split: the first child's part of `count` points (a whole
// number in a double), valid where both importances are not 0.
template <class DD, class VD = hn::Vec<DD>>
HWY_INLINE VD bvh_split(DD dd, VD i0, VD i1, VD count, hn::Mask<DD>& valid) {
  const VD zero = hn::Zero(dd);
  i0 = hn::IfThenElseZero(i0 > zero, i0);
  i1 = hn::IfThenElseZero(i1 > zero, i1);
  const VD m = hn::Max(i1, i0);  // std::max(i0, i1)
  valid = m > zero;
  const VD a = i0 / m, b = i1 / m;
  const VD first = hn::Floor(count * (a / (a + b)) + hn::Set(dd, 0.5));
  return hn::IfThenElse(count < first, count, first);  // std::min(first, count)
}

}  // namespace pathlab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // PATHLAB_CORE_SIMD_LIGHT_BVH_INL_H_ toggle
