// The light BVH's walks (LightBvh::pick and share, core/light_bvh.h) and
// the steps they take at each node (importance, LightBvh::split), written
// once over double lanes: core's LightBvh calls them at width 1 through
// lane1 (core/simd/width1.h), the wavefront's vectorised stages at the
// width of their SIMD target, each lane walking its own path down the tree.
// IEEE double + - * / sqrt and floor in one order, std::max(a, b) as
// Max(b, a), the clamps and comparisons as selects; VectorStages.* holds the
// lanes to the width-1 bits.
//
// The walks read the tree through a Tree (BvhTable below: the lanes gather
// LightBvh::node_table(), kBvhFields doubles per node; core reads its
// nodes), by node index (int64 lanes). Operations are called unqualified (see
// core/simd/lanes-inl.h); the descriptors are passed in: dd for the
// doubles, di for the node indices (int64), du for the lights' trails
// (uint64).
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

// std::clamp(c, -1, 1), then {c, sqrt(max(0, 1 - c c))} (from_cos).
template <class DD, class VD = VecOf<DD>>
HWY_INLINE void bvh_from_cos(DD dd, VD c, VD& cos, VD& sin) {
  const VD one = Set(dd, 1.0), minus_one = Set(dd, -1.0);
  c = IfThenElse(c < minus_one, minus_one, IfThenElse(one < c, one, c));
  cos = c;
  sin = Sqrt(Max(one - c * c, Zero(dd)));
}
// minus_clamped: cos and sin of max(0, a - b).
template <class DD, class VD = VecOf<DD>>
HWY_INLINE void bvh_minus_clamped(DD dd, VD a_cos, VD a_sin, VD b_cos, VD b_sin, VD& cos, VD& sin) {
  const auto le = a_cos >= b_cos;
  cos = IfThenElse(le, Set(dd, 1.0), a_cos * b_cos + a_sin * b_sin);
  sin = IfThenElseZero(Not(le), a_sin * b_cos - a_cos * b_sin);
}

// One node's bounds, as doubles (LightBounds' fields; two_sided a mask).
template <class VD, class MD>
struct BvhBounds {
  Vec3<VD> lo, hi, axis;
  VD cos_o, cos_e, phi;
  MD two_sided;
};

// importance(b, {p, n}) (core/light_bvh.h gives the formula): n = 0 (every
// lane's, has_n false) for a query without a normal.
template <class DD, class VD, class MD>
HWY_INLINE VD bvh_importance(DD dd, const BvhBounds<VD, MD>& b, const Vec3<VD>& p, const Vec3<VD>& n) {
  const VD zero = Zero(dd), half_ = Set(dd, 0.5);
  const Vec3<VD> c = half_ * (b.lo + b.hi);
  const Vec3<VD> half = half_ * (b.hi - b.lo);
  const VD r2 = dot(half, half);
  const Vec3<VD> d = p - c;  // centre -> shading point
  const VD d2 = dot(d, d);
  // std::max({d2, r2 / 4, DBL_MIN}): the first largest.
  VD dist2 = d2;
  dist2 = IfThenElse(dist2 < Set(dd, 0.25) * r2, Set(dd, 0.25) * r2, dist2);
  dist2 = IfThenElse(dist2 < Set(dd, DBL_MIN), Set(dd, DBL_MIN), dist2);
  auto finite_or_max = [&](VD v) { return IfThenElse(IsFinite(v), v, Set(dd, DBL_MAX)); };
  // Inside the bounding sphere every direction is possible (theta_b = pi):
  // the cone and the surface's side cannot rule anything out; phi / d^2.
  const auto inside = Not(d2 > r2);
  const VD inside_imp = finite_or_max(b.phi / dist2);
  if (AllTrue(dd, inside)) return inside_imp;  // (the scalar walk's early returns: the same values)

  const VD sin2_b = r2 / d2;
  const VD tb_cos = Sqrt(Max(Set(dd, 1.0) - sin2_b, zero)), tb_sin = Sqrt(sin2_b);
  const Vec3<VD> wi = d / Sqrt(d2);
  // The emitters: the smallest angle between a normal in the cone and a
  // direction from the box to the point.
  VD cos_w = dot(b.axis, wi);
  cos_w = IfThenElse(b.two_sided, Abs(cos_w), cos_w);
  VD w_cos, w_sin, o_cos, o_sin, x_cos, x_sin, p_cos, p_sin;
  bvh_from_cos(dd, cos_w, w_cos, w_sin);
  bvh_from_cos(dd, b.cos_o, o_cos, o_sin);
  bvh_minus_clamped(dd, w_cos, w_sin, o_cos, o_sin, x_cos, x_sin);
  bvh_minus_clamped(dd, x_cos, x_sin, tb_cos, tb_sin, p_cos, p_sin);
  auto zero_imp = p_cos <= b.cos_e;
  if (AllTrue(dd, Or(inside, zero_imp))) return IfThenElseZero(inside, inside_imp);
  VD imp = b.phi * p_cos / dist2;
  // The receiver, when the query has a normal: the smallest angle between
  // its normal and a direction to the box.
  const auto has_n = Not(And(And(n.x == zero, n.y == zero), n.z == zero));
  VD i_cos, i_sin, pi_cos, pi_sin;
  bvh_from_cos(dd, dot(n, -wi), i_cos, i_sin);
  bvh_minus_clamped(dd, i_cos, i_sin, tb_cos, tb_sin, pi_cos, pi_sin);
  zero_imp = Or(zero_imp, And(has_n, pi_cos <= zero));
  imp = IfThenElse(has_n, imp * pi_cos, imp);
  zero_imp = Or(zero_imp, Not(imp >= zero));
  const VD outside_imp = IfThenZeroElse(zero_imp, finite_or_max(imp));
  return IfThenElse(inside, inside_imp, outside_imp);
}

