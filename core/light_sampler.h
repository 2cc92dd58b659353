// Light sampling for next-event estimation.
//
// Area lights are every emitting triangle and sphere, plus the environment
// (uniform, or an image: core/environment_map.h); one is picked in
// proportion to its power, then a point on it uniformly by area (for the
// environment a direction: uniformly on the sphere, or by the image's
// importance sampler). With `light_sampling: solid_angle` (the scene's
// RenderSettings) a triangle is sampled uniformly in the solid angle it
// subtends (Arvo's spherical triangles) and a sphere seen from outside
// uniformly in its cone (core/sampling_spherical.h), unless the rule there
// sends that (shading point, light) pair to area sampling; pdf() applies
// the same rule to the same pair. Densities are returned in solid angle as seen from the
// shading point and include the probability of picking that light, so
// `pdf()` of an emitter that a BSDF-sampled ray hits is directly comparable
// with the BSDF's pdf (MIS).
//
// A directional light with an angular diameter is a sun disk: uniform
// radiance in a cone that escaping rays can hit, sampled uniformly in the
// cone, picked like the environment (power pi r^2 Y(E)). The environment and
// the sun disks are one sky to the estimators: environment(dir) and
// pdf_environment(dir) sum them all, and a sample of any of them carries
// those sums, so MIS weighs the sky as one light.
//
// Which light: `render.light_sampler` (LightSamplerKind). `power` (the
// default) picks an entry in proportion to its power (docs/scene-format.md,
// "How a light is picked"), wherever the shading point is. `bvh` picks the
// emitting triangles and spheres down a light BVH (core/light_bvh.h) by
// their importance for the shading point (position and the normal of the
// side that receives light: LightQuery), and the environment and each sun
// disk each with the fixed probability 1 / (number of them + 1), the tree
// taking the rest, as pbrt-v4's BVHLightSampler does (the sky's pdf then
// needs no shading point). Both rules cut the 2^24 grid of the LightChoice
// number exactly, so the probability pdf() multiplies by is the one the pick
// used.
//
// Point, spot and directional lights are delta lights: no ray can hit them,
// so they live in a separate list that every strategy samples explicitly
// (DESIGN: the strategies differ only on lights a ray can find). One is
// picked in proportion to an estimate of its power (delta_power_over_4pi).
#pragma once

#include "core/geometry.h"
#include "core/light_bvh.h"
#include "core/path_observer.h"
#include "core/sampling_spherical.h"
#include "core/scene.h"
#include "core/surfel.h"

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

