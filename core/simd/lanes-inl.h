// Geometry, hashing and weighting steps of the estimator over Highway's
// vectors, for the wavefront's vectorised stages at the width of their SIMD
// target (wavefront/vector_stages.cpp), and for core's scalar code at width
// 1 through core/simd/lane1.h (core/simd/width1.h): each names the scalar
// function of core that calls it or that it mirrors. The operations are
// called unqualified and the vector type is VecOf<D>, so that argument-
// dependent lookup finds Highway's for its vectors and lane1's for lane1's.
// VectorStages.* and tests/test_simd.cpp hold the lanes to the width-1
// bits; the rules that make every lane compute them are in
// core/simd/simd.h and docs/one-estimator.md. In short: the order of every
// sum and product is the scalar code's (GLM's dot is (x + y) + z, a vec3
// times a float multiplies each component), no fused multiply-add, and
// std::max(a, b) is Max(b, a) (x86's max returns its second operand for
// a NaN or for -0 against +0, std::max its first).
//
// Highway's "-inl.h" convention: no include guard but the toggle below.
#if defined(PATHLAB_CORE_SIMD_LANES_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef PATHLAB_CORE_SIMD_LANES_INL_H_
#undef PATHLAB_CORE_SIMD_LANES_INL_H_
#else
#define PATHLAB_CORE_SIMD_LANES_INL_H_
#endif

#include <hwy/highway.h>

#include "core/math.h"
#include "core/scene.h"
#include "core/simd/lane1.h"
#include "core/sobol.h"

#include <cmath>
#include <cstdint>
#include <limits>

