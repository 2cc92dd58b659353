#include "core/light_sampler.h"

#include "core/environment_map.h"
#include "core/faults.h"
#include "core/geometry.h"
#include "core/sampling.h"
#include "core/sampling_spherical.h"
#include "core/simd/width1.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace pathlab {
namespace {

// The cdf (cdf.back() == 1 exactly) of non-negative weights, and the pmf
// with which pick() really chooses each entry. The random number is a
// multiple of 2^-24 (rng.h), so entry i is chosen for the grid points in
// [cdf[i-1], cdf[i]): its probability is their count times 2^-24, which can
// differ from w_i / total by a lot for a dim entry - and is 0 for one
// dimmer than 2^-24 of the total. The estimators divide by this pmf, so
// they stay unbiased; an entry with pmf 0 is never sampled, and the
// tracers count its emission when a ray finds it (light pdf 0).
void build_distribution(const std::vector<double>& weights, std::vector<float>* pmf, std::vector<float>* cdf) {
  const double total = std::accumulate(weights.begin(), weights.end(), 0.0);
  pmf->resize(weights.size());
  cdf->resize(weights.size());
  double running = 0.0;
  for (std::size_t i = 0; i < weights.size(); ++i) {
    running += weights[i];
    (*cdf)[i] = static_cast<float>(running / total);
  }
  if (!cdf->empty()) cdf->back() = 1.0f;
  // Grid points k * 2^-24 below c: ceil(c * 2^24) of them (c * 2^24 is exact).
  auto below = [](float c) { return std::ceil(static_cast<double>(c) * 0x1p24); };
  double previous = 0.0;
  for (std::size_t i = 0; i < weights.size(); ++i) {
    const double count = below((*cdf)[i]);
    (*pmf)[i] = static_cast<float>((count - previous) * 0x1p-24);
    previous = count;
  }
}

constexpr std::uint32_t kGrid = 1u << 24;  // LightChoice numbers are multiples of 1 / kGrid

// Entry e (a triangle or sphere) as core/simd/lights-inl.h's area_light_sample
// reads it, as the wavefront's lanes gather it from their light table.
HWY_INLINE width1::generic::AreaLight<width1::F, lane1::M> area_light(const Scene& scene, const LightSampler::Entry& e) {
  using namespace width1;
  const Shape& shape = scene.shapes[e.shape];
  const bool sphere = shape.kind == Shape::Kind::Sphere;
  generic::AreaLight<F, lane1::M> light;
  light.p0 = lanes(sphere ? shape.center : e.triangle.p0);
  light.p1 = sphere ? F3{F{shape.radius}, F{0.0f}, F{0.0f}} : lanes(e.triangle.p1);
  light.p2 = lanes(sphere ? vec3(0.0f) : e.triangle.p2);
  light.n = lanes(sphere ? vec3(0.0f) : e.triangle.n);
  light.sphere = lane1::M{sphere};
  light.flip = lane1::M{sphere && shape.flip_normals};
  light.two_sided = lane1::M{scene.materials[shape.material].two_sided_emission};
  light.inv_area = F{LightSampler::area_density(e)};
  return light;
}

// No light sampled in solid angle (under light_sampling area).
width1::generic::SolidAngleDraw<width1::F, lane1::M> no_solid_angle() {
  using namespace width1;
  return {lane1::M{false}, F{0.0f}, F{0.0f}, F{0.0f}, lanes(vec3(0.0f))};
}

// Whether the area light `light` (area_light) is sampled in solid angle from
// ref under `sampling` (the fallback rule of core/sampling_spherical.h), with
// which density, and with `draw` the point drawn there with u:
// core/simd/spherical-inl.h's solid_angle_draw at width 1, carried to floats
// as the lanes carry it. sample() and pdf() both ask this, so they cannot
// apply different rules.
HWY_INLINE width1::generic::SolidAngleDraw<width1::F, lane1::M> solid_angle_draw(
    const width1::generic::AreaLight<width1::F, lane1::M>& light, LightSampling sampling, const vec3& ref, lane1::M m,
    bool draw, vec2 u) {
  using namespace width1;
  generic::SolidAngleDraw<F, lane1::M> out = no_solid_angle();
  if (sampling != LightSampling::SolidAngle || !m.raw) return out;
  const auto in_double = [](const F3& v) { return lanes(dvec3(scalars(v))); };
  const generic::SolidAngleDraw<D1, lane1::M> view =
      generic::solid_angle_draw(kScalarD, m, light.sphere, lanes(dvec3(ref)), in_double(light.p0),
                                in_double(light.p1), in_double(light.p2), draw, D1{double(u.x)}, D1{double(u.y)});
  out.use = view.use;
  out.density = F{static_cast<float>(view.density.raw)};
  out.b1 = F{static_cast<float>(view.b1.raw)};
  out.b2 = F{static_cast<float>(view.b2.raw)};
  out.n = lanes(vec3(scalars(view.n)));
  return out;
}

}  // namespace