namespace pathlab {

struct LightSample {
  vec3 p{0.0f};        // point on the light (unused for the environment)
  vec3 p_error{0.0f};  // bound on its rounding error
  vec3 n{0.0f};        // the light's normal at p (a point or spot light: -wi, facing the shading point)
  vec3 wi{0.0f};       // unit direction from the shading point towards the light
  float dist = 0.0f;   // distance to p; infinity for the environment and a directional light
  Spectrum Le{0.0f};   // radiance arriving (for a delta light: intensity * profile / dist^2,
                       // or a directional light's irradiance)
  float pdf = 0.0f;    // solid angle, times the probability of choosing this light;
                       // for a delta light just that probability
  std::uint32_t light = 0;
  bool infinite = false;  // the shadow ray is unbounded (environment, directional light)
};

// The observer's event for a light sample rejected before any shadow ray
// (LightEvent::rejected): from the sample `ls` (null when the sampler gave
// none). Both tracers report a rejection through this, identically.
inline LightEvent rejected_light_event(int vertex, bool delta, const LightSample* ls, LightRejection reason) {
  LightEvent e;
  e.vertex = vertex;
  e.delta = delta;
  e.rejected = reason;
  e.mis_weight = 0.0f;
  if (ls != nullptr) {
    e.infinite = ls->infinite;
    e.light = ls->light;
    e.point = ls->p;
    e.wi = ls->wi;
    e.dist = ls->dist;
    e.pdf = ls->pdf;
    e.Le = ls->Le;
  }
  return e;
}

// The shadow ray from `s` to the light sample `ls`: unbounded towards an
// infinite light (the environment, a directional light), else ending just
// before the point on the light. Both tracers cast exactly this ray.
Ray shadow_ray(const Surfel& s, const LightSample& ls);

// A delta light's power divided by 4 pi, the weight with which sample_delta
// picks it: Y(I) for a point, Y(I) (1 - (cos_inner + cos_outer) / 2) / 2 for
// a spot, Y(E) r^2 / 4 for a directional light (r: the scene's radius).
double delta_power_over_4pi(const DeltaLight& light, float scene_radius);
// The scene's delta lights that LightSampler samples, in its order
// (LightSample::light of a delta light indexes this list): all but the
// black ones.
std::vector<const DeltaLight*> sampled_delta_lights(const Scene& scene);

// The shading point `s`, seen along wo, as light selection sees it: its
// position and the geometric normal turned to wo's side (a reflection in
// pathlab never crosses the geometric surface, and a transmission is an
// impulse NEE never connects through), or no normal when wo grazes. Both
// tracers make the query of a vertex with this, for its light sample and
// for the pdf of the emitter its BSDF ray finds (PreviousVertex::ref).
LightQuery light_query(const Surfel& s, const vec3& wo);

class LightSampler {
 public:
  // `scene_radius`: radius of a sphere bounding the scene, for the power of
  // the environment (pi r^2 times the integral of Y(L) over the sphere, the
  // flux it sends through the scene: pi * Y(L) * 4 pi r^2 when uniform).
  // `textures`: the scene's, for emission read from a texture (null if it
  // has none). A textured emitter is picked by the power of its texture's
  // mean (over the whole image, not the part a triangle maps: an estimate;
  // any positive weight keeps the estimator unbiased), and each sample's Le
  // is read at the point's uv, unfiltered, as a ray that hits it reads it.
  LightSampler(const Scene& scene, float scene_radius, const Textures* textures = nullptr);

  std::size_t area_light_count() const { return entries_.size(); }
  // Area lights (or the environment) too dim, next to the others, ever to be
  // picked: light sampling misses them and only rays that hit them count
  // their emission.
  std::size_t unsampled_light_count() const;
  bool has_area_lights() const { return !entries_.empty(); }
  bool has_delta_lights() const { return !deltas_.empty(); }

  // An area or environment light sample as seen from `ref`. Nothing if the
  // sample cannot contribute (back of a one-sided emitter, seen edge-on,
  // every light of the BVH unimportant there).
  std::optional<LightSample> sample(const LightQuery& ref, float u_choice, vec2 u) const;
  // The radiance a light sample at point p of area-light entry i carries:
  // its material's emission, or under an emission texture the texel at the
  // point's uv (b: its barycentrics (b1, b2) on a triangle; a sphere's uv
  // comes from p). sample() takes Le from here; the wavefront's lanes, which
  // draw the point themselves, call it for textured emitters.
  Spectrum emission_at_point(std::size_t i, vec2 b, const vec3& p) const;
  // Density with which sample() would produce the emitter point `hit`
  // (reached from `ref`), in solid angle; 0 if `hit` is not on a light.
  float pdf(const LightQuery& ref, const Surfel& hit) const;
  // The same from a bare point (no normal: LightQuery::n = 0).
  std::optional<LightSample> sample(const vec3& ref, float u_choice, vec2 u) const {
    return sample(LightQuery{ref, vec3(0.0f)}, u_choice, u);
  }
  float pdf(const vec3& ref, const Surfel& hit) const { return pdf(LightQuery{ref, vec3(0.0f)}, hit); }

