#include "reference/reference_tracer.h"

#include "core/faults.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "core/scene_limits.h"
#include "core/strategy_weights.h"

#include <optional>

namespace pathlab {

// What one pixel sample carries down the recursion.
struct ReferenceTracer::Path {
  SampleStream rng;
  PathObserver* observer;
  std::uint32_t rays = 0;
  std::uint32_t hits = 0;
  // Textured scenes only: the cone the current ray carries, and where its
  // hit's evaluated parameters go (one suffices: a vertex is done with its
  // Surfel before the path goes on).
  RayCone cone{};
  SurfaceParams* params = nullptr;
  float u(int vertex, Dim dim) const { return rng.get(static_cast<std::uint32_t>(vertex), dim); }
  // A 2D pair: u(vertex, x), u(vertex, x + 1) (SampleStream::get2).
  vec2 u2(int vertex, Dim x) const {
    const SampleStream::Pair p = rng.get2(static_cast<std::uint32_t>(vertex), x);
    return vec2(p.x, p.y);
  }
  // The key of the rays leaving `vertex` (core/alpha.h).
  std::uint32_t alpha_key(const CompiledScene& scene, int vertex) const {
    return PATHLAB_FAULT(AlphaKeysNotSet) ? 0u : scene.alpha_key(rng, vertex);
  }
};

Spectrum ReferenceTracer::Li(const Ray& ray, int vertex, const PreviousVertex& prev, const Spectrum& beta,
                             Path& path) const {
  const CompiledScene& scene = scene_;
  Surfel s;
  ++path.rays;
  if (!scene.intersect(ray, &s, path.cone, path.params)) {
    // A ray Embree refuses (NaN or beyond 1.8e18) makes the sample bad.
    if (!embree_accepts(ray)) return Spectrum(std::numeric_limits<float>::quiet_NaN());
    const LightSampler::Sky sky = scene.lights().sky(ray.dir);
    const Spectrum Le = sky.Le;
    const float w = is_black(Le) ? 0.0f : emission_weight(settings_.strategy, prev, sky.pdf);
    if (path.observer) {
      path.observer->on_escape({vertex, Le, w, beta * w * Le});
      path.observer->on_end({vertex, PathEnd::Escaped});
    }
    return w * Le;
  }

  ++path.hits;
  const vec3 wo = -ray.dir;
  const Spectrum Le = s.emitted(wo);
  const float w_e = is_black(Le) ? 0.0f : emission_weight(settings_.strategy, prev, scene.lights().pdf(prev.ref, s));
  Spectrum L = w_e * Le;
  if (path.observer)
    path.observer->on_hit({vertex, s.p, s.n, glm::dot(s.n, wo) > 0.0f,
                           static_cast<std::uint32_t>(s.material - scene.scene().materials.data()), s.shape, s.prim,
                           s.instance, Le, w_e, beta * L, beta});

  const int cap = max_vertex(settings_);
  if (vertex > cap) {
    if (path.observer) path.observer->on_end({vertex, PathEnd::MaxDepth});
    return L;
  }
  if (!s.material->scatters()) {
    if (path.observer) path.observer->on_end({vertex, PathEnd::Absorbed});
    return L;
  }

  // Light a ray cannot find: point, spot and directional lights, in every strategy.
  L += direct_delta(s, wo, vertex, beta, path);

  // Light a ray can find, as the strategy says.
  const Strategy strategy = settings_.strategy;
  // The Technique number, drawn when a technique rule below first asks
  // (only light+bsdf's do) and kept for the other.
  std::optional<float> technique;
  const auto u_technique = [&] {
    if (!technique) technique = path.u(vertex, Dim::Technique);
    return *technique;
  };
  if (samples_area_lights(strategy, u_technique)) L += direct_area(s, wo, vertex, beta, path);

  // Continue the path.
  const vec2 u_dir = path.u2(vertex, Dim::DirectionX);
  bool cosine = false;
  const std::optional<BsdfSample> bs = scatter_for(strategy, s, wo, path.u(vertex, Dim::LobeChoice), u_dir, &cosine);
  if (!bs || is_black(bs->weight)) {
    if (path.observer) path.observer->on_end({vertex, bs ? PathEnd::NoSample : PathEnd::Absorbed});
    return L;
  }
  Spectrum weight = bs->weight;
  float survival = 1.0f;
  // Russian roulette: survive in proportion to the throughput, so that paths
  // which carry little end early; the survivors' weight is divided by the
  // probability, which keeps the estimate unbiased.
  if (vertex > settings_.rr_depth) {
    if (!survives_roulette(beta, path.u(vertex, Dim::Roulette), &weight, &survival)) {
      if (path.observer) {
        path.observer->on_scatter({vertex, bs->lobe, bs->impulse, cosine, bs->wi, bs->pdf, weight, survival, Spectrum(0.0f)});
        path.observer->on_end({vertex, PathEnd::Roulette});
      }
      return L;
    }
    if (PATHLAB_FAULT(RouletteNotReweighted)) weight = bs->weight;
  }
  const Spectrum beta_next = beta * weight;
  Ray next_ray = s.spawn(bs->wi);
  next_ray.alpha_key = path.alpha_key(scene_, vertex);
  if (path.observer)
    path.observer->on_scatter(
        {vertex, bs->lobe, bs->impulse, cosine, bs->wi, bs->pdf, weight, survival, beta_next, next_ray});

  const PreviousVertex next = previous_vertex(strategy, s, wo, *bs, u_technique);
  if (path.params)
    path.cone = scattered_cone(path.cone, glm::length(s.p - ray.origin), bs->impulse, bs->pdf, settings_.texture_filter);
  return L + weight * Li(next_ray, vertex + 1, next, beta_next, path);
}

Spectrum ReferenceTracer::direct_delta(const Surfel& s, const vec3& wo, int vertex, const Spectrum& beta,
                                       Path& path) const {
  const LightSampler& lights = scene_.lights();
  if (!lights.has_delta_lights()) return Spectrum(0.0f);
  const std::optional<LightSample> ls = lights.sample_delta(s.p, path.u(vertex, Dim::DeltaLightChoice));
  if (!ls) {
    if (path.observer) path.observer->on_light(rejected_light_event(vertex, true, nullptr, LightRejection::NoSample));
    return Spectrum(0.0f);
  }
  const Spectrum f = s.eval(ls->wi, wo);
  if (is_black(f)) {
    if (path.observer)
      path.observer->on_light(rejected_light_event(vertex, true, &*ls, black_light_sample_reason(s.n, ls->wi, wo)));
    return Spectrum(0.0f);
  }
  ++path.rays;
  Ray shadow = shadow_ray(s, *ls);
  shadow.alpha_key = path.alpha_key(scene_, vertex);
  const bool visible = !scene_.occluded(shadow);
  const Spectrum L = visible ? delta_light_contribution(f, ls->Le, ls->pdf) : Spectrum(0.0f);
  if (path.observer)
    path.observer->on_light(
        {vertex, true, ls->infinite, ls->light, ls->p, ls->wi, ls->dist, ls->pdf, ls->Le, visible, 1.0f, beta * L, shadow});
  return L;
}

Spectrum ReferenceTracer::direct_area(const Surfel& s, const vec3& wo, int vertex, const Spectrum& beta,
                                      Path& path) const {
  const std::optional<LightSample> ls = scene_.lights().sample(
      light_query(s, wo), path.u(vertex, Dim::LightChoice), path.u2(vertex, Dim::LightX));
  if (!ls) {
    if (path.observer && scene_.lights().has_area_lights())
      path.observer->on_light(rejected_light_event(vertex, false, nullptr, LightRejection::NoSample));
    return Spectrum(0.0f);
  }
  const Spectrum f = s.eval(ls->wi, wo);
  if (is_black(f)) {
    if (path.observer)
      path.observer->on_light(rejected_light_event(vertex, false, &*ls, black_light_sample_reason(s.n, ls->wi, wo)));
    return Spectrum(0.0f);
  }
  const float w = light_sample_weight(settings_.strategy, ls->pdf, s.pdf(ls->wi, wo));
  ++path.rays;
  Ray shadow = shadow_ray(s, *ls);
  shadow.alpha_key = path.alpha_key(scene_, vertex);
  const bool visible = !scene_.occluded(shadow);
  const Spectrum L = visible ? light_contribution(f, ls->Le, w, ls->pdf) : Spectrum(0.0f);
  if (path.observer)
    path.observer->on_light(
        {vertex, false, ls->infinite, ls->light, ls->p, ls->wi, ls->dist, ls->pdf, ls->Le, visible, w, beta * L, shadow});
  return L;
}

FilmSample ReferenceTracer::trace_sample(std::uint32_t x, std::uint32_t y, std::uint32_t sample,
                                         PathObserver* observer) const {
  Path path{stream(x, y, sample), observer};
  std::optional<SurfaceParams> params;
  if (scene_.has_textures()) {
    params.emplace();
    path.params = &*params;
    path.cone = scene_.camera_cone(settings_.texture_filter);
  }
  FilmSample fs;
  fs.film = vec2(static_cast<float>(x), static_cast<float>(y)) + path.u2(0, Dim::FilmX);
  Ray ray = scene_.camera().generate_ray(fs.film, [&] { return path.u2(0, Dim::LensX); });
  ray.alpha_key = path.alpha_key(scene_, 0);
  if (observer) observer->on_camera({x, y, sample, fs.film, ray.origin, ray.dir});
  fs.L = Li(ray, 1, PreviousVertex{}, Spectrum(1.0f), path);
  fs.rays = path.rays;
  fs.hits = path.hits;
  if (observer) observer->on_result(fs.L);
  return fs;
}

void ReferenceTracer::render_batch(std::uint32_t first, std::uint32_t count, std::span<FilmSample> out) const {
  const int width = scene_.scene().film.width;
  const int height = scene_.scene().film.height;
  parallel_for(0, static_cast<std::size_t>(height), 1, [&](std::size_t y0, std::size_t y1) {
    for (std::size_t y = y0; y < y1; ++y)
      for (int x = 0; x < width; ++x) {
        const std::size_t pixel = y * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
        for (std::uint32_t j = 0; j < count; ++j)
          out[pixel * count + j] =
              trace_sample(static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y), first + j, nullptr);
      }
  });
}

}  // namespace pathlab