// The tree as the walks below read it, from LightBvh::node_table() by
// gathers (the wavefront's lanes). A walk asks a tree three things of each
// lane's node (an int64 index): its importance for {p, n}, whether it is a
// leaf (not 0) and its index (the light of a leaf, the second child of an
// interior node), the last two as doubles. core's LightBvh answers them from
// its nodes at width 1 (core/light_bvh.cpp), with the same bits: the table
// holds the nodes' floats as doubles.
template <class DD, class DI>
struct BvhTable {
  DD dd;
  DI di;
  const double* table;
  using VD = VecOf<DD>;
  using VI = VecOf<DI>;
  // Field f of each lane's node (0 for a lane off the walk).
  VD field(VI node, int f) const { return GatherIndex(dd, table, node * Set(di, kBvhFields) + Set(di, f)); }
  VD importance(VI node, const Vec3<VD>& p, const Vec3<VD>& n) const {
    auto field3 = [&](int f) { return Vec3<VD>{field(node, f), field(node, f + 1), field(node, f + 2)}; };
    const BvhBounds<VD, decltype(p.x == p.x)> b{field3(kBvhLo),
                                                field3(kBvhHi),
                                                field3(kBvhAxis),
                                                field(node, kBvhCosO),
                                                field(node, kBvhCosE),
                                                field(node, kBvhPhi),
                                                field(node, kBvhTwoSided) != Zero(dd)};
    return bvh_importance(dd, b, p, n);
  }
  VD leaf(VI node) const { return field(node, kBvhLeaf); }
  VD index(VI node) const { return field(node, kBvhIndex); }
};

// LightBvh::split: the first child's part of `count` points (a whole
// number in a double), valid where both importances are not 0.
template <class DD, class VD, class MD>
HWY_INLINE VD bvh_split(DD dd, VD i0, VD i1, VD count, MD& valid) {
  const VD zero = Zero(dd);
  i0 = IfThenElseZero(i0 > zero, i0);
  i1 = IfThenElseZero(i1 > zero, i1);
  const VD m = Max(i1, i0);  // std::max(i0, i1)
  valid = m > zero;
  const VD a = i0 / m, b = i1 / m;  // in [0, 1], one of them 1: the sum cannot overflow
  const VD first = Floor(count * (a / (a + b)) + Set(dd, 0.5));
  return IfThenElse(count < first, count, first);  // std::min(first, count)
}