float spot_profile(float cos_theta, float cos_outer, float cos_inner) {
  using namespace width1;
  return generic::spot_profile(kScalar, F{cos_theta}, F{cos_outer}, F{cos_inner}).raw;
}

double delta_power_over_4pi(const DeltaLight& light, float scene_radius) {
  const double y = luminance_double(light.intensity);
  switch (light.kind) {
    case DeltaLight::Kind::Point:
      return y;  // 4 pi Y(I)
    case DeltaLight::Kind::Spot:
      // 2 pi Y(I) (1 - (cos_inner + cos_outer) / 2): the exact integral of the
      // profile over the sphere (a smoothstep in cos theta averages 1/2).
      return 0.5 * y * (1.0 - 0.5 * (double(light.cos_inner) + double(light.cos_outer)));
    case DeltaLight::Kind::Directional:
      // pi r^2 Y(E): the flux it sends through the scene's bounding sphere.
      return 0.25 * y * double(scene_radius) * double(scene_radius);
  }
  return 0.0;
}

LightQuery light_query(const Surfel& s, const vec3& wo) {
  using namespace width1;
  return {s.p, scalars(generic::facing_normal(kScalar, lanes(s.n), lanes(wo)))};
}

Ray shadow_ray(const Surfel& s, const LightSample& ls) {
  using namespace width1;
  F3 origin, dir;
  F tmax;
  generic::shadow_ray(kScalar, lane1::M{true}, lane1::M{ls.infinite}, lanes(s.p), lanes(s.p_error), lanes(s.n),
                      lanes(ls.wi), lanes(ls.p), lanes(ls.p_error), lanes(ls.n), origin, dir, tmax);
  return Ray{scalars(origin), scalars(dir), tmax.raw};
}

std::vector<const DeltaLight*> sampled_delta_lights(const Scene& scene) {
  std::vector<const DeltaLight*> out;
  for (const DeltaLight& dl : scene.delta_lights)
    if (!is_black(dl.intensity) && !dl.is_sun_disk()) out.push_back(&dl);
  return out;
}

float LightSampler::area_density(const Entry& e) { return PATHLAB_FAULT(LightPdfWithoutArea) ? 1.0f : 1.0f / e.area; }