HWY_BEFORE_NAMESPACE();
namespace pathlab::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// A vec3 per lane.
template <class V>
struct Vec3 {
  V x, y, z;
};
template <class D, class V = VecOf<D>>
HWY_INLINE Vec3<V> splat3(D d, float x, float y, float z) {
  return {Set(d, x), Set(d, y), Set(d, z)};
}
template <class V>
HWY_INLINE Vec3<V> operator+(const Vec3<V>& a, const Vec3<V>& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class V>
HWY_INLINE Vec3<V> operator-(const Vec3<V>& a, const Vec3<V>& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class V>
HWY_INLINE Vec3<V> operator*(const Vec3<V>& a, const Vec3<V>& b) {
  return {a.x * b.x, a.y * b.y, a.z * b.z};
}
// s * v and v * s round alike (IEEE multiplication commutes).
template <class V>
HWY_INLINE Vec3<V> operator*(V s, const Vec3<V>& a) {
  return {s * a.x, s * a.y, s * a.z};
}
// Each component divided (GLM's vec3 / float), not a reciprocal multiplied.
template <class V>
HWY_INLINE Vec3<V> operator/(const Vec3<V>& a, V s) {
  return {a.x / s, a.y / s, a.z / s};
}
template <class V>
HWY_INLINE Vec3<V> operator-(const Vec3<V>& a) {
  return {Neg(a.x), Neg(a.y), Neg(a.z)};
}
template <class V>
HWY_INLINE Vec3<V> abs(const Vec3<V>& a) {
  return {Abs(a.x), Abs(a.y), Abs(a.z)};
}
template <class M, class V>
HWY_INLINE Vec3<V> select(M m, const Vec3<V>& yes, const Vec3<V>& no) {
  return {IfThenElse(m, yes.x, no.x), IfThenElse(m, yes.y, no.y), IfThenElse(m, yes.z, no.z)};
}
template <class M, class V>
HWY_INLINE Vec3<V> zero_unless(M m, const Vec3<V>& a) {
  return {IfThenElseZero(m, a.x), IfThenElseZero(m, a.y), IfThenElseZero(m, a.z)};
}
// glm::dot: (x x' + y y') + z z'.
template <class V>
HWY_INLINE V dot(const Vec3<V>& a, const Vec3<V>& b) {
  return (a.x * b.x + a.y * b.y) + a.z * b.z;
}
// glm::cross: (a.y b.z - b.y a.z, a.z b.x - b.z a.x, a.x b.y - b.x a.y).
template <class V>
HWY_INLINE Vec3<V> cross(const Vec3<V>& a, const Vec3<V>& b) {
  return {a.y * b.z - b.y * a.z, a.z * b.x - b.z * a.x, a.x * b.y - b.x * a.y};
}
// glm::normalize: v * (1 / sqrt(v.v)).
template <class D, class V = VecOf<D>>
HWY_INLINE Vec3<V> normalize(D d, const Vec3<V>& v) {
  return (Set(d, 1.0f) / Sqrt(dot(v, v))) * v;
}
template <class D, class V = VecOf<D>>
HWY_INLINE auto is_black(D d, const Vec3<V>& a) {
  const V zero = Zero(d);
  return And(And(a.x == zero, a.y == zero), a.z == zero);
}

// next_float_up / next_float_down (core/ray.h): the neighbouring float away
// from (up) or towards minus infinity; NaN and the infinity in that
// direction stay, 0 (either sign) becomes +-denorm_min.
template <bool kUp, class D, class V = VecOf<D>>
HWY_INLINE V NextFloat(D d, V v) {
  const hn::RebindToSigned<D> di;
  const auto bits = BitCast(di, v);
  const auto one = Set(di, 1);
  const auto positive = RebindMask(di, v > Zero(d));
  const auto away = bits + one, toward = bits - one;
  auto r = kUp ? IfThenElse(positive, away, toward) : IfThenElse(positive, toward, away);
  r = IfThenElse(RebindMask(di, v == Zero(d)), Set(di, kUp ? 1 : INT32_MIN + 1), r);
  const V inf = Set(d, kUp ? HUGE_VALF : -HUGE_VALF);
  const auto keep = Or(IsNaN(v), v == inf);
  return IfThenElse(keep, v, BitCast(d, r));
}

// c moved one float in the direction of o's sign: up for o > 0, down for
// o < 0, unchanged for 0 or NaN. A primitive, like Highway's operations:
// lane1 (core/simd/lane1.h) has its own, core/ray.h's branches (cheaper at
// width 1 than computing both neighbours), which overload resolution
// prefers for its lanes; tests/test_simd.cpp holds the two to one set of bits.
template <class D, class V = VecOf<D>>
HWY_INLINE V StepAway(D d, V c, V o) {
  return IfThenElse(o > Zero(d), NextFloat<true>(d, c), IfThenElse(o < Zero(d), NextFloat<false>(d, c), c));
}

// 2^n for a whole n in [-126, 127]: the float whose exponent field is
// n + 127. A primitive: lane1 has its own (ldexp); both are exact.
template <class D, class V = VecOf<D>>
HWY_INLINE V Pow2I(D d, V n) {
  const hn::RebindToSigned<D> di;
  return BitCast(d, hn::ShiftLeft<23>(hn::ConvertTo(di, n) + Set(di, 127)));
}

// x = m 2^e with m in [1, 2) and e whole, for a positive normal float x
// (0, subnormals, infinities and NaN are outside: callers keep them out);
// returns m, e in `e`. Both exact. A primitive: lane1 has its own (frexp).
template <class D, class V = VecOf<D>>
HWY_INLINE V SplitExponent(D d, V x, V& e) {
  const hn::RebindToSigned<D> di;
  const auto bits = BitCast(di, x);
  e = hn::ConvertTo(d, hn::ShiftRight<23>(bits) - Set(di, 127));
  return BitCast(d, hn::Or(hn::And(bits, Set(di, 0x007fffff)), Set(di, 0x3f800000)));
}

// fn(dd, a, b) computed in double lanes (dd a descriptor of doubles) for two
// vec3s of float lanes, the result rounded to float once: for the few steps
// that need double's precision (microfacet-inl.h's half_vector). A
// primitive: here each half of the float lanes in turn, promoted exactly;
// lane1's below, one double.
#if HWY_TARGET == HWY_SCALAR
// Highway's one-lane target has no halves: its one float promoted.
template <class D, class Fn, class V = VecOf<D>>
HWY_INLINE Vec3<V> InDouble3(D d, Fn&& fn, const Vec3<V>& a, const Vec3<V>& b) {
  const hn::Rebind<double, D> dd;
  const auto wide = [&](const Vec3<V>& v) {
    return Vec3<VecOf<decltype(dd)>>{hn::PromoteTo(dd, v.x), hn::PromoteTo(dd, v.y), hn::PromoteTo(dd, v.z)};
  };
  const auto r = fn(dd, wide(a), wide(b));
  return {hn::DemoteTo(d, r.x), hn::DemoteTo(d, r.y), hn::DemoteTo(d, r.z)};
}
#else
template <class D, class Fn, class V = VecOf<D>>
HWY_INLINE Vec3<V> InDouble3(D d, Fn&& fn, const Vec3<V>& a, const Vec3<V>& b) {
  const hn::Half<D> dh;
  const hn::Rebind<double, decltype(dh)> dd;
  const auto half = [&](const Vec3<V>& v, bool upper) {
    const auto wide = [&](V x) { return hn::PromoteTo(dd, upper ? hn::UpperHalf(dh, x) : hn::LowerHalf(dh, x)); };
    return Vec3<VecOf<decltype(dd)>>{wide(v.x), wide(v.y), wide(v.z)};
  };
  const auto lo = fn(dd, half(a, false), half(b, false));
  const auto hi = fn(dd, half(a, true), half(b, true));
  const auto narrow = [&](VecOf<decltype(dd)> l, VecOf<decltype(dd)> h) {
    return hn::Combine(d, hn::DemoteTo(dh, h), hn::DemoteTo(dh, l));
  };
  return {narrow(lo.x, hi.x), narrow(lo.y, hi.y), narrow(lo.z, hi.z)};
}
#endif
// lane1's InDouble3: one double each, the result rounded to float once.
template <class Fn>
HWY_INLINE Vec3<lane1::V<float>> InDouble3(lane1::One<float>, Fn&& fn, const Vec3<lane1::V<float>>& a,
                                           const Vec3<lane1::V<float>>& b) {
  using F1 = lane1::V<float>;
  using D1 = lane1::V<double>;
  const auto wide = [](const Vec3<F1>& v) { return Vec3<D1>{{v.x.raw}, {v.y.raw}, {v.z.raw}}; };
  const Vec3<D1> r = fn(lane1::One<double>{}, wide(a), wide(b));
  return {{static_cast<float>(r.x.raw)}, {static_cast<float>(r.y.raw)}, {static_cast<float>(r.z.raw)}};
}

// offset_ray_origin (core/ray.h): p moved off its surface along n by its
// rounding error bound across the surface, then one float further.
template <class D, class V = VecOf<D>>
HWY_INLINE Vec3<V> offset_ray_origin(D d, const Vec3<V>& p, const Vec3<V>& error, const Vec3<V>& n) {
  V dist = dot(abs(n), error);
  // No error across the surface (every vertex on a coordinate plane through
  // the origin): one float of the largest coordinate, at least 2^-100.
  // std::max(std::max(|x|, std::max(|y|, |z|)) * 2^-23, 2^-100), in Max's order.
  const Vec3<V> a = abs(p);
  const V largest = Max(Max(a.z, a.y), a.x);
  dist = IfThenElse(dist == Zero(d), Max(Set(d, 0x1p-100f), largest * Set(d, 0x1p-23f)), dist);
  const Vec3<V> offset = dist * n;
  const Vec3<V> po = p + offset;
  return {StepAway(d, po.x, offset.x), StepAway(d, po.y, offset.y), StepAway(d, po.z, offset.z)};
}

// Frame(n) (core/math.h): the tangents s and t of Duff et al.'s
// orthonormal basis about the unit normal n.
template <class D, class V = VecOf<D>>
HWY_INLINE void frame(D d, const Vec3<V>& n, Vec3<V>& s, Vec3<V>& t) {
  const V sign = CopySign(Set(d, 1.0f), n.z);
  const V a = Set(d, -1.0f) / (sign + n.z);
  const V b = n.x * n.y * a;
  s = {Set(d, 1.0f) + sign * n.x * n.x * a, sign * b, Neg(sign) * n.x};
  t = {b, sign + n.y * n.y * a, Neg(n.y)};
}
// Frame::to_local: v's coordinates (v.s, v.t, v.n).
template <class V>
HWY_INLINE Vec3<V> to_local(const Vec3<V>& s, const Vec3<V>& t, const Vec3<V>& n, const Vec3<V>& v) {
  return {dot(v, s), dot(v, t), dot(v, n)};
}
// Frame::to_world: s x + t y + n z.
template <class V>
HWY_INLINE Vec3<V> to_world(const Vec3<V>& s, const Vec3<V>& t, const Vec3<V>& n, V x, V y, V z) {
  return (x * s + y * t) + z * n;
}

// Surfel's local directions for its two-sided reflection models
// (to_local_upper, core/surfel.cpp): wo and wi in the frame (s, t, n),
// both flipped about the tangent plane where wo is below it, so that wo is
// on +z.
template <class D, class V = VecOf<D>>
HWY_INLINE void to_local_upper(D d, const Vec3<V>& s, const Vec3<V>& t, const Vec3<V>& n, const Vec3<V>& wo,
                               const Vec3<V>& wi, Vec3<V>& wo_local, Vec3<V>& wi_local) {
  wo_local = to_local(s, t, n, wo);
  wi_local = to_local(s, t, n, wi);
  const auto below = wo_local.z < Zero(d);
  wo_local.z = IfThenElse(below, Neg(wo_local.z), wo_local.z);
  wi_local.z = IfThenElse(below, Neg(wi_local.z), wi_local.z);
}

// Whether a and b (two directions' dot products with one normal) have
// opposite signs: (a < 0) != (b < 0).
template <class D, class V = VecOf<D>>
HWY_INLINE auto opposite_sides(D d, V a, V b) {
  const auto below_a = a < Zero(d), below_b = b < Zero(d);
  return Or(And(below_a, Not(below_b)), And(below_b, Not(below_a)));
}
// Surfel's shading-normal rule (surface_eval_ok, scattered_side_ok below): under a shading normal, a reflection
// needs wi and wo on one side of the geometric surface (wi_z wo_z > 0), a
// transmission opposite sides, neither in it (wi_z, wo_z: their dot products
// with the geometric normal).
template <class D, class M, class V = VecOf<D>>
HWY_INLINE M geometric_side_ok(D d, M transmission, V wi_z, V wo_z) {
  const M across = And(opposite_sides(d, wi_z, wo_z), And(Not(wi_z == Zero(d)), Not(wo_z == Zero(d))));
  return Or(And(transmission, across), And(Not(transmission), wi_z * wo_z > Zero(d)));
}

// Surfel's rules around the BSDFs (core/surfel.cpp), for both tracers:
// wo_z, wi_z are wo's and wi's dot products with the geometric normal, wo_fz
// wo's with the shading frame's.
//
// Surfel::eval (and the light sample's f): nothing unless wo and wi both
// leave the front of a one-sided surface, and, under a shading normal,
// unless they are on one geometric side (a reflection: no lobe evaluated
// transmits).
template <class D, class M, class V = VecOf<D>>
HWY_INLINE M surface_eval_ok(D d, M one_sided, M shading_normal, V wo_z, V wi_z) {
  const M front = And(wo_z > Zero(d), wi_z > Zero(d));
  const M no_transmission = AndNot(shading_normal, shading_normal);
  return And(Or(Not(one_sided), front), Or(Not(shading_normal), geometric_side_ok(d, no_transmission, wi_z, wo_z)));
}
// Surfel::scatter before the BSDF draws: nothing from the back of a
// one-sided surface, nor from a dielectric under a shading normal where wo
// is on different sides of its two normals (it tells inside from outside by
// wo's side).
template <class D, class M, class V = VecOf<D>>
HWY_INLINE M surface_scatter_ok(D d, M one_sided, M dielectric_shading_normal, V wo_z, V wo_fz) {
  return And(Or(Not(one_sided), wo_z > Zero(d)), Not(And(dielectric_shading_normal, opposite_sides(d, wo_z, wo_fz))));
}
// Surfel::scatter after the draw: under a shading normal, wi on wo's
// geometric side, or across it where the draw transmitted.
template <class D, class M, class V = VecOf<D>>
HWY_INLINE M scattered_side_ok(D d, M shading_normal, M transmitted, V wo_z, V wi_z) {
  return Or(Not(shading_normal), geometric_side_ok(d, transmitted, wi_z, wo_z));
}
// The side the reflection models see wo from: -1 where it is below the
// shading frame (wo_fz < 0), which they flip to +z, else 1.
template <class D, class V = VecOf<D>>
HWY_INLINE V upper_side(D d, V wo_fz) {
  return IfThenElse(wo_fz < Zero(d), Set(d, -1.0f), Set(d, 1.0f));
}
// A mixture's draw is usable where its density is > 0 and not below the
// material's min_pdf (Surfel::scatter of a Disney closure).
template <class D, class V = VecOf<D>>
HWY_INLINE auto usable_bsdf_pdf(D d, V pdf, V min_pdf) {
  return And(pdf > Zero(d), Not(pdf < min_pdf));
}

// Surfel::emitted: the emission Le towards wo, 0 behind a one-sided
// emitter (n the geometric normal).
template <class D, class M, class V = VecOf<D>>
HWY_INLINE Vec3<V> emitted_towards(D d, M two_sided, const Vec3<V>& n, const Vec3<V>& wo, const Vec3<V>& Le) {
  return zero_unless(Or(two_sided, dot(n, wo) > Zero(d)), Le);
}

// power_heuristic (core/sampling.h): a^2 / (a^2 + b^2) through the ratio;
// 1 for an infinite a (a delta), 0 unless a > 0.
template <class D, class V = VecOf<D>>
HWY_INLINE V power_heuristic(D d, V a, V b) {
  const V r = b / a;
  const V w = Set(d, 1.0f) / (Set(d, 1.0f) + r * r);
  return IfThenElse(IsInf(a), Set(d, 1.0f), IfThenElseZero(a > Zero(d), w));
}

// emission_weight (core/strategy_weights.h): how much of the emission a ray
// found `strategy` keeps, given how the vertex before chose the ray
// (`impulse`: a camera ray or an impulse, 1; `bsdf_technique`: light+bsdf
// chose BSDF sampling; `prev_pdf` its solid-angle density) and the density
// with which next-event estimation would have sampled the emitter. The
// strategy is the render's, the same in every lane.
template <class D, class M, class V = VecOf<D>>
HWY_INLINE V emission_weight(D d, Strategy strategy, M impulse, M bsdf_technique, V prev_pdf, V light_pdf) {
  V weight = Set(d, 1.0f);  // cosine, bsdf
  // light: 0 (NEE counted it) unless NEE could not pick it.
  if (strategy == Strategy::Light) weight = IfThenElse(light_pdf > Zero(d), Zero(d), Set(d, 1.0f));
  if (strategy == Strategy::Mis) weight = power_heuristic(d, prev_pdf, light_pdf);
  // light+bsdf, the one-sample balance heuristic: f / (p_b / 2 + p_l / 2) =
  // (f / p_b) 2 p_b / (p_b + p_l) after BSDF sampling, 0 after light sampling.
  if (strategy == Strategy::LightBsdf)
    weight = IfThenElseZero(bsdf_technique, Set(d, 2.0f) * prev_pdf / (prev_pdf + light_pdf));
  return IfThenElse(impulse, Set(d, 1.0f), weight);
}

// light_sample_weight (core/strategy_weights.h): how much of a light sample
// (next-event estimation) `strategy` keeps.
template <class D, class V = VecOf<D>>
HWY_INLINE V light_sample_weight(D d, Strategy strategy, V light_pdf, V bsdf_pdf) {
  if (strategy == Strategy::Mis) return power_heuristic(d, light_pdf, bsdf_pdf);
  if (strategy == Strategy::LightBsdf) return Set(d, 2.0f) * light_pdf / (light_pdf + bsdf_pdf);
  return Set(d, 1.0f);
}

// What a light sample brings if its shadow ray arrives (next-event
// estimation), from the BSDF value f and the radiance Le: a delta light's
// f Le / pdf (pdf the pick's probability), an area light's f Le (w / pdf),
// w the strategy's weight (light_sample_weight).
template <class V>
HWY_INLINE Vec3<V> delta_light_contribution(const Vec3<V>& f, const Vec3<V>& Le, V pdf) {
  return (f * Le) / pdf;
}
template <class V>
HWY_INLINE Vec3<V> light_contribution(const Vec3<V>& f, const Vec3<V>& Le, V weight, V pdf) {
  return (weight / pdf) * (f * Le);
}

// Russian roulette's survival (roulette, below; core/strategy_weights.h): the
// probability for a path whose throughput would become `throughput`,
// std::min(1, max_component(throughput)) in Min's and Max's order.
template <class D, class V = VecOf<D>>
HWY_INLINE V roulette_survival(D d, const Vec3<V>& throughput) {
  return Min(Max(Max(throughput.z, throughput.y), throughput.x), Set(d, 1.0f));
}
// Russian roulette after a scatter, in the lanes of m where it applies (the
// path is past rr_depth; the caller draws u, Dim::Roulette, only there): a
// path whose throughput would become beta weight goes on where
// u < survival = roulette_survival(beta weight), and a survivor's weight is
// divided by survival, which keeps the estimate unbiased. Returns the lanes
// of m that go on; the others keep their weight (the observers report it).
template <class D, class M, class V = VecOf<D>>
HWY_INLINE M roulette(D d, M m, const Vec3<V>& beta, V u, Vec3<V>& weight, V& survival) {
  survival = roulette_survival(d, beta * weight);
  const M survives = And(m, u < survival);
  weight = select(survives, weight / survival, weight);
  return survives;
}

// Light+bsdf's one-sample choice of technique at a vertex, by its
// Dim::Technique number u: light sampling where u < 1/2, BSDF sampling
// elsewhere (the weights above take c = 1/2).
template <class D, class V = VecOf<D>>
HWY_INLINE auto chooses_light_technique(D d, V u) {
  return u < Set(d, 0.5f);
}

// The strategy's dispatch at a vertex, in the lanes of m: the lanes that
// sample area lights (next-event estimation), all of m under light and mis,
// under light+bsdf those whose Dim::Technique number chooses light sampling,
// none under bsdf and cosine. u_technique() draws that number; it is asked
// only under light+bsdf, the one strategy it decides anything for (under
// zsobol a draw costs a permutation of the Sobol' index).
template <class D, class M, class Draw>
HWY_INLINE M samples_area_lights(D d, Strategy strategy, M m, const Draw& u_technique) {
  switch (strategy) {
    case Strategy::Light:
    case Strategy::Mis:
      return m;
    case Strategy::LightBsdf:
      return And(m, chooses_light_technique(d, u_technique()));
    case Strategy::Bsdf:
    case Strategy::Cosine:
      break;
  }
  return AndNot(m, m);
}
// The lanes of m whose continuation counts as BSDF sampling for the emitter
// it finds (PreviousVertex::bsdf_technique, emission_weight): all of m but
// where light+bsdf chose light sampling (u_technique() as above).
template <class D, class M, class Draw>
HWY_INLINE M chose_bsdf_technique(D d, Strategy strategy, M m, const Draw& u_technique) {
  if (strategy != Strategy::LightBsdf) return m;
  return AndNot(chooses_light_technique(d, u_technique()), m);
}

// area_to_solid_angle (core/sampling.h): pdf_area d^2 / |cos|, 0 edge-on.
template <class D, class V = VecOf<D>>
HWY_INLINE V area_to_solid_angle(D d, V pdf_area, V dist, V cos_light) {
  const V c = Abs(cos_light);
  return IfThenElseZero(c > Zero(d), pdf_area * dist * dist / c);
}

// A point of a triangle from barycentrics b1, b2 and the bound by which a
// ray leaving it must move off the triangle (triangle_point,
// core/geometry.cpp): b0 = (1 - b1) - b2, p = (b0 p0 + b1 p1) + b2 p2, and
// per axis its rounding error gamma(7) ((|b0 p0| + |b1 p1|) + |b2 p2|)
// plus gamma(8) times its largest distance to a vertex. The second term is
// Embree's: its triangle test (tnear = 0) tells an origin from the plane by
// the vertices taken relative to that origin, rounded within a few ulps of
// |v - o|, so an origin nearer its own triangle than that can hit it again.
// Where the vertices' coordinates are small next to the triangle (an edge
// on a coordinate axis: the point's own error is about 0 across it), the
// first term alone let shadow rays hit their own triangle.
template <class D, class V = VecOf<D>>
HWY_INLINE void triangle_point(D d, V b1, V b2, const Vec3<V>& p0, const Vec3<V>& p1, const Vec3<V>& p2, Vec3<V>& p,
                               Vec3<V>& error) {
  const V b0 = Set(d, 1.0f) - b1 - b2;
  const Vec3<V> a0 = b0 * p0, a1 = b1 * p1, a2 = b2 * p2;
  p = (a0 + a1) + a2;
  const Vec3<V> r0 = abs(p0 - p), r1 = abs(p1 - p), r2 = abs(p2 - p);
  const Vec3<V> reach{Max(Max(r0.x, r1.x), r2.x), Max(Max(r0.y, r1.y), r2.y), Max(Max(r0.z, r1.z), r2.z)};
  error = Set(d, gamma_bound(7)) * ((abs(a0) + abs(a1)) + abs(a2)) + Set(d, gamma_bound(8)) * reach;
}

// An instance's placement (CompiledScene::resolve) is an affine map given by
// the columns c0, c1, c2 (its linear part) and c3 (its translation) of a
// GLM mat4, or a linear one by the columns of a mat3.
//
// The point p under it as GLM's mat4 * vec4(p, 1) rounds it:
// (c0 x + c1 y) + (c2 z + c3 1).
template <class V>
HWY_INLINE Vec3<V> affine_point(const Vec3<V>& c0, const Vec3<V>& c1, const Vec3<V>& c2, const Vec3<V>& c3,
                                const Vec3<V>& p) {
  return (p.x * c0 + p.y * c1) + (p.z * c2 + c3);
}
// transform_point (surface_point's placing): p placed, ((c0 x + c1 y) +
// c2 z) + c3, and its error bound grown by the placement's rounding (PBR 4th
// ed. 6.8.6): (gamma(3) + 1) (|c0| e.x + |c1| e.y + |c2| e.z) +
// gamma(3) (|c0 x| + |c1 y| + |c2 z| + |c3|).
template <class D, class V = VecOf<D>>
HWY_INLINE void transform_point(D d, const Vec3<V>& c0, const Vec3<V>& c1, const Vec3<V>& c2, const Vec3<V>& c3,
                                Vec3<V>& p, Vec3<V>& error) {
  const Vec3<V> a0 = p.x * c0, a1 = p.y * c1, a2 = p.z * c2, e = error;
  p = ((a0 + a1) + a2) + c3;
  error = Set(d, gamma_bound(3) + 1.0f) * ((e.x * abs(c0) + e.y * abs(c1)) + e.z * abs(c2)) +
          Set(d, gamma_bound(3)) * (((abs(a0) + abs(a1)) + abs(a2)) + abs(c3));
}
// A normal placed by the inverse transpose (columns c0, c1, c2) and made
// unit again: glm::normalize(to_normal * n).
template <class D, class V = VecOf<D>>
HWY_INLINE Vec3<V> place_normal(D d, const Vec3<V>& c0, const Vec3<V>& c1, const Vec3<V>& c2, const Vec3<V>& n) {
  return normalize(d, to_world(c0, c1, c2, n.x, n.y, n.z));
}
// The factor by which an instance's linear part L (columns c0, c1, c2; its
// inverse transpose's t0, t1, t2) scales the area of a surface whose unit
// normal is n in the group's space (Nanson's formula): |det L| |L^-T n|.
template <class V>
HWY_INLINE V placed_area_scale(const Vec3<V>& c0, const Vec3<V>& c1, const Vec3<V>& c2, const Vec3<V>& t0,
                               const Vec3<V>& t1, const Vec3<V>& t2, const Vec3<V>& n) {
  const Vec3<V> m = to_world(t0, t1, t2, n.x, n.y, n.z);
  return Abs(dot(c0, cross(c1, c2))) * Sqrt(dot(m, m));
}

// square_to_uniform_triangle (core/sampling.cpp): barycentrics (b1, b2) =
// (uy sqrt(ux), 1 - sqrt(ux)).
template <class D, class V = VecOf<D>>
HWY_INLINE void uniform_triangle(D d, V ux, V uy, V& b1, V& b2) {
  const V s = Sqrt(ux);
  b1 = uy * s;
  b2 = Set(d, 1.0f) - s;
}

// sphere_point (core/geometry.cpp): an approximate point of a sphere
// projected onto it, with its rounding error bound (PBR 6.8.4: a few ulps of
// the offset from the centre, plus the rounding of adding the centre back)
// and its normal (inwards where `flip`).
template <class D, class M, class V = VecOf<D>>
HWY_INLINE void sphere_point(D d, const Vec3<V>& center, V radius, M flip, const Vec3<V>& p_approx, Vec3<V>& p,
                             Vec3<V>& error, Vec3<V>& n) {
  const Vec3<V> dir = normalize(d, p_approx - center);
  const Vec3<V> offset = radius * dir;
  p = center + offset;
  error = Set(d, gamma_bound(5)) * abs(offset) + Set(d, gamma_bound(2)) * abs(p);
  n = select(flip, -dir, dir);
}

// CompiledScene::resolve's point of a hit in world space, with its error
// bound and front normal n: where `mesh`, triangle_point of the hit
// triangle at Embree's barycentrics (b1, b2), with the triangle's normal;
// where `sphere`, sphere_point of the ray's o + t dir, taken first into the
// group's space by the instance's to_local (affine_point) where `placed`:
// Embree found an instance's hit there, at the same t. Then, where
// `placed`, the point and its bound placed by to_world (transform_point)
// and the normal by the inverse transpose (place_normal: it keeps pointing
// to the image of its side, so the front stays the front under a mirroring
// placement too), whose columns `to_normal` returns (0 where no lane is
// placed). 0 in no mask's lanes.
// Called by CompiledScene::resolve at width 1 and the wavefront's resolve.
// The lookups, each asked only in the lanes of a mask m where some lane
// needs it: at.ray(m, o, dir, t) the ray and the hit's distance along it;
// at.triangle(m, p0, p1, p2, n) the triangle's corners and front normal
// (core's Triangle, in its group's space); at.sphere(m, center, radius)
// the sphere's, returning where it has flip_normals; at.to_local(m, c) and
// at.to_world(m, c) the columns c[0..3] of the placement's inverse and of
// the placement; at.to_normal(m, c) c[0..2] of its inverse transpose.
template <class D, class M, class Lookup, class V = VecOf<D>>
HWY_INLINE void surface_point(D d, M mesh, M sphere, M placed, V b1, V b2, const Lookup& at, Vec3<V>& p,
                              Vec3<V>& error, Vec3<V>& n, Vec3<V> (&to_normal)[3]) {
  p = error = n = splat3(d, 0.0f, 0.0f, 0.0f);
  if (!AllFalse(d, mesh)) {
    Vec3<V> p0, p1, p2;
    at.triangle(mesh, p0, p1, p2, n);
    triangle_point(d, b1, b2, p0, p1, p2, p, error);
  }
  if (!AllFalse(d, sphere)) {
    Vec3<V> o, dir;
    V t;
    at.ray(sphere, o, dir, t);
    Vec3<V> local = o + t * dir;
    if (const M in_group = And(sphere, placed); !AllFalse(d, in_group)) {
      Vec3<V> c[4];
      at.to_local(in_group, c);
      local = select(in_group, affine_point(c[0], c[1], c[2], c[3], local), local);
    }
    Vec3<V> center, sp, serr, sn;
    V radius;
    const M flipped = at.sphere(sphere, center, radius);
    sphere_point(d, center, radius, flipped, local, sp, serr, sn);
    p = select(sphere, sp, p);
    error = select(sphere, serr, error);
    n = select(sphere, sn, n);
  }
  for (Vec3<V>& c : to_normal) c = splat3(d, 0.0f, 0.0f, 0.0f);
  if (!AllFalse(d, placed)) {
    Vec3<V> c[4], pp = p, pe = error;
    at.to_world(placed, c);
    transform_point(d, c[0], c[1], c[2], c[3], pp, pe);
    at.to_normal(placed, to_normal);
    p = select(placed, pp, p);
    error = select(placed, pe, error);
    n = select(placed, place_normal(d, to_normal[0], to_normal[1], to_normal[2], n), n);
  }
}

// A mesh's vertex normals n0, n1, n2 blended by the barycentrics
// (b0, b1, b2) of a hit, b0 = (1 - b1) - b2 (shading_frame-inl.h's
// surface_frame): (b0 n0 + b1 n1) + b2 n2, not normalised.
template <class D, class V = VecOf<D>>
HWY_INLINE Vec3<V> blend_normals(D d, V b1, V b2, const Vec3<V>& n0, const Vec3<V>& n1, const Vec3<V>& n2) {
  const V b0 = Set(d, 1.0f) - b1 - b2;
  return (b0 * n0 + b1 * n1) + b2 * n2;
}

// scattered_cone (core/ray_cone.h): the ray cone (width at its origin,
// spread) leaving a hit at distance t after a scatter of density `pdf`: its
// width there, and the spread of the lobe, 2 sqrt(1 / (pi pdf)) capped at
// pi (pi where pdf is not positive), where that is wider and the scatter is
// not an impulse. (The point filter's zero cone is the caller's.)
template <class D, class M, class V = VecOf<D>>
HWY_INLINE void scattered_cone(D d, V width, V spread, V t, M impulse, V pdf, V& out_width, V& out_spread) {
  out_width = width + spread * t;
  const V pi = Set(d, kPi);
  const auto positive = pdf > Zero(d);
  const V lobe =
      IfThenElse(positive, Set(d, 2.0f) * Sqrt(Set(d, 1.0f) / (pi * IfThenElse(positive, pdf, Set(d, 1.0f)))), pi);
  out_spread = IfThenElse(impulse, spread, Max(Min(pi, lobe), spread));
}

// The shading frame about the unit normal ns whose s lies along `perp`
// (perpendicular to ns, of length `length`) where `usable`, with
// t = handed ns x s; Frame(ns) elsewhere. The tail of tangent_frame and
// normal_map_frame, which differ in what they call usable.
template <class D, class M, class V = VecOf<D>>
HWY_INLINE void frame_along(D d, const Vec3<V>& ns, const Vec3<V>& perp, V length, M usable, V handed, Vec3<V>& fs,
                            Vec3<V>& ft) {
  const Vec3<V> s = perp / IfThenElse(usable, length, Set(d, 1.0f));
  Vec3<V> ds, dt;
  frame(d, ns, ds, dt);
  fs = select(usable, s, ds);
  ft = select(usable, handed * cross(ns, s), dt);
}

// The shading frame of a mesh with tangents at a hit (shading_frame-inl.h's
// surface_frame, for CompiledScene::shading_frame). tangents[k] and w[k] are the triangle's vertices'
// tangents (xyz; handedness w), blended here by the barycentrics (b1, b2) in
// blend_normals' order, the sum placed by the linear part c0 c1 c2 of the
// instance's placement (the identity's columns in world space); `mirrors`
// where that placement's determinant
// is negative. The placed tangent is made perpendicular to the shading
// normal ns (Gram-Schmidt) and is the frame's s, with t = w' n x s, w' the
// handedness turned where the placement mirrors and where ns faces away
// from the mesh's own normal n_mesh; Frame(ns) where the tangent has
// (almost) no part perpendicular to ns or is not finite.
template <class D, class M, class V = VecOf<D>>
HWY_INLINE void tangent_frame(D d, V b1, V b2, const Vec3<V> (&tangents)[3], const V (&w)[3], const Vec3<V>& c0,
                              const Vec3<V>& c1, const Vec3<V>& c2, M mirrors, const Vec3<V>& n_mesh,
                              const Vec3<V>& ns, Vec3<V>& fs, Vec3<V>& ft) {
  const Vec3<V> sum = blend_normals(d, b1, b2, tangents[0], tangents[1], tangents[2]);
  const V b0 = Set(d, 1.0f) - b1 - b2;
  const V w_sum = (b0 * w[0] + b1 * w[1]) + b2 * w[2];
  const Vec3<V> placed = to_world(c0, c1, c2, sum.x, sum.y, sum.z);
  const Vec3<V> s = placed - dot(placed, ns) * ns;
  const V length = Sqrt(dot(s, s));
  const auto usable = And(length > Set(d, 1e-4f) * Sqrt(dot(placed, placed)), IsFinite(length));
  const V one = Set(d, 1.0f);
  V handed = IfThenElse(w_sum < Zero(d), Neg(one), one);
  handed = IfThenElse(mirrors, Neg(handed), handed);
  handed = IfThenElse(dot(ns, n_mesh) < Zero(d), Neg(handed), handed);
  frame_along(d, ns, s, length, usable, handed, fs, ft);
}

// A normal map's tilt of the shading frame (fs, ft, fn) at a hit with
// geometric normal ng (CompiledScene::read_textures): the map's texel c
// read as glTF's tangent-space normal (2 c - 1, x and y times `scale`),
// taken to the frame, through the shading-normal policy (shading_normal),
// with s kept along the old s (Gram-Schmidt; Frame(ns) where it is (almost)
// along ns) and t = h ns x s, h the old frame's handedness. The frame is
// kept where the tilted normal has no direction or is within ~0.08 degrees
// of fn (so a flat map changes no bit). Returns where it tilted.
template <class D, class V = VecOf<D>>
HWY_INLINE auto normal_map_frame(D d, const Vec3<V>& c, V scale, const Vec3<V>& ng, Vec3<V>& fs, Vec3<V>& ft,
                                 Vec3<V>& fn) {
  const V one = Set(d, 1.0f), two = Set(d, 2.0f);
  const V x = (two * c.x - one) * scale, y = (two * c.y - one) * scale, z = two * c.z - one;
  const Vec3<V> sum = to_world(fs, ft, fn, x, y, z);
  const V length = Sqrt(dot(sum, sum));
  const auto tilt =
      And(And(length > Set(d, 1e-20f), IsFinite(length)), dot(sum / length, fn) < Set(d, 1.0f - 1e-6f));
  const Vec3<V> ns = shading_normal(d, ng, sum);
  const Vec3<V> t = fs - dot(fs, ns) * ns;
  const V tl = Sqrt(dot(t, t));
  const V handed = IfThenElse(dot(cross(fn, fs), ft) < Zero(d), Neg(one), one);
  Vec3<V> new_s, new_t;
  frame_along(d, ns, t, tl, tl > Set(d, 1e-4f), handed, new_s, new_t);
  fs = select(tilt, new_s, fs);
  ft = select(tilt, new_t, ft);
  fn = select(tilt, ns, fn);
  return tilt;
}

// A texture lookup's footprint (CompiledScene::read_textures; ray cones,
// core/ray_cone.h). Of a triangle with world edges e1 and e2 (placed by its
// instance) and texture-coordinate edges a and b (uv1 - uv0, uv2 - uv0; the
// barycentrics' where the mesh has none, `uvs` false: uv area 1/2): the uv
// area per world area, 0 for a degenerate triangle.
template <class D, class M, class V = VecOf<D>>
HWY_INLINE V triangle_uv_per_area(D d, const Vec3<V>& e1, const Vec3<V>& e2, M uvs, V ax, V ay, V bx, V by) {
  const V half = Set(d, 0.5f);
  const V uv_area = IfThenElse(uvs, half * Abs(ax * by - ay * bx), half);
  const Vec3<V> c = cross(e1, e2);
  const V area = half * Sqrt(dot(c, c));
  const auto usable = area > Zero(d);
  return IfThenElse(usable, uv_area / IfThenElse(usable, area, Set(d, 1.0f)), Zero(d));
}
// The footprint's width in texture space at the hit p (geometric normal ng)
// of the ray from o along dir: the ray cone's width there (`width` at the
// ray's origin plus `spread` per unit of the distance |p - o|: RayCone::
// width_at), projected onto the surface (the cosine dir . ng, at least 1e-4
// in magnitude) and scaled by sqrt(uv_per_area) (texture_inputs-inl.h's);
// 0 (the finest level) where that is not finite.
template <class D, class V = VecOf<D>>
HWY_INLINE V footprint_width(D d, V width, V spread, const Vec3<V>& o, const Vec3<V>& dir, const Vec3<V>& p,
                             const Vec3<V>& ng, V uv_per_area) {
  const Vec3<V> to = p - o;
  const V w = width + spread * Sqrt(dot(to, to));
  const V fw = w / Max(Set(d, 1e-4f), Abs(dot(dir, ng))) * Sqrt(uv_per_area);
  return IfThenElse(IsFinite(fw), fw, Zero(d));
}

// shading_normal (core/geometry.cpp): `sum` (blended vertex normals, or a
// normal map's tilt) normalised and turned to the geometric normal ng's
// side; ng itself where the sum has no direction (length at most 1e-20 or
// not finite) or is within ~0.08 degrees of ng, so that a flat mesh's
// normals change no bit.
template <class D, class V = VecOf<D>>
HWY_INLINE Vec3<V> shading_normal(D d, const Vec3<V>& ng, const Vec3<V>& sum) {
  const V length = Sqrt(dot(sum, sum));
  const auto usable = And(length > Set(d, 1e-20f), IsFinite(length));
  const Vec3<V> unit = sum / length;
  const V c = dot(unit, ng);
  const auto below = c < Zero(d);
  const V cos = IfThenElse(below, Neg(c), c);
  return select(Or(Not(usable), cos > Set(d, 1.0f - 1e-6f)), ng, select(below, -unit, unit));
}

// n turned to wo's side, 0 where wo is edge-on: the normal of a light
// query (light_query, core/light_sampler.h) and of the light BVH's.
template <class D, class V = VecOf<D>>
HWY_INLINE Vec3<V> facing_normal(D d, const Vec3<V>& n, const Vec3<V>& wo) {
  const V c = dot(n, wo);
  return select(c > Zero(d), n, select(c < Zero(d), -n, splat3(d, 0.0f, 0.0f, 0.0f)));
}

// The vertex a scatter at p (normal n, wo towards the previous vertex)
// leaves for the emitter its ray finds (PreviousVertex,
// core/strategy_weights.h), in the lanes of m: the light query (light_query:
// p and n turned to wo's side), the density pdf of the direction, whether it
// was an impulse, and whether it counts as BSDF sampling
// (chose_bsdf_technique, u_technique() drawn only under light+bsdf).
template <class V, class M>
struct PreviousVertexLanes {
  Vec3<V> p, n;
  V pdf;
  M impulse, bsdf_technique;
};
template <class D, class M, class Draw, class V = VecOf<D>>
HWY_INLINE PreviousVertexLanes<V, M> previous_vertex(D d, Strategy strategy, M m, const Vec3<V>& p, const Vec3<V>& n,
                                                     const Vec3<V>& wo, V pdf, M impulse, const Draw& u_technique) {
  return {p, facing_normal(d, n, wo), pdf, impulse, chose_bsdf_technique(d, strategy, m, u_technique)};
}

// Surfel::spawn (core/surfel.cpp): the origin of a ray leaving p (error
// bound `error`, normal n) along dir, off the surface on dir's side.
template <class D, class V = VecOf<D>>
HWY_INLINE Vec3<V> spawn_origin(D d, const Vec3<V>& p, const Vec3<V>& error, const Vec3<V>& n, const Vec3<V>& dir) {
  return offset_ray_origin(d, p, error, select(dot(dir, n) >= Zero(d), n, -n));
}

// Surfel::spawn_to (core/surfel.cpp): the shadow ray from p towards
// `target` (its error bound and normal), both ends strictly off their
// surfaces: the ray reaches t = dist within gamma(3) |end - origin| of its
// end per axis (the difference and the division round once each, the
// rounded length cancels), so the end moves off the target's surface by
// that reach beyond the target's own error, however long the ray.
template <class D, class V = VecOf<D>>
HWY_INLINE void spawn_to(D d, const Vec3<V>& p, const Vec3<V>& error, const Vec3<V>& n, const Vec3<V>& target,
                         const Vec3<V>& target_error, const Vec3<V>& target_n, Vec3<V>& origin, Vec3<V>& dir, V& dist) {
  origin = spawn_origin(d, p, error, n, target - p);
  const Vec3<V> reach = Set(d, gamma_bound(3)) * abs(target - origin);
  const Vec3<V> end = spawn_origin(d, target, target_error + reach, target_n, origin - target);
  const Vec3<V> to_end = end - origin;
  dist = Sqrt(dot(to_end, to_end));
  dir = to_end / dist;
}

// shadow_ray (core/light_sampler.cpp): from p (error bound `error`, normal
// n) towards a light sample in the lanes of m: escaping along wi (tmax
// infinite) where `infinite` (the sky, a directional light), else to the
// light's point lp (its error bound and normal: an area light's, or a point
// light's own with no error and the normal -wi). Unspecified off m.
template <class D, class M, class V = VecOf<D>>
HWY_INLINE void shadow_ray(D d, M m, M infinite, const Vec3<V>& p, const Vec3<V>& error, const Vec3<V>& n,
                           const Vec3<V>& wi, const Vec3<V>& lp, const Vec3<V>& lp_error, const Vec3<V>& ln,
                           Vec3<V>& origin, Vec3<V>& dir, V& tmax) {
  origin = dir = {Zero(d), Zero(d), Zero(d)};
  tmax = Zero(d);
  if (!AllFalse(d, AndNot(infinite, m))) spawn_to(d, p, error, n, lp, lp_error, ln, origin, dir, tmax);
  if (const M along = And(infinite, m); !AllFalse(d, along)) {
    origin = select(along, spawn_origin(d, p, error, n, wi), origin);
    dir = select(along, wi, dir);
    tmax = IfThenElse(along, Set(d, std::numeric_limits<float>::infinity()), tmax);
  }
}

// The camera's image plane (Camera::Plane, core/camera.h) in lanes.
template <class V>
struct CameraPlane {
  Vec3<V> position, forward, right, up;
  V tan_half_fov, aspect, inv_width, inv_height;
};
// Camera::generate_ray's direction through film position (fx, fy) in pixels:
// the point of the image plane at distance 1 along forward.
template <class D, class V = VecOf<D>>
HWY_INLINE Vec3<V> camera_direction(D d, const CameraPlane<V>& c, V fx, V fy) {
  const V one = Set(d, 1.0f), two = Set(d, 2.0f);
  const V sx = (two * fx * c.inv_width - one) * c.tan_half_fov * c.aspect;
  const V sy = (one - two * fy * c.inv_height) * c.tan_half_fov;
  return normalize(d, (c.forward + sx * c.right) + sy * c.up);
}
// Camera::generate_ray's thin lens: the ray of direction `dir` (from
// camera_direction) leaves the aperture's point (lx, ly) (the concentric
// disk's point, times the radius) through that direction's point of the
// plane in focus, so every ray through a film point meets there.
template <class D, class V = VecOf<D>>
HWY_INLINE void thin_lens(D d, const CameraPlane<V>& c, V focus_distance, const Vec3<V>& dir, V lx, V ly,
                          Vec3<V>& origin, Vec3<V>& lens_dir) {
  const Vec3<V> focus = c.position + (focus_distance / dot(dir, c.forward)) * dir;
  origin = (c.position + lx * c.right) + ly * c.up;
  lens_dir = normalize(d, focus - origin);
}

// average (core/math.h): (x + y + z) / 3, as a product with 1/3.
template <class D, class V = VecOf<D>>
HWY_INLINE V average(D d, const Vec3<V>& v) {
  return ((v.x + v.y) + v.z) * Set(d, 1.0f / 3.0f);
}

// 64-bit lanes: the full 64-bit product of the low 32 bits of a and of b
// (one 32 x 32 -> 64-bit multiply). A primitive of core/simd/sobol-generic.h:
// lane1 has its own (plain integer products, the same bits).
template <class D64, class V64 = hn::Vec<D64>>
HWY_INLINE V64 mul_wide32(D64, V64 a, V64 b) {
  const hn::Repartition<std::uint32_t, D64> d32;
  return hn::MulEven(hn::BitCast(d32, a), hn::BitCast(d32, b));
}

// 64-bit lanes: z * c modulo 2^64. Highway 1.0 has no 64-bit multiply but
// AVX-512DQ's, so elsewhere it is three 32 x 32 -> 64-bit products.
template <class D64, class V64 = hn::Vec<D64>>
HWY_INLINE V64 mul64(D64 d64, V64 z, std::uint64_t c) {
#if HWY_TARGET <= HWY_AVX3 && HWY_ARCH_X86
  if constexpr (hn::MaxLanes(D64()) == 8) {
    (void)d64;
    return V64{_mm512_mullo_epi64(z.raw, _mm512_set1_epi64(static_cast<long long>(c)))};
  }
#endif
  const V64 k = hn::Set(d64, c);
  const V64 lo = mul_wide32(d64, z, k);
  const V64 cross = mul_wide32(d64, hn::ShiftRight<32>(z), k) + mul_wide32(d64, z, hn::Set(d64, c >> 32));
  return lo + hn::ShiftLeft<32>(cross);
}

// sobol::permute_digits' step: the image of `digit` (0 to 3) under the
// permutation of four that the hash h picks, entry (h >> 32) % 24 of
// sobol::kPermutations4. A primitive of core/simd/sobol-generic.h: lane1
// indexes the table; lanes read it packed (sobol::kPermutations4Packed) by
// two selects and a shift, where a gather cost its latency once per digit
// (40 % of the lanes' zsobol draws in perf on AMD family 26 model 2).
template <class D64, class V64 = hn::Vec<D64>>
HWY_INLINE V64 permutation_image(D64 d64, V64 h, V64 digit) {
  // (h >> 32) % 24, exactly: for x < 2^32, x / 24 = (x * 0xaaaaaaab) >> 36
  // (a 32 x 32 -> 64-bit product), and q * 24 < 2^32.
  const V64 x = hn::ShiftRight<32>(h);
  const V64 q = hn::ShiftRight<36>(mul_wide32(d64, x, hn::Set(d64, 0xaaaaaaabull)));
  const V64 which = x - mul_wide32(d64, q, hn::Set(d64, 24));
  const V64 word = hn::IfThenElse(which < hn::Set(d64, 8), hn::Set(d64, sobol::kPermutations4Packed[0]),
                                  hn::IfThenElse(which < hn::Set(d64, 16), hn::Set(d64, sobol::kPermutations4Packed[1]),
                                                 hn::Set(d64, sobol::kPermutations4Packed[2])));
  const V64 shift = hn::ShiftLeft<3>(hn::And(which, hn::Set(d64, 7))) + hn::ShiftLeft<1>(digit);
  return hn::And(word >> shift, hn::Set(d64, 3));
}

}  // namespace pathlab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // PATHLAB_CORE_SIMD_LANES_INL_H_ toggle