// One level of a walk down the tree: for the lanes of ok still above a leaf
// (`walking`), their children c0 and c1 and the first child's part of
// `count`; a walking lane whose children both have importance 0 leaves ok.
// False when no lane walks.
template <class VD, class VI, class MD>
struct BvhLevel {
  MD walking;
  VI c0, c1;
  VD first;
};
template <class DD, class DI, class Tree, class VD, class VI, class MD>
HWY_INLINE bool bvh_level(DD dd, DI di, const Tree& tree, const Vec3<VD>& p, const Vec3<VD>& n, VI node, VD count,
                          MD& ok, BvhLevel<VD, VI, MD>& level) {
  level.walking = AndNot(tree.leaf(node) != Zero(dd), ok);
  if (AllFalse(dd, level.walking)) return false;
  level.c0 = node + Set(di, 1);
  level.c1 = IfThenElse(RebindMask(di, level.walking), ConvertTo(di, tree.index(node)), level.c0);
  MD valid;
  level.first = bvh_split(dd, tree.importance(level.c0, p, n), tree.importance(level.c1, p, n), count, valid);
  ok = AndNot(AndNot(valid, level.walking), ok);
  return true;
}

// LightBvh::pick for the lanes of `active`: the light grid point k (of
// `count`; whole numbers in doubles) leads to, and its share (0 where the
// walk ends on two children of importance 0, or the root has none).
template <class DD, class DI, class Tree, class VD, class MD>
HWY_INLINE void bvh_pick(DD dd, DI di, const Tree& tree, const Vec3<VD>& p, const Vec3<VD>& n, VD k, VD count,
                         MD active, VD& light, VD& share) {
  using VI = VecOf<DI>;
  VI node = Zero(di);
  MD ok = And(active, tree.importance(node, p, n) > Zero(dd));
  for (BvhLevel<VD, VI, MD> l; bvh_level(dd, di, tree, p, n, node, count, ok, l);) {
    const MD to_first = And(l.walking, k < l.first), to_second = AndNot(k < l.first, l.walking);
    node = IfThenElse(RebindMask(di, to_first), l.c0, IfThenElse(RebindMask(di, to_second), l.c1, node));
    k = IfThenElse(to_second, k - l.first, k);  // re-based to the second child's part
    count = IfThenElse(to_first, l.first, IfThenElse(to_second, count - l.first, count));
  }
  light = tree.index(node);
  share = IfThenElseZero(ok, count);
}

// LightBvh::share for the lanes of `active`: the grid points (of `count`)
// that lead to `light`, down the light's trail (LightBvh::trails(); bit d
// set: the second child at depth d).
template <class DD, class DI, class DU, class Tree, class VD, class MD>
HWY_INLINE VD bvh_share(DD dd, DI di, DU du, const Tree& tree, const std::uint64_t* trails, const Vec3<VD>& p,
                        const Vec3<VD>& n, VD light, VD count, MD active) {
  using VI = VecOf<DI>;
  const VI light_index = IfThenElseZero(RebindMask(di, active), ConvertTo(di, light));
  auto trail = GatherIndex(du, trails, light_index);
  VI node = Zero(di);
  MD ok = And(active, tree.importance(node, p, n) > Zero(dd));
  for (BvhLevel<VD, VI, MD> l; bvh_level(dd, di, tree, p, n, node, count, ok, l);) {
    const MD second = RebindMask(dd, And(trail, Set(du, 1)) != Zero(du));
    const MD to_first = AndNot(second, l.walking), to_second = And(l.walking, second);
    node = IfThenElse(RebindMask(di, to_first), l.c0, IfThenElse(RebindMask(di, to_second), l.c1, node));
    count = IfThenElse(to_first, l.first, IfThenElse(to_second, count - l.first, count));
    ok = AndNot(And(l.walking, count == Zero(dd)), ok);
    trail = IfThenElse(RebindMask(du, l.walking), ShiftRight<1>(trail), trail);
  }
  return IfThenElseZero(ok, count);
}

}  // namespace pathlab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // PATHLAB_CORE_SIMD_LIGHT_BVH_INL_H_ toggle