LightSampler::LightSampler(const Scene& scene, float scene_radius, const Textures* textures)
    : scene_(&scene),
      textures_(textures),
      light_sampling_(scene.render.light_sampling),
      kind_(scene.render.light_sampler) {
  std::vector<double> power;
  first_entry_.assign(scene.shapes.size(), -1);
  for (std::uint32_t s = 0; s < scene.shapes.size(); ++s) {
    const Shape& shape = scene.shapes[s];
    const Material& m = scene.materials[shape.material];
    // Emitters in groups are not sampled: the scene loader refuses them
    // unless their material says "light": false.
    if (!m.emits() || !m.sampled_as_light || shape.in_group) continue;
    // Flux of a Lambertian emitter: pi * L * area per emitting side.
    const TexturedParam* tex = textures ? m.texture_of(MaterialParam::Emission) : nullptr;
    const Spectrum mean_emission = tex ? glm::max(textures->mean_color(tex->texture), Spectrum(0.0f)) : m.emission;
    const double per_area = double(kPi) * luminance_double(mean_emission) * (m.two_sided_emission ? 2.0 : 1.0);
    first_entry_[s] = static_cast<std::int64_t>(entries_.size());
    if (shape.kind == Shape::Kind::Sphere) {
      const float area = 4.0f * kPi * shape.radius * shape.radius;
      entries_.push_back({s, 0, area, {}});
      power.push_back(per_area * area);
    } else {
      for (std::uint32_t t = 0; t < shape.mesh.triangles.size(); ++t) {
        const float area = triangle_area(shape.mesh, t);
        entries_.push_back({s, t, area, make_triangle(shape, t)});
        power.push_back(per_area * area);
      }
    }
  }
  if (scene.environment && !is_black(*scene.environment)) {
    env_index_ = static_cast<std::int64_t>(entries_.size());
    entries_.push_back({0, 0, 0.0f, {}});
    power.push_back(4.0 * kPi * kPi * double(scene_radius) * scene_radius * luminance_double(*scene.environment));
  }
  // An image: pi r^2 times its luminance integrated over the sphere (the
  // uniform case above is that for a constant map). A black map is no light.
  if (scene.environment_map && scene.environment_map->luminance_integral() > 0.0) {
    env_index_ = static_cast<std::int64_t>(entries_.size());
    entries_.push_back({0, 0, 0.0f, {}});
    power.push_back(kPi * double(scene_radius) * scene_radius * scene.environment_map->luminance_integral());
  }
  // Sun disks: pi r^2 Y(E), as a delta directional light. The cone's size in
  // double: 1 - cos alpha of the sun (about 1e-5) would keep two digits in float.
  for (const DeltaLight& dl : scene.delta_lights) {
    if (!dl.is_sun_disk() || is_black(dl.intensity)) continue;
    const double alpha = dl.angular_radius, sin_alpha = std::sin(alpha);
    const double one_minus_cos = 2.0 * std::sin(0.5 * alpha) * std::sin(0.5 * alpha);
    SunDisk sun;
    sun.frame = Frame(-dl.direction);
    sun.one_minus_cos = static_cast<float>(one_minus_cos);
    sun.sin2 = static_cast<float>(sin_alpha * sin_alpha);
    sun.cone_pdf = static_cast<float>(1.0 / (2.0 * double(kPi) * one_minus_cos));
    sun.Le = Spectrum(dvec3(dl.intensity) / (double(kPi) * sin_alpha * sin_alpha));
    sun.entry = static_cast<std::int64_t>(entries_.size());
    suns_.push_back(sun);
    entries_.push_back({0, 0, 0.0f, {}});
    power.push_back(kPi * double(scene_radius) * scene_radius * luminance_double(dl.intensity));
  }
  build_distribution(power, &pmf_, &cdf_);
  if (kind_ == LightSamplerKind::Bvh) build_bvh(power);

  // Delta lights by power (docs/scene-format.md, "How a light is picked"),
  // each divided by 4 pi so that a point light's weight is the luminance of
  // its intensity, as it was before there were other kinds (same bits).
  std::vector<double> intensity;
  for (const DeltaLight* dl : sampled_delta_lights(scene)) {
    deltas_.push_back(*dl);
    intensity.push_back(delta_power_over_4pi(*dl, scene_radius));
  }
  build_distribution(intensity, &delta_pmf_, &delta_cdf_);
}

