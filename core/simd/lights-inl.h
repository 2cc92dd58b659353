// LightSampler's steps (core/light_sampler.cpp) written once over Highway's
// vectors: the pick from a cdf (and a piecewise-constant density's samples,
// Distribution1D and Distribution2D, core/sampling.cpp), what an area light's point gives a shading
// point (direction, distance, density), and what a delta light does. core/light_sampler.cpp calls
// them at width 1 (core/simd/width1.h) for both tracers' scalar code, the
// wavefront's vectorised stages at their SIMD width.
//
// Highway's "-inl.h" convention: no include guard but the toggle below.
#if defined(PATHLAB_CORE_SIMD_LIGHTS_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef PATHLAB_CORE_SIMD_LIGHTS_INL_H_
#undef PATHLAB_CORE_SIMD_LIGHTS_INL_H_
#else
#define PATHLAB_CORE_SIMD_LIGHTS_INL_H_
#endif

#include <hwy/highway.h>

#include "core/simd/lane1.h"
#include "core/simd/lanes-inl.h"
#include "core/simd/sampling-inl.h"

#include <cmath>
#include <cstddef>

HWY_BEFORE_NAMESPACE();
namespace pathlab::HWY_NAMESPACE {

// LightSampler::pick: the first of `count` entries whose cdf exceeds u, the
// last if none does (std::upper_bound), as a branch-free binary search:
// the number of entries that u is not below, at most count - 1 (a NaN u
// is below nothing, as upper_bound's !(u < cdf) has it). Indices are float
// lanes, exact for count <= kMaxExactFloatIndex (core/math.h); cdf_at(m, i) is entry i's cdf in
// the lanes of m (its caller's table lookup: a gather, a permute or a load).
template <class D, class M, class Lookup, class V = VecOf<D>>
HWY_INLINE V pick_cdf(D d, M m, std::size_t count, V u, const Lookup& cdf_at) {
  std::size_t step = 1;
  while (step * 2 <= count) step *= 2;
  V idx = Zero(d);
  const V n = Set(d, static_cast<float>(count));
  for (; step > 0; step /= 2) {
    const V cand = idx + Set(d, static_cast<float>(step));
    const M valid = And(m, Not(cand > n));
    idx = IfThenElse(And(valid, Not(u < cdf_at(valid, cand - Set(d, 1.0f)))), cand, idx);
  }
  return Min(idx, Set(d, static_cast<float>(count - 1)));
}

// LightSampler::pick under the light BVH: the grid point of a LightChoice
// number u (a multiple of 2^-24, core/rng.h), floor(u 2^24) clamped to
// [0, 2^24 - 1] as std::clamp does, a whole number in a double.
template <class DD, class VD = VecOf<DD>>
HWY_INLINE VD light_grid_point(DD dd, VD u) {
  const VD scaled = Floor(u * Set(dd, 0x1p24));
  return IfThenElse(scaled < Zero(dd), Zero(dd), IfThenElse(Set(dd, 0x1p24 - 1) < scaled, Set(dd, 0x1p24 - 1), scaled));
}
// ... and past the tree's grid points: the sky entry j whose grid points
// [start j, start j + 1) hold the grid point k (a whole float), the last j
// whose start k is not below (std::upper_bound - 1), by pick_cdf over the
// upper ends of `count` entries; starts(m, i) reads start i.
template <class D, class M, class Lookup, class V = VecOf<D>>
HWY_INLINE V sky_entry_of(D d, M m, std::size_t count, V k, const Lookup& starts) {
  return pick_cdf(d, m, count, k, [&](M valid, V i) { return starts(valid, i + Set(d, 1.0f)); });
}

// The probability of a light the light BVH's tree picks with a share of
// `share` of the 2^24 grid points of LightChoice (each 2^-24 likely).
template <class D, class V = VecOf<D>>
HWY_INLINE V tree_share_pmf(D d, V share) {
  return share * Set(d, 0x1p-24f);
}

// LightSampler::pick under the light BVH, once the grid point k of each
// lane of m is known (light_grid_point, a whole float): below tree_count
// (the tree's grid points; 0 for an empty tree) the tree's walk from the
// shading point, walk(tree, share), which returns the entry of the tree's
// light and sets its share of the 2^24 grid points (0 where the tree gives
// the lane nothing); at or past it the entry of the sky's grid points that
// hold k (sky_entry_of over sky_count entries, starts(m, i); the entry
// sky_entry(m, j)), whose probability is pmf_of(m, entry). Without a sky
// the grid is the tree's. Returns the lanes it picks a light for, with the
// light's entry (lanes of DI: int32 in the vector stages, int64 at width 1)
// and its probability; 0 in the others.
template <class D, class DI, class M, class Walk, class Starts, class SkyEntry, class PmfOf, class V = VecOf<D>,
          class VI = VecOf<DI>>
HWY_INLINE M tree_or_sky_pick(D d, DI di, M m, V k, V tree_count, std::size_t sky_count, const Walk& walk,
                              const Starts& starts, const SkyEntry& sky_entry, const PmfOf& pmf_of, VI& light,
                              V& pmf) {
  const M tree = And(m, k < tree_count);
  const M sky = sky_count != 0 ? AndNot(tree, m) : AndNot(m, m);
  light = Zero(di);
  pmf = Zero(d);
  M picked = sky;
  if (!AllFalse(d, tree)) {
    V share;
    const VI entry = walk(tree, share);
    const M tree_ok = And(tree, share > Zero(d));
    picked = Or(picked, tree_ok);
    pmf = IfThenElseZero(tree_ok, tree_share_pmf(d, share));
    light = IfThenElseZero(RebindMask(di, tree_ok), entry);
  }
  if (!AllFalse(d, sky)) {
    const V j = sky_entry_of(d, sky, sky_count, k, starts);
    light = IfThenElse(RebindMask(di, sky), sky_entry(sky, j), light);
    pmf = IfThenElse(sky, pmf_of(sky, light), pmf);
  }
  return picked;
}

// LightSampler::pick_pmf: the probability that the pick chose a light
// entry from the shading point it was picked from: where the entry is the
// tree's (in_tree), its share of the grid, share(m) in the lanes of m (the
// tree's walk back from the light, bvh_share); elsewhere its pmf (power's,
// or a sky entry's grid points).
template <class D, class M, class Share, class V = VecOf<D>>
HWY_INLINE V pick_pmf(D d, M in_tree, V pmf, const Share& share) {
  if (AllFalse(d, in_tree)) return pmf;
  return IfThenElse(in_tree, tree_share_pmf(d, share(in_tree)), pmf);
}

// A piecewise-constant density's cdf (Distribution1D, core/sampling.h): count
// cells, count + 1 entries from 0 to 1, entry i read by cdf_entry(m, i) (i a
// whole float; the caller's table lookup).
//
// cdf_density: the density of cell `cell`, its step times count
// (Distribution1D::pdf).
template <class D, class M, class Lookup, class V = VecOf<D>>
HWY_INLINE V cdf_density(D d, M m, std::size_t count, const Lookup& cdf_entry, V cell) {
  return (cdf_entry(m, cell + Set(d, 1.0f)) - cdf_entry(m, cell)) * Set(d, static_cast<float>(count));
}
// cdf_sample (Distribution1D::sample): the cell u falls in (pick_cdf over
// the cells' upper ends; zero-width cells skipped), its density, and the
// point placed in it by where u falls (piecewise_point).
template <class D, class M, class Lookup, class V = VecOf<D>>
HWY_INLINE V cdf_sample(D d, M m, std::size_t count, V u, const Lookup& cdf_entry, V& cell, V& pdf) {
  const V one = Set(d, 1.0f), n = Set(d, static_cast<float>(count));
  cell = pick_cdf(d, m, count, u, [&](M valid, V i) { return cdf_entry(valid, i + one); });
  const V lo = cdf_entry(m, cell), hi = cdf_entry(m, cell + one);
  pdf = (hi - lo) * n;
  return piecewise_point(d, u, lo, hi, cell, n);
}
// A Distribution2D's cdfs, as the two functions below read them: an object
// whose row(m, i) is entry i of the rows' cdf and column(m, y, i) entry i of
// row y's (i, y whole floats; the caller's table lookups).
//
// Distribution2D::sample: the row by uy from the rows' cdf, then the column
// by ux from that row's; the point (px, py), its density (the row's times
// the column's) and its cell (x, y). Lanes whose row has density 0 leave ok.
template <class D, class M, class Cdfs, class V = VecOf<D>>
HWY_INLINE void distribution2d_sample(D d, M& ok, std::size_t width, std::size_t height, V ux, V uy, const Cdfs& cdfs,
                                      V& px, V& py, V& pdf, V& x, V& y) {
  V row_pdf, column_pdf;
  py = cdf_sample(d, ok, height, uy, [&](M valid, V i) { return cdfs.row(valid, i); }, y, row_pdf);
  ok = And(ok, row_pdf > Zero(d));
  px = cdf_sample(d, ok, width, ux, [&](M valid, V i) { return cdfs.column(valid, y, i); }, x, column_pdf);
  pdf = row_pdf * column_pdf;
}

// An area light's point lp (normal ln) seen from ref: the direction wi, the
// distance and the cosine at the light (LightSampler::sample). False where
// the distance is not > 0 or the point shows its back to ref (cos_light <=
// 0) and the emitter is one-sided (a NaN cosine passes, as in the scalar
// code).
template <class D, class M, class V = VecOf<D>>
HWY_INLINE M light_point_seen(D d, const Vec3<V>& ref, const Vec3<V>& lp, const Vec3<V>& ln, M two_sided, Vec3<V>& wi,
                              V& dist, V& cos_light) {
  const Vec3<V> to = lp - ref;
  dist = Sqrt(dot(to, to));
  wi = to / dist;
  cos_light = dot(ln, -wi);
  return And(dist > Zero(d), Or(two_sided, Not(cos_light <= Zero(d))));
}

// The solid-angle density of an area light's point chosen with `pmf` and
// the area density inv_area, at `dist` and `cos_light`: pmf inv_area d^2 /
// |cos| (area_to_solid_angle), 0 edge-on. `drop_distance` plants the
// test-only fault LightPdfWithoutDistance (core/faults.h: no d^2), which
// only core's fault build passes (a parameter, not the macro here, so that
// this template is the same in every translation unit).
template <class D, class V = VecOf<D>>
HWY_INLINE V area_light_pdf(D d, V pmf, V inv_area, V dist, V cos_light, bool drop_distance = false) {
  return pmf * area_to_solid_angle(d, inv_area, drop_distance ? Set(d, 1.0f) : dist, cos_light);
}

// LightSampler::pdf of an area light's point p (normal n) seen from ref.
template <class D, class V = VecOf<D>>
HWY_INLINE V area_light_pdf_at(D d, const Vec3<V>& ref, const Vec3<V>& p, const Vec3<V>& n, V pmf, V inv_area,
                               bool drop_distance = false) {
  const Vec3<V> to = p - ref;
  const V dist = Sqrt(dot(to, to));
  return area_light_pdf(d, pmf, inv_area, dist, dot(n, to) / dist, drop_distance);
}

// LightSampler::pdf of an area light's point p (normal n) that a ray from
// ref found, the light picked with probability pmf there, in the lanes of
// m: pmf / solid angle where solid_angle(lanes) (the caller's
// solid_angle_draw without a draw, as area_light_sample takes it) says the
// light is sampled in solid angle, else area_light_pdf_at. Where
// zero_unpicked (under bvh or solid_angle) a light picked with probability 0
// has density 0 (not 0 times a density that may be infinite edge-on).
template <class D, class M, class SolidAngle, class V = VecOf<D>>
HWY_INLINE V emitter_hit_pdf(D d, M m, const Vec3<V>& ref, const Vec3<V>& p, const Vec3<V>& n, V pmf, V inv_area,
                             bool zero_unpicked, const SolidAngle& solid_angle, bool drop_distance = false) {
  const M live = zero_unpicked ? AndNot(pmf == Zero(d), m) : m;
  const auto sa = solid_angle(live);
  const V pdf = area_light_pdf_at(d, ref, p, n, pmf, inv_area, drop_distance);
  return IfThenElseZero(live, IfThenElse(sa.use, pmf * sa.density, pdf));
}

// A light sample's density is usable: > 0 and finite (not seen edge-on).
template <class D, class V = VecOf<D>>
HWY_INLINE auto usable_light_pdf(D d, V pdf) {
  return And(pdf > Zero(d), Not(IsInf(pdf)));
}

// An area light as LightSampler::sample reads it in a lane: a triangle's
// vertices p0 p1 p2 and unit normal n, or where `sphere` a sphere of centre
// p0 and radius p1.x (its normals inwards where `flip`); whether it emits
// from both sides; its area density (1 / area).
template <class V, class M>
struct AreaLight {
  Vec3<V> p0, p1, p2, n;
  M sphere, flip, two_sided;
  V inv_area;
};
// What LightSampler::sample draws on an area light: the point p (its
// rounding error bound, its normal n; a triangle's barycentrics (b1, b2) of
// p1 and p2, for an emission texture), the direction wi towards it from the
// shading point, its distance and the sample's density in solid angle.
template <class V>
struct AreaLightSample {
  Vec3<V> p, error, n, wi;
  V b1, b2, dist, pdf;
};

// LightSampler::sample's point on the area light e, chosen with
// probability pmf, seen from ref, in the lanes of ok; the lanes it gives no
// sample (no distance, the back of a one-sided emitter, edge-on) leave the
// mask it returns. solid_angle(ok) is the caller's solid_angle_draw (core/
// simd/spherical-inl.h) of those lanes with (ux, uy), carried to floats (its
// `use` none where light_sampling is area): where it says so, the point is
// the one drawn in solid angle with that density, elsewhere one uniform in
// area (square_to_uniform_triangle and triangle_point, sample_sphere) with
// density pmf inv_area d^2 / |cos|. drop_distance: area_light_pdf's fault.
template <class D, class M, class SolidAngle, class V = VecOf<D>>
HWY_INLINE M area_light_sample(D d, M ok, const Vec3<V>& ref, const AreaLight<V, M>& e, V pmf, V ux, V uy,
                               const SolidAngle& solid_angle, bool drop_distance, AreaLightSample<V>& s) {
  const auto sa = solid_angle(ok);
  const M spheres = And(ok, e.sphere), triangles = AndNot(e.sphere, ok);
  uniform_triangle(d, ux, uy, s.b1, s.b2);
  const M triangles_sa = AndNot(e.sphere, sa.use);
  s.b1 = IfThenElse(triangles_sa, sa.b1, s.b1);
  s.b2 = IfThenElse(triangles_sa, sa.b2, s.b2);
  s.p = s.error = {Zero(d), Zero(d), Zero(d)};
  s.n = e.n;
  if (!AllFalse(d, triangles)) triangle_point(d, s.b1, s.b2, e.p0, e.p1, e.p2, s.p, s.error);
  if (!AllFalse(d, spheres)) {
    // A direction from the centre (uniform, or the cone's), projected onto the sphere.
    Vec3<V> dir, p, error, n;
    uniform_sphere(d, ux, uy, dir.x, dir.y, dir.z);
    dir = select(sa.use, sa.n, dir);
    const V radius = e.p1.x;
    sphere_point(d, e.p0, radius, e.flip, e.p0 + radius * dir, p, error, n);
    s.p = select(spheres, p, s.p);
    s.error = select(spheres, error, s.error);
    s.n = select(spheres, n, s.n);
  }
  V cos_light;
  ok = And(ok, light_point_seen(d, ref, s.p, s.n, e.two_sided, s.wi, s.dist, cos_light));
  s.pdf = IfThenElse(sa.use, pmf * sa.density, area_light_pdf(d, pmf, e.inv_area, s.dist, cos_light, drop_distance));
  return And(ok, usable_light_pdf(d, s.pdf));
}

// spot_profile (core/scene.h): 1 for cos_theta >= cos_inner, 0 for
// cos_theta <= cos_outer, a smoothstep in cos_theta between.
template <class D, class V = VecOf<D>>
HWY_INLINE V spot_profile(D d, V cos_theta, V cos_outer, V cos_inner) {
  const V t = (cos_theta - cos_outer) / (cos_inner - cos_outer);
  const V smooth = t * t * (Set(d, 3.0f) - Set(d, 2.0f) * t);
  return IfThenElse(cos_theta >= cos_inner, Set(d, 1.0f), IfThenElseZero(Not(cos_theta <= cos_outer), smooth));
}

// LightSampler::sample_delta's light, once picked, seen from ref: the
// direction wi towards it, its distance and the radiance Le that arrives.
// A directional light shines along `direction` from infinitely far (wi =
// -direction, Le its intensity); a point or spot light at `position` sends
// intensity / dist^2, a spot's times its profile about `direction`. False
// where the point lies at ref (dist^2 not > 0) or ref is outside the spot's
// cone.
template <class D, class M, class V = VecOf<D>>
HWY_INLINE M delta_light_seen(D d, M directional, M spot, const Vec3<V>& ref, const Vec3<V>& position,
                              const Vec3<V>& direction, const Vec3<V>& intensity, V cos_outer, V cos_inner,
                              Vec3<V>& wi, V& dist, Vec3<V>& Le) {
  const Vec3<V> to = position - ref;
  const V dist2 = dot(to, to);
  const V r = Sqrt(dist2);
  const Vec3<V> towards = to / r;
  const V profile = spot_profile(d, dot(-towards, direction), cos_outer, cos_inner);
  const Vec3<V> falloff = intensity / dist2;
  wi = select(directional, -direction, towards);
  dist = IfThenElse(directional, Set(d, HUGE_VALF), r);
  Le = select(directional, intensity, select(spot, profile * falloff, falloff));
  return Or(directional, And(dist2 > Zero(d), Or(Not(spot), profile > Zero(d))));
}

// A delta light as delta_light_sample reads it (LightSampler's DeltaLight and
// its probability of being picked).
template <class V, class M>
struct DeltaLightLanes {
  M directional, spot;
  Vec3<V> position, direction, intensity;
  V cos_outer, cos_inner, pmf;
};
// LightSampler::sample_delta in the lanes of m: the delta light that
// pick(m, u) chooses (an index lane: the caller's search of the delta
// lights' cdf), read by light_of(m, index) into `light`, seen from ref
// (delta_light_seen). Returns the index; the lanes of m it gives no sample
// (the point at ref, ref outside a spot's cone) leave m.
template <class D, class M, class Pick, class LightOf, class V = VecOf<D>>
HWY_INLINE auto delta_light_sample(D d, M& m, V u, const Vec3<V>& ref, const Pick& pick, const LightOf& light_of,
                                   DeltaLightLanes<V, M>& light, Vec3<V>& wi, V& dist, Vec3<V>& Le) {
  const auto index = pick(m, u);
  light = light_of(m, index);
  m = And(m, delta_light_seen(d, light.directional, light.spot, ref, light.position, light.direction, light.intensity,
                              light.cos_outer, light.cos_inner, wi, dist, Le));
  return index;
}

// Sun disks (LightSampler's SunDisk): a cone of directions of half-angle
// alpha about n, the direction towards the sun.
//
// Whether dir (unit) lies in the cone, by the sine: the cosine of a 0.27
// degree cone is 1 - 1.1e-5, which float resolves only to about 0.5 %; the
// cross product keeps full precision (sin2 = sin^2 alpha).
template <class D, class V = VecOf<D>>
HWY_INLINE auto sun_contains(D d, const Vec3<V>& dir, const Vec3<V>& n, V sin2) {
  const Vec3<V> c = cross(dir, n);
  return And(dot(dir, n) > Zero(d), dot(c, c) <= sin2);
}
// A direction uniform in the cone (frame s, t, n), by 1 - cos theta = ux (1
// - cos alpha): sin theta from that difference keeps a tiny sun's size exact.
template <class D, class V = VecOf<D>>
HWY_INLINE Vec3<V> sun_direction(D d, const Vec3<V>& s, const Vec3<V>& t, const Vec3<V>& n, V one_minus_cos_alpha,
                                 V ux, V uy) {
  const V one_minus_cos = ux * one_minus_cos_alpha;
  const V sin_theta = Sqrt(Max(one_minus_cos * (Set(d, 2.0f) - one_minus_cos), Zero(d)));
  V sin_phi, cos_phi;
  sin_cos_turn(d, uy, sin_phi, cos_phi);
  return normalize(d, to_world(s, t, n, sin_theta * cos_phi, sin_theta * sin_phi, Set(d, 1.0f) - one_minus_cos));
}
// The sky along dir gains a sun disk's radiance Le and density pdf_sun (its
// pick probability times the cone's 1 / solid angle) where dir is in it.
template <class D, class V = VecOf<D>>
HWY_INLINE void add_sun(D d, const Vec3<V>& dir, const Vec3<V>& n, V sin2, const Vec3<V>& sun_Le, V pdf_sun,
                        Vec3<V>& Le, V& pdf) {
  const auto in = sun_contains(d, dir, n, sin2);
  Le = select(in, Le + sun_Le, Le);
  pdf = IfThenElse(in, pdf + pdf_sun, pdf);
}

// LightSampler::sky along dir in the lanes of m: the environment's radiance
// and density (an image's texel and its density, or the one radiance and
// 1 / 4 pi, times the environment's pick probability), then each sun disk's
// that dir is in. The caller's sky, as sky_sample's, also has
//   void lookup(m, dir, Le, pdf)                  EnvironmentMap::lookup (pdf without the pick)
//   Vec3<V> radiance()                            a uniform environment's (0 without one)
template <class D, class M, class Sky, class V = VecOf<D>>
HWY_INLINE void sky_along(D d, M m, const Vec3<V>& dir, const Sky& sky, Vec3<V>& Le, V& pdf) {
  if (sky.image()) {
    V map_pdf;
    sky.lookup(m, dir, Le, map_pdf);
    pdf = sky.env_pmf() * map_pdf;
  } else {
    Le = zero_unless(m, sky.radiance());
    pdf = IfThenElseZero(m, sky.env_pmf() * Set(d, kInv4Pi));
  }
  sky.add_suns(dir, Le, pdf);
}

// LightSampler::sample of the sky's entries in the lanes of ok, `env` those
// that picked the environment, the rest a sun disk: a direction (one drawn
// from the environment image, uniform on the sphere for one radiance, or
// uniform in the sun's cone), with the sky's radiance and density there
// (the image's texel drawn and its density, or the sky along it: one
// technique for the whole sky, as an escaping ray weighs it). Returns ok
// without the lanes that get no sample: an image that draws nothing, a sun
// direction rounded out of every cone.
//
// The caller's sky reads what the two tracers store differently:
//   bool image()                                  an environment image is sampled
//   M sample_image(m, ux, uy, wi, Le, pdf)        EnvironmentMap::sample (pdf without the pick)
//   V env_pmf()                                   the environment's pick probability
//   void add_suns(dir, Le, pdf)                   LightSampler::add_suns
//   void along(m, dir, Le, pdf)                   LightSampler::sky (sky_along above)
//   void sun_directions(m, ux, uy, wi)            wi of the lanes of m: their sun's sun_direction
template <class D, class M, class Sky, class V = VecOf<D>>
HWY_INLINE M sky_sample(D d, M ok, M env, V ux, V uy, const Sky& sky, Vec3<V>& wi, Vec3<V>& Le, V& pdf) {
  env = And(env, ok);
  const M suns = AndNot(env, ok);
  wi = Le = {Zero(d), Zero(d), Zero(d)};
  pdf = Zero(d);
  if (!AllFalse(d, suns)) sky.sun_directions(suns, ux, uy, wi);
  const bool image = sky.image() && !AllFalse(d, env);
  Vec3<V> image_Le = Le;  // zero: a draw that fails may leave them
  V image_pdf = pdf;
  if (image) {
    Vec3<V> image_wi = Le;
    const M drawn = sky.sample_image(env, ux, uy, image_wi, image_Le, image_pdf);
    image_pdf = sky.env_pmf() * image_pdf;
    sky.add_suns(image_wi, image_Le, image_pdf);
    wi = select(env, image_wi, wi);
    ok = Or(suns, drawn);
  } else if (!AllFalse(d, env)) {
    Vec3<V> uniform;
    uniform_sphere(d, ux, uy, uniform.x, uniform.y, uniform.z);
    wi = select(env, uniform, wi);
  }
  const M along = image ? suns : ok;
  if (!AllFalse(d, along)) sky.along(along, wi, Le, pdf);
  if (image) {
    Le = select(env, image_Le, Le);
    pdf = IfThenElse(env, image_pdf, pdf);
  }
  return AndNot(And(suns, Or(Not(pdf > Zero(d)), is_black(d, Le))), ok);
}

// LightSampler::sample after the pick, in the lanes of m whose picked entry
// is `entry`: the sky's entries are the last ones, from first_sky on (the
// environment, then the sun disks: LightSampler::first_sky_entry); their
// lanes, `sky`, take sample_sky's sample (sky_sample above), the others
// sample_area's (a triangle or a sphere: area_light_sample). Each is called
// only if it has lanes, with those, and returns the lanes it gave a sample;
// so does this. Where the two write their samples is the caller's.
template <class D, class M, class VI, class SkyFn, class AreaFn>
HWY_INLINE M sky_or_area_sample(D d, M m, VI entry, VI first_sky, M& sky, const SkyFn& sample_sky,
                                const AreaFn& sample_area) {
  sky = And(m, RebindMask(d, Not(entry < first_sky)));
  const M area = AndNot(sky, m);
  M sampled = AndNot(m, m);
  if (!AllFalse(d, sky)) sampled = sample_sky(sky);
  if (!AllFalse(d, area)) sampled = Or(sampled, sample_area(area));
  return sampled;
}

}  // namespace pathlab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // PATHLAB_CORE_SIMD_LIGHTS_INL_H_ toggle