  // The entry (index into entries()) that sample() picks from `ref` with
  // the number u_choice, and the probability of that pick; nothing when the
  // light BVH has no light of importance there. sample() and pdf() go
  // through these two, so they cannot disagree.
  struct Pick {
    std::size_t entry;
    float pmf;
  };
  std::optional<Pick> pick(const LightQuery& ref, float u_choice) const;
  // The probability with which pick() chooses entry `entry` from `ref`
  // (under `power`, pmf()[entry] wherever ref is).
  float pick_pmf(const LightQuery& ref, std::size_t entry) const;
  // Density with which sample() would produce direction `wi` towards the
  // environment or a sun disk (0 without them): the sum over those lights.
  float pdf_environment(const vec3& wi) const { return sky(wi).pdf; }
  // The radiance a ray with direction `dir` sees when it escapes the scene:
  // the environment's plus that of every sun disk it points into (black
  // without them).
  Spectrum environment(const vec3& dir) const { return sky(dir).Le; }
  // Both, from one lookup: what both tracers' escapes call.
  struct Sky {
    Spectrum Le{0.0f};
    float pdf = 0.0f;
  };
  Sky sky(const vec3& dir) const;

  // A delta light picked in proportion to its power. Nothing if it sends no
  // light towards `ref` (outside a spot's cone, or at its position).
  std::optional<LightSample> sample_delta(const vec3& ref, float u_choice) const;
  // The probability with which sample_delta picks delta light i (its index
  // among the non-black ones, LightSample::light).
  std::span<const float> delta_pmf() const { return delta_pmf_; }
  // The delta lights sample_delta picks from (sampled_delta_lights()) and
  // the cdf it picks by (pick(): the first entry exceeding u).
  std::span<const DeltaLight> delta_lights() const { return deltas_; }
  std::span<const float> delta_cdf() const { return delta_cdf_; }

  // How sample() places a point on an area light (the scene's
  // render.light_sampling when it was made).
  LightSampling light_sampling() const { return light_sampling_; }
  // How sample() picks the light (the scene's render.light_sampler).
  LightSamplerKind light_sampler() const { return kind_; }
  // The light BVH (null under `power`); its light i is entry bvh_entry(i).
  const LightBvh* bvh() const { return bvh_.get(); }
  std::size_t bvh_entry(std::uint32_t light) const { return tree_entry_[light]; }
  // Entry i's light in the BVH, or -1 (not in the tree); and the grid points
  // of LightChoice ([0, bvh_grid()) of 2^24) that walk the tree.
  std::int64_t bvh_light(std::size_t entry) const { return entry_tree_[entry]; }
  std::uint32_t bvh_grid() const { return sky_start_.empty() ? 0 : sky_start_[0]; }

  // The area-light distribution itself, for code that samples lights in
  // bulk (the wavefront's vectorised stages) and must pick exactly as
  // sample() does (under LightSampling::Area and LightSamplerKind::Power
  // only; under `bvh` pmf() holds the fixed probabilities of the sky's
  // entries and 0 for the others): entry i is chosen when cdf[i - 1] <= u_choice < cdf[i]
  // (the first entry whose cdf exceeds u; the last one if none does), with
  // probability pmf[i]; its density on the light is 1 / area.
  struct Entry {
    std::uint32_t shape;
    std::uint32_t prim;
    float area;
    Triangle triangle;  // the emitting triangle (unused for a sphere or the environment)
  };
  std::span<const Entry> entries() const { return entries_; }
  // The density of entry e's points, uniform in area: 1 / area (the
  // wavefront's lanes read it from a table of these).
  static float area_density(const Entry& e);
  std::span<const float> cdf() const { return cdf_; }
  std::span<const float> pmf() const { return pmf_; }
  // True if an environment or a sun disk is sampled (a light escaping rays find).
  bool samples_environment() const { return env_index_ >= 0 || !suns_.empty(); }