void LightSampler::build_bvh(const std::vector<double>& power) {
  // The emitting triangles and spheres of positive power, each bounded by
  // its box and its normals: a triangle's front normal (theta_o = 0), a
  // sphere's every direction (theta_o = pi); Lambertian, so theta_e = pi/2.
  entry_tree_.assign(entries_.size(), -1);
  std::vector<LightBounds> bounds;
  for (std::size_t i = 0; i < entries_.size(); ++i) {
    const bool sky = static_cast<std::int64_t>(i) == env_index_ ||
                     (!suns_.empty() && static_cast<std::int64_t>(i) >= suns_.front().entry);
    if (sky || !(power[i] > 0.0) || !std::isfinite(power[i])) continue;
    const Entry& e = entries_[i];
    const Shape& shape = scene_->shapes[e.shape];
    LightBounds b;
    if (shape.kind == Shape::Kind::Sphere) {
      b.lo = shape.center - vec3(shape.radius);
      b.hi = shape.center + vec3(shape.radius);
      b.cos_o = -1.0f;
    } else {
      b.lo = glm::min(e.triangle.p0, glm::min(e.triangle.p1, e.triangle.p2));
      b.hi = glm::max(e.triangle.p0, glm::max(e.triangle.p1, e.triangle.p2));
      b.axis = e.triangle.n;
      b.cos_o = 1.0f;
    }
    b.cos_e = 0.0f;
    b.phi = power[i];
    b.two_sided = scene_->materials[shape.material].two_sided_emission;
    entry_tree_[i] = static_cast<std::int64_t>(bounds.size());
    tree_entry_.push_back(i);
    bounds.push_back(b);
  }
  bvh_ = std::make_unique<const LightBvh>(std::move(bounds));
  // The sky: each of its lights 1 / (n + 1) of the grid, the tree the rest
  // (all of it without a sky; none without a tree), in whole grid points.
  if (env_index_ >= 0) sky_entry_.push_back(static_cast<std::size_t>(env_index_));
  for (const SunDisk& sun : suns_) sky_entry_.push_back(static_cast<std::size_t>(sun.entry));
  const std::uint64_t tree_slots = bvh_->empty() ? 0 : 1, slots = sky_entry_.size() + tree_slots;
  std::fill(pmf_.begin(), pmf_.end(), 0.0f);
  cdf_.clear();  // nothing picks by it under bvh
  sky_start_.clear();
  for (std::uint64_t j = 0; j <= sky_entry_.size(); ++j)
    sky_start_.push_back(slots == 0 ? kGrid : static_cast<std::uint32_t>((j + tree_slots) * kGrid / slots));
  for (std::size_t j = 0; j < sky_entry_.size(); ++j)
    pmf_[sky_entry_[j]] = static_cast<float>(sky_start_[j + 1] - sky_start_[j]) * 0x1p-24f;
}

std::size_t LightSampler::unsampled_light_count() const {
  if (kind_ == LightSamplerKind::Bvh) {
    // Outside the tree (no power) and no sky share; the tree's lights may
    // be unpickable from some points and not others.
    std::size_t n = 0;
    for (std::size_t i = 0; i < entries_.size(); ++i)
      if (entry_tree_[i] < 0 && pmf_[i] == 0.0f) ++n;
    return n;
  }
  return static_cast<std::size_t>(std::count(pmf_.begin(), pmf_.end(), 0.0f));
}

std::optional<LightSampler::Pick> LightSampler::pick(const LightQuery& ref, float u_choice) const {
  if (entries_.empty()) return std::nullopt;
  if (kind_ == LightSamplerKind::Power) {
    const std::size_t i = pick(cdf_, u_choice);
    return Pick{i, pmf_[i]};
  }
  // The grid point of u, then the tree's walk below the tree's grid points
  // and the sky's entry past them: core/simd/lights-inl.h's light_grid_point
  // and tree_or_sky_pick at width 1, as the wavefront's lanes pick.
  using namespace width1;
  const F k{static_cast<float>(generic::light_grid_point(kScalarD, D1{static_cast<double>(u_choice)}).raw)};
  const std::uint32_t tree_count = bvh_->empty() ? 0 : sky_start_[0];
  const auto walk = [&](lane1::M, F& share) {
    const std::optional<LightBvh::Pick> p = bvh_->pick(ref, static_cast<std::uint32_t>(k.raw), tree_count);
    share = F{p ? static_cast<float>(p->share) : 0.0f};
    return Index{p ? static_cast<std::int64_t>(tree_entry_[p->light]) : 0};
  };
  const auto starts = [this](lane1::M m, F i) {
    return F{m.raw ? static_cast<float>(sky_start_[static_cast<std::size_t>(i.raw)]) : 0.0f};
  };
  const auto sky_entry = [this](lane1::M, F j) {
    return Index{static_cast<std::int64_t>(sky_entry_[static_cast<std::size_t>(j.raw)])};
  };
  const auto pmf_of = [this](lane1::M, Index entry) { return F{pmf_[static_cast<std::size_t>(entry.raw)]}; };
  Index light;
  F pmf;
  if (!generic::tree_or_sky_pick(kScalar, kIndex, lane1::M{true}, k, F{static_cast<float>(tree_count)},
                                 sky_entry_.size(), walk, starts, sky_entry, pmf_of, light, pmf)
           .raw)
    return std::nullopt;
  return Pick{static_cast<std::size_t>(light.raw), pmf.raw};
}

float LightSampler::pick_pmf(const LightQuery& ref, std::size_t entry) const {
  // core/simd/lights-inl.h's pick_pmf at width 1, as the wavefront's lanes.
  using namespace width1;
  const bool in_tree = kind_ == LightSamplerKind::Bvh && entry_tree_[entry] >= 0;
  const auto share = [&](lane1::M) {
    const auto light = static_cast<std::uint32_t>(entry_tree_[entry]);
    return F{static_cast<float>(bvh_->share(ref, light, sky_start_[0]))};
  };
  return generic::pick_pmf(kScalar, lane1::M{in_tree}, F{pmf_[entry]}, share).raw;
}

std::size_t LightSampler::pick(const std::vector<float>& cdf, float u) {
  using namespace width1;
  if (cdf.empty()) return 0;
  if (cdf.size() > kMaxExactFloatIndex) {
    // Beyond the generic search's float indices: the same answer by integers.
    const auto it = std::upper_bound(cdf.begin(), cdf.end(), u);
    return std::min<std::size_t>(static_cast<std::size_t>(it - cdf.begin()), cdf.size() - 1);
  }
  const auto cdf_at = [&](lane1::M m, F i) { return F{m.raw ? cdf[static_cast<std::size_t>(i.raw)] : 0.0f}; };
  return static_cast<std::size_t>(generic::pick_cdf(kScalar, lane1::M{true}, cdf.size(), F{u}, cdf_at).raw);
}

// The sky as this sampler holds it; `entry` is the sun disk sky_sample draws for.
struct LightSampler::SkyView {
  using F = width1::F;
  using F3 = width1::F3;
  const LightSampler& sampler;
  std::size_t entry = 0;
  bool image() const { return sampler.scene_->environment_map != nullptr; }
  lane1::M sample_image(lane1::M, F ux, F uy, F3& wi, F3& Le, F& pdf) const {
    const std::optional<EnvironmentMap::Sample> es = sampler.scene_->environment_map->sample(vec2(ux.raw, uy.raw));
    if (!es) return lane1::M{false};
    wi = width1::lanes(es->wi);
    Le = width1::lanes(es->radiance);
    pdf = F{es->pdf};
    return lane1::M{true};
  }
  void lookup(lane1::M, const F3& dir, F3& Le, F& pdf) const {
    const EnvironmentMap::Lookup m = sampler.scene_->environment_map->lookup(width1::scalars(dir));
    Le = width1::lanes(m.radiance);
    pdf = F{m.pdf};
  }
  F3 radiance() const { return width1::lanes(sampler.scene_->environment.value_or(Spectrum(0.0f))); }
  F env_pmf() const {
    return F{sampler.env_index_ >= 0 ? sampler.pmf_[static_cast<std::size_t>(sampler.env_index_)] : 0.0f};
  }
  void add_suns(const F3& dir, F3& Le, F& pdf) const {
    vec3 L = width1::scalars(Le);
    sampler.add_suns(width1::scalars(dir), &L, &pdf.raw);
    Le = width1::lanes(L);
  }
  void along(lane1::M m, const F3& dir, F3& Le, F& pdf) const {
    width1::generic::sky_along(width1::kScalar, m, dir, *this, Le, pdf);
  }
  void sun_directions(lane1::M, F ux, F uy, F3& wi) const {
    const SunDisk& sun = sampler.suns_[entry - static_cast<std::size_t>(sampler.suns_.front().entry)];
    const Frame& f = sun.frame;
    wi = width1::generic::sun_direction(width1::kScalar, width1::lanes(f.s), width1::lanes(f.t), width1::lanes(f.n),
                                        F{sun.one_minus_cos}, ux, uy);
  }
};