  // The sky as sample() and sky() see it, for code that samples it in bulk
  // (the wavefront's lanes; core/simd/lights-inl.h has the steps): the
  // environment's entry (-1 if it is not sampled: none, or black) and the
  // sun disks, the last entries in order. A sun disk is radiance Le within
  // the cone of half-angle alpha about frame.n (the direction towards the
  // sun); sun_pdf() is its pick probability times the cone's density.
  struct SunDisk {
    Frame frame;
    float one_minus_cos = 0.0f;  // 1 - cos alpha, computed as 2 sin^2(alpha / 2)
    float sin2 = 0.0f;           // sin^2 alpha
    float cone_pdf = 0.0f;       // 1 / (2 pi (1 - cos alpha))
    Spectrum Le{0.0f};           // E / (pi sin^2 alpha)
    std::int64_t entry = -1;     // its entry in entries_
  };
  std::int64_t environment_entry() const { return env_index_; }
  // The first of the sky's entries, which are the last ones (the
  // environment's, then the sun disks'); entries().size() without a sky.
  std::size_t first_sky_entry() const {
    return env_index_ >= 0  ? static_cast<std::size_t>(env_index_)
           : suns_.empty() ? entries_.size()
                           : static_cast<std::size_t>(suns_.front().entry);
  }
  std::span<const SunDisk> sun_disks() const { return suns_; }
  float sun_pdf(const SunDisk& sun) const { return pmf_[static_cast<std::size_t>(sun.entry)] * sun.cone_pdf; }
  // Under `bvh`: the sky's entries (environment, then sun disks) and the
  // grid points [sky_starts()[j], sky_starts()[j + 1]) of LightChoice that
  // pick sky entry j (the tree takes [0, bvh_grid())); empty under `power`.
  std::span<const std::size_t> sky_entries() const { return sky_entry_; }
  std::span<const std::uint32_t> sky_starts() const { return sky_start_; }
  // The entry of shape `shape`'s triangle 0 (its triangle k is entry
  // first_entry + k), or -1 if the shape is not sampled as a light.
  std::int64_t first_entry(std::uint32_t shape) const { return first_entry_[shape]; }

  // The entry of a cdf that u picks: the first whose cdf exceeds u (std::
  // upper_bound), the last if none does (a NaN u too). The generic pick_cdf
  // of core/simd/lights-inl.h at width 1, the search the wavefront's lanes run.
  static std::size_t pick(const std::vector<float>& cdf, float u);

 private:
  // Under `bvh`: the entries of the sky (environment, then sun disks) and
  // the grid points [sky_start_[j], sky_start_[j + 1]) of LightChoice that
  // pick sky entry j; the tree takes [0, sky_start_[0]).
  void build_bvh(const std::vector<double>& power);

  // The sky as core/simd/lights-inl.h's sky_sample and sky_along read it at
  // width 1 (core/light_sampler.cpp).
  struct SkyView;
  // Adds the radiance and density (with its pick probability) of every sun
  // disk whose cone holds `dir`.
  void add_suns(const vec3& dir, Spectrum* Le, float* pdf) const;

  const Scene* scene_;
  const Textures* textures_;
  LightSampling light_sampling_ = LightSampling::Area;
  LightSamplerKind kind_ = LightSamplerKind::Power;
  std::unique_ptr<const LightBvh> bvh_;
  std::vector<std::size_t> tree_entry_;    // BVH light -> entry
  std::vector<std::int64_t> entry_tree_;   // entry -> BVH light, or -1 (not in the tree)
  std::vector<std::size_t> sky_entry_;     // the sky's entries, in order
  std::vector<std::uint32_t> sky_start_;   // sky_entry_.size() + 1 bounds, the last 2^24
  std::vector<Entry> entries_;           // area lights, then the environment, then the sun disks
  std::vector<SunDisk> suns_;
  std::vector<float> pmf_, cdf_;         // over entries_
  std::vector<std::int64_t> first_entry_;  // per shape: index of its prim 0, or -1
  std::int64_t env_index_ = -1;
  std::vector<DeltaLight> deltas_;  // sampled_delta_lights(), copied
  std::vector<float> delta_pmf_, delta_cdf_;
};

}  // namespace pathlab