std::optional<LightSample> LightSampler::sample(const LightQuery& query, float u_choice, vec2 u) const {
  const std::optional<Pick> picked = pick(query, u_choice);
  if (!picked) return std::nullopt;
  const std::size_t i = picked->entry;
  const float pmf = picked->pmf;
  const vec3& ref = query.p;
  LightSample ls;
  ls.light = static_cast<std::uint32_t>(i);
  using namespace width1;
  // The environment or a sun disk: core/simd/lights-inl.h's sky_sample at
  // width 1. Not where the image drew nothing, or a sun's direction rounded
  // out of its cone.
  const auto sample_sky = [&](lane1::M m) {
    F3 wi, Le;
    F pdf;
    const lane1::M env{static_cast<std::int64_t>(i) == env_index_};
    const lane1::M ok = generic::sky_sample(kScalar, m, env, F{u.x}, F{u.y}, SkyView{*this, i}, wi, Le, pdf);
    ls.wi = scalars(wi);
    ls.Le = scalars(Le);
    ls.pdf = pdf.raw;
    ls.dist = kInfinity;
    ls.infinite = true;
    return ok;
  };
  // A triangle or a sphere: area_light_sample at width 1. Not where the
  // point is at no distance, on a one-sided emitter's back, or edge-on.
  const auto sample_area = [&](lane1::M m) {
    const Entry& e = entries_[i];
    const generic::AreaLight<F, lane1::M> light = area_light(*scene_, e);
    const auto solid_angle = [&](lane1::M mask) {
      return solid_angle_draw(light, light_sampling_, ref, mask, true, u);
    };
    generic::AreaLightSample<F> s;
    const lane1::M ok = generic::area_light_sample(kScalar, m, lanes(ref), light, F{pmf}, F{u.x}, F{u.y}, solid_angle,
                                                   PATHLAB_FAULT(LightPdfWithoutDistance), s);
    if (!ok.raw) return ok;
    ls.p = scalars(s.p);
    ls.p_error = scalars(s.error);
    ls.n = scalars(s.n);
    ls.wi = scalars(s.wi);
    ls.dist = s.dist.raw;
    ls.pdf = s.pdf.raw;
    ls.Le = emission_at_point(i, vec2(s.b1.raw, s.b2.raw), ls.p);
    return ok;
  };
  lane1::M sky;
  if (!generic::sky_or_area_sample(kScalar, lane1::M{true}, Index{static_cast<std::int64_t>(i)},
                                   Index{static_cast<std::int64_t>(first_sky_entry())}, sky, sample_sky, sample_area)
           .raw)
    return std::nullopt;
  return ls;
}

Spectrum LightSampler::emission_at_point(std::size_t i, vec2 b, const vec3& p) const {
  const Entry& e = entries_[i];
  const Shape& shape = scene_->shapes[e.shape];
  const Material& m = scene_->materials[shape.material];
  if (!(textures_ && m.emission_textured)) return m.emission;
  // The texture at the point's uv, as CompiledScene::resolve gives a hit there.
  const vec2 uv = shape.kind == Shape::Kind::Sphere ? sphere_uv((p - shape.center) / shape.radius)
                                                    : shape.mesh.uv_at(e.prim, b);
  return emission_at(m, textures_, uv);
}

float LightSampler::pdf(const LightQuery& query, const Surfel& hit) const {
  const std::int64_t first = first_entry_[hit.shape];
  if (first < 0) return 0.0f;
  const std::size_t i = static_cast<std::size_t>(first) + hit.prim;
  const vec3& ref = query.p;
  const float pmf = pick_pmf(query, i);
  // core/simd/lights-inl.h's emitter_hit_pdf at width 1, as the lanes take it.
  using namespace width1;
  const auto solid_angle = [&](lane1::M m) {
    if (light_sampling_ != LightSampling::SolidAngle) return no_solid_angle();  // area_light only when needed
    return solid_angle_draw(area_light(*scene_, entries_[i]), light_sampling_, ref, m, false, vec2(0.0f));
  };
  const bool zero_unpicked = kind_ == LightSamplerKind::Bvh || light_sampling_ == LightSampling::SolidAngle;
  return generic::emitter_hit_pdf(kScalar, lane1::M{true}, lanes(ref), lanes(hit.p), lanes(hit.n), F{pmf},
                                  F{area_density(entries_[i])}, zero_unpicked, solid_angle,
                                  PATHLAB_FAULT(LightPdfWithoutDistance))
      .raw;
}

void LightSampler::add_suns(const vec3& dir, Spectrum* Le, float* pdf) const {
  using namespace width1;
  F3 L = lanes(*Le);
  F p{*pdf};
  for (const SunDisk& sun : suns_)
    generic::add_sun(kScalar, lanes(dir), lanes(sun.frame.n), F{sun.sin2}, lanes(sun.Le), F{sun_pdf(sun)}, L, p);
  *Le = scalars(L);
  *pdf = p.raw;
}

LightSampler::Sky LightSampler::sky(const vec3& dir) const {
  using namespace width1;
  F3 Le;
  F pdf;
  generic::sky_along(kScalar, lane1::M{true}, lanes(dir), SkyView{*this}, Le, pdf);
  return {scalars(Le), pdf.raw};
}

std::optional<LightSample> LightSampler::sample_delta(const vec3& ref, float u_choice) const {
  if (deltas_.empty()) return std::nullopt;
  // core/simd/lights-inl.h's delta_light_sample at width 1, as the
  // wavefront's lanes sample.
  using namespace width1;
  const auto pick_delta = [this](lane1::M, F u) { return Index{static_cast<std::int64_t>(pick(delta_cdf_, u.raw))}; };
  const auto light_of = [this](lane1::M, Index i) {
    const DeltaLight& light = deltas_[static_cast<std::size_t>(i.raw)];
    return generic::DeltaLightLanes<F, lane1::M>{lane1::M{light.kind == DeltaLight::Kind::Directional},
                                                 lane1::M{light.kind == DeltaLight::Kind::Spot},
                                                 lanes(light.position),
                                                 lanes(light.direction),
                                                 lanes(light.intensity),
                                                 F{light.cos_outer},
                                                 F{light.cos_inner},
                                                 F{delta_pmf_[static_cast<std::size_t>(i.raw)]}};
  };
  lane1::M seen{true};
  generic::DeltaLightLanes<F, lane1::M> light;
  F3 wi, Le;
  F dist;
  const Index i = generic::delta_light_sample(kScalar, seen, F{u_choice}, lanes(ref), pick_delta, light_of, light, wi,
                                              dist, Le);
  if (!seen.raw) return std::nullopt;  // at the point itself, or outside the spot's cone
  LightSample ls;
  ls.light = static_cast<std::uint32_t>(i.raw);
  ls.pdf = light.pmf.raw;
  ls.wi = scalars(wi);
  ls.dist = dist.raw;
  ls.Le = scalars(Le);
  const bool directional = light.directional.raw;
  // A directional light's shadow ray escapes (infinite): nothing may block
  // it anywhere. A point has no surface: its ray ends as if at one facing
  // the shading point.
  ls.infinite = directional;
  if (!directional) {
    ls.p = scalars(light.position);
    ls.n = -ls.wi;
  }
  return ls;
}

}  // namespace pathlab
