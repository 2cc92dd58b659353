#include "wavefront/wavefront_tracer.h"

#include "core/bsdf/disney.h"
#include "core/environment_map.h"
#include "core/faults.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "core/scene_limits.h"
#include "core/strategy_weights.h"
#include "core/simd/simd.h"
#include "wavefront/vector_stages.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <optional>
#include <type_traits>

namespace pathlab {

// One wave's clock: the time of its queries of each kind and of the whole
// wave, in nanoseconds (indexed by Clocked), and the rays of each kind. A
// clock read per batch of rays, not per ray.
struct WavefrontTracer::Clock {
  std::uint64_t nanoseconds[kClocked] = {}, queries[kWave] = {};
  // A batch of n queries of `kind` that started at clock_ns() == t0.
  void batch(Clocked kind, std::uint64_t t0, std::size_t n);
  // Stage `stage` ran from *t to now; *t becomes now (the next stage's start).
  void stage(WavefrontStage stage, std::uint64_t* t);
};

const char* wavefront_stage_name(WavefrontStage stage) {
  switch (stage) {
    case WavefrontStage::Camera: return "camera";
    case WavefrontStage::Resolve: return "resolve";
    case WavefrontStage::Emission: return "emission";
    case WavefrontStage::Lights: return "light samples";
    case WavefrontStage::AddLight: return "add light";
    case WavefrontStage::Scatter: return "scatter";
    case WavefrontStage::Compact: return "compact";
  }
  return "?";
}

// The state of every path of a wave, one array per field. The paths still
// being traced occupy slots [0, n), in the order they were created: after
// each bounce compact() writes out the finished ones and moves the
// survivors down (a stable compaction), so every stage walks its arrays
// front to back with no index list and no holes. One thread runs a wave
// through all its stages; threads run different waves.
struct WavefrontTracer::Wave {
  std::size_t n = 0;  // live paths
  Clock clock;
  // Identity and output. x, y and sample are read only when the camera ray
  // is made; the rest is moved with the path.
  std::vector<std::uint32_t> out_index, x, y, sample;
  std::vector<SampleStream> rng;
  std::vector<vec2> film;
  // The path so far; moved with the path.
  std::vector<Ray> ray;
  std::vector<Spectrum> beta, L;
  std::vector<PreviousVertex> prev;
  std::vector<std::int32_t> vertex;  // the vertex the current ray will reach
  std::vector<std::uint32_t> rays;
  // Textured scenes only (sized by textured()): the ray's cone, moved with
  // the path, and the hit's evaluated parameters, this bounce only.
  std::vector<RayCone> cone;
  std::vector<SurfaceParams> params;
  // This bounce only.
  std::vector<std::uint8_t> alive;
  std::vector<Surfel> surfel;
  std::vector<RayHit> hit;
  std::vector<std::uint8_t> found;
  // Two shadow rays per path: [0] a point light, [1] an area light.
  std::vector<Ray> shadow;
  std::vector<LightSample> light;
  std::vector<Spectrum> unoccluded;  // f Le w / pdf, before visibility
  std::vector<float> light_weight;
  // 0 none, 1 to trace, 2 visible, 3 occluded; with an observer only,
  // 4 + LightRejection: rejected before a shadow ray (reported, adds nothing).
  std::vector<std::uint8_t> shadow_state;
  // Scratch for the pending shadow rays: the rays, whose slot each belongs
  // to, and whether it is blocked.
  std::vector<Ray> query;
  std::vector<std::uint32_t> query_slot;
  std::vector<std::uint8_t> query_result;
  // render_batch_recording only: where each path's state at vertex
  // record_vertex goes (indexed by out_index); null otherwise.
  StageRecord* record = nullptr;
  int record_vertex = 0;

  void resize(std::size_t size) {
    out_index.resize(size), x.resize(size), y.resize(size), sample.resize(size), rng.resize(size, SampleStream(0, 0, 0));
    film.resize(size), ray.resize(size), beta.resize(size), L.resize(size), prev.resize(size), vertex.resize(size);
    rays.resize(size), alive.resize(size), surfel.resize(size), hit.resize(size), found.resize(size);
    shadow.resize(2 * size), light.resize(2 * size), unoccluded.resize(2 * size), light_weight.resize(2 * size);
    shadow_state.resize(2 * size);
    query.resize(2 * size), query_slot.resize(2 * size), query_result.resize(2 * size);
    // A thread's wave that once served a textured scene keeps its cones, and
    // move() copies them whenever there are any: they must grow with the rest
    // (a textured render, then a larger untextured one, wrote past them).
    if (!cone.empty()) textured(size);
  }
  // A finished path's sample. Its last ray reached vertex `vertex` unless it
  // found nothing.
  FilmSample result(std::size_t i) const {
    const auto hits = static_cast<std::uint32_t>(vertex[i] - (found[i] ? 0 : 1));
    return FilmSample{film[i], L[i], rays[i], hits};
  }
  // Slot `from`'s path into slot `to` (to < from): the fields that outlive a
  // bounce (x, y and sample are read only by the camera stage).
  void move(std::size_t from, std::size_t to) {
    out_index[to] = out_index[from], rng[to] = rng[from], film[to] = film[from], ray[to] = ray[from];
    beta[to] = beta[from], L[to] = L[from], prev[to] = prev[from], vertex[to] = vertex[from], rays[to] = rays[from];
    if (!cone.empty()) cone[to] = cone[from];
  }
  std::size_t capacity() const { return out_index.size(); }
  // Room for the texture state too (the thread's wave may have served an
  // untextured scene before).
  void textured(std::size_t size) {
    if (cone.size() < size) cone.resize(size), params.resize(size);
  }
  float u(std::size_t i, Dim dim) const { return rng[i].get(static_cast<std::uint32_t>(vertex[i]), dim); }
  // A 2D pair: u(i, x), u(i, x + 1) (SampleStream::get2).
  vec2 u2(std::size_t i, Dim first) const {
    const SampleStream::Pair p = rng[i].get2(static_cast<std::uint32_t>(vertex[i]), first);
    return vec2(p.x, p.y);
  }
};

namespace {

// "a", "a and b", "a, b and c": names listed in a stage description.
std::string list_names(const std::vector<std::string>& names) {
  std::string l;
  for (std::size_t i = 0; i < names.size(); ++i) l += (i == 0 ? "" : i + 1 == names.size() ? " and " : ", ") + names[i];
  return l;
}
// `name` appended to `names` unless it is there already.
void add_name(std::vector<std::string>& names, const std::string& name) {
  if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
}
std::uint64_t clock_ns() {
  return static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count());
}
}  // namespace

void WavefrontTracer::Clock::stage(WavefrontStage stage, std::uint64_t* t) {
  const std::uint64_t now = clock_ns();
  nanoseconds[kFirstStage + static_cast<int>(stage)] += now - *t;
  *t = now;
}

void WavefrontTracer::Clock::batch(Clocked kind, std::uint64_t t0, std::size_t n) {
  nanoseconds[kind] += clock_ns() - t0;
  queries[kind] += n;
}

void WavefrontTracer::publish(const Clock& clock) const {
  for (int k = 0; k < kClocked; ++k) nanoseconds_[k].fetch_add(clock.nanoseconds[k], std::memory_order_relaxed);
  for (int k = 0; k < kWave; ++k) rays_[k].fetch_add(clock.queries[k], std::memory_order_relaxed);
}

std::size_t WavefrontTracer::scalar_bytes_per_path() {
  return 4 * sizeof(std::uint32_t) + sizeof(SampleStream) + sizeof(vec2) + sizeof(Ray) + 2 * sizeof(Spectrum) +
         sizeof(PreviousVertex) + sizeof(std::int32_t) + sizeof(std::uint32_t) + 1 + sizeof(Surfel) + sizeof(RayHit) +
         1 + 2 * (sizeof(Ray) + sizeof(LightSample) + sizeof(Spectrum) + sizeof(float) + 1) +
         2 * (sizeof(Ray) + sizeof(std::uint32_t) + 1);
}

// What the vectorised stages read of the scene (vector_stages.h), and the
// storage of its tables. Exists when the processor and the scene allow
// them.
struct WavefrontTracer::VectorStages {
  vector_stages::Scene scene;
  vector_stages::Camera camera;
  std::vector<float> inv_area, light_triangle, shape, light_columns, shape_columns, delta_table, energy, sun_table,
      sky_starts, sky_entries, env_row_cdf, env_column_cdf, light_sphere, light_textured, vertex_normals,
      triangle_uvs, vertex_tangents, placements;
  // What core shades or samples path by path (stages_description): the
  // materials by name, then shapes' shading frames and lights.
  std::vector<std::string> general_materials, general;
  std::vector<std::int32_t> bvh_entry, bvh_light;

  // Null, with *why_not saying what stops it, unless the selected SIMD
  // target is a vector one (and the scene's tables fit the gathers' indices).
  static std::unique_ptr<const VectorStages> make(const CompiledScene& compiled, const RenderSettings& settings,
                                                  const SamplerSetup& sampler, std::string* why_not) {
    namespace vs = vector_stages;
    auto no = [&](std::string why) {
      *why_not = std::move(why);
      return nullptr;
    };
    if (!vs::cpu_supported())
      return no("the SIMD target is scalar (--simd scalar, PATHLAB_SIMD=scalar, or a processor without SSE4.1)");
    auto v = std::make_unique<VectorStages>();
    vs::Scene& sc = v->scene;
    sc.strategy = settings.strategy;
    sc.rr_depth = settings.rr_depth;
    sc.max_vertex = max_vertex(settings);
    // Lambert surfaces (shaded by lambert.h, not through the Disney
    // closure), Disney surfaces (disney-inl.h; with one min_pdf), mirrors and
    // dielectrics, textured or not, in the geometric normal's frame or their
    // own, are shaded in the lanes (in_lanes below); any other surface that
    // scatters (a Lambert one under the General shading path) by core's
    // Surfel, path by path (vector_stages.h).
    const Scene& scene = compiled.scene();
    const Material* diffuse = nullptr;
    const bool cosine = settings.strategy == Strategy::Cosine;  // every surface by scatter_cosine
    if (cosine) v->general.push_back("every surface's scatter (strategy cosine)");
    for (const Material& m : scene.materials) {
      if (m.type == MaterialType::Emissive) continue;  // never scatters
      if (!in_lanes(m)) {
        v->general_materials.push_back("'" + m.name + "'");
        continue;
      }
      if (const unsigned lobes = disney_features(m); lobes != 0) {
        // The lobes are the scene's ShadingPath's, the same for every material (configure_shading), and so is
        // the glossy lobes' sampling (the render's bsdf_sampling).
        const bool cospow = m.shading.sampling == BsdfSampling::Cospow;
        if (sc.disney != 0 && sc.disney != lobes) return no("Disney materials shaded with different lobes");
        if (sc.disney != 0 && sc.disney_cospow != cospow) return no("Disney materials sampled in different ways");
        sc.disney = lobes;
        sc.disney_cospow = cospow;
      }
      if (m.type != MaterialType::Diffuse && m.type != MaterialType::Disney) continue;
      if (diffuse && m.shading.min_pdf != diffuse->shading.min_pdf) return no("materials with different min_pdf");
      diffuse = &m;
    }
    if (diffuse) sc.min_pdf = diffuse->shading.min_pdf;
    // Hits on instances are placed in the lanes by their instance's transforms (PlacementField).
    sc.instanced = !scene.instances.empty();
    if (sc.instanced) {
      if (compiled.placements().size() >= (std::size_t{1} << 26)) return no("more than 2^26 instances");
      const auto column = [&](const auto& c) { v->placements.insert(v->placements.end(), {c.x, c.y, c.z}); };
      for (const CompiledScene::Placement& pl : compiled.placements()) {
        for (int c = 0; c < 4; ++c) column(pl.to_world[c]);
        for (int c = 0; c < 4; ++c) column(pl.to_local[c]);
        for (int c = 0; c < 3; ++c) column(pl.to_normal[c]);
        // Whether it mirrors (the tangent frame's handedness), as core decided it (Placement::mirrors).
        v->placements.push_back(pl.mirrors ? 1.0f : 0.0f);
      }
      static_assert(vs::kToLocal == 12 && vs::kToNormal == 24 && vs::kMirrors == 33 && vs::kPlacementFloats == 34);
      sc.placements = v->placements.data();
    }
    // Alpha is decided inside Embree by the rays' keys, which the lanes make too.
    sc.alpha = compiled.has_alpha();
    // Textured hits are resolved in the lanes (uv, frame, normal map, each
    // path's ray cone), which ask core only for their texels (OpenImageIO's
    // TextureSystem, per lane), textured emission included.
    sc.textured = compiled.has_textures();
    if (sc.textured) {
      const RayCone cone = compiled.camera_cone(settings.texture_filter);
      sc.camera_cone_width = cone.width;
      sc.camera_cone_spread = cone.spread;
      sc.texture_filter = static_cast<std::uint8_t>(settings.texture_filter);
    }
    // The lanes sample triangle and sphere lights (by area or in solid
    // angle), the sky and delta lights; the rest is core's (below).
    const LightSampler& lights = compiled.lights();
    // Delta lights: a second light sample and shadow ray per path, in the lanes.
    if (lights.has_delta_lights()) {
      for (std::size_t i = 0; i < lights.delta_lights().size(); ++i) {
        const DeltaLight& d = lights.delta_lights()[i];
        float f[vs::kDeltaFields] = {};
        const vs::DeltaKind kind = d.kind == DeltaLight::Kind::Spot          ? vs::kDeltaSpot
                                   : d.kind == DeltaLight::Kind::Directional ? vs::kDeltaDirectional
                                                                             : vs::kDeltaPoint;
        f[vs::kDeltaKind] = static_cast<float>(kind);
        for (int c = 0; c < 3; ++c) {
          f[vs::kDeltaPosition + c] = d.position[c];
          f[vs::kDeltaDirection + c] = d.direction[c];
          f[vs::kDeltaIntensity + c] = d.intensity[c];
        }
        f[vs::kDeltaCosOuter] = d.cos_outer;
        f[vs::kDeltaCosInner] = d.cos_inner;
        f[vs::kDeltaPmf] = lights.delta_pmf()[i];
        v->delta_table.insert(v->delta_table.end(), std::begin(f), std::end(f));
      }
      sc.deltas = {lights.delta_lights().size(), lights.delta_cdf().data(), v->delta_table.data()};
    }
    // The lanes sample triangle and sphere lights (by area or in solid angle)
    // and the sky; the rest (below) is sampled by LightSampler::sample(), path
    // by path.
    std::vector<std::string> other_lights;
    if (const EnvironmentMap* map = scene.environment_map.get();
        map && std::size_t(map->width()) * std::size_t(map->height() + 1) * 3 >= (std::size_t{1} << 31))
      other_lights.push_back("an environment image of 2^29 texels or more");  // beyond the gathers' indices
    sc.solid_angle = lights.light_sampling() == LightSampling::SolidAngle;
    // Emitters placed by instances are no light entries (the loader takes them
    // only as emitters no light sample aims at): found by rays alone, their
    // density is 0 (triangle_light_pdf: no kFirstLight), as pdf() says.
    sc.sky = lights.samples_environment();
    sc.general_lights = !other_lights.empty();
    if (sc.general_lights) {
      std::string what = "the light samples (";
      for (std::size_t i = 0; i < other_lights.size(); ++i) what += (i ? ", " : "") + other_lights[i];
      v->general.push_back(what + ")");
    }
    // The tables the lanes' own sampler reads (triangles by area, then the sky).
    if (!sc.general_lights) {
      vs::Sky& sky = sc.skies;
      const std::span<const LightSampler::SunDisk> suns = lights.sun_disks();
      const std::int64_t env = lights.environment_entry();
      sky.first_entry = lights.first_sky_entry();
      sky.environment = env;
      const Spectrum env_Le = scene.environment.value_or(Spectrum(0.0f));
      for (int c = 0; c < 3; ++c) sky.Le[c] = env_Le[c];
      sky.pmf = env >= 0 ? lights.pmf()[static_cast<std::size_t>(env)] : 0.0f;
      if (const EnvironmentMap* map = scene.environment_map.get()) {
        sky.image = &map->texels().pixels.front().x;
        sky.width = static_cast<float>(map->width());
        sky.height = static_cast<float>(map->height());
        for (int c = 0; c < 3; ++c)
          for (int r = 0; r < 3; ++r) {
            sky.to_local[3 * c + r] = map->to_local()[c][r];
            sky.to_world[3 * c + r] = map->to_world()[c][r];
          }
        const Distribution2D& dist = map->distribution();
        const std::span<const float> rows = dist.marginal().cdf();
        v->env_row_cdf.assign(rows.begin(), rows.end());
        for (int y = 0; y < map->height(); ++y) {
          const std::span<const float> columns = dist.conditional(static_cast<std::size_t>(y)).cdf();
          v->env_column_cdf.insert(v->env_column_cdf.end(), columns.begin(), columns.end());
        }
        sky.row_cdf = v->env_row_cdf.data();
        sky.column_cdf = v->env_column_cdf.data();
      }
      for (const LightSampler::SunDisk& sun : suns) {
        float f[vs::kSunFields] = {};
        for (int c = 0; c < 3; ++c) {
          f[vs::kSunS + c] = sun.frame.s[c];
          f[vs::kSunT + c] = sun.frame.t[c];
          f[vs::kSunN + c] = sun.frame.n[c];
          f[vs::kSunLe + c] = sun.Le[c];
        }
        f[vs::kSunOneMinusCos] = sun.one_minus_cos;
        f[vs::kSunSin2] = sun.sin2;
        f[vs::kSunPdf] = lights.sun_pdf(sun);
        f[vs::kSunEntry] = static_cast<float>(sun.entry);
        v->sun_table.insert(v->sun_table.end(), std::begin(f), std::end(f));
      }
      sky.suns = suns.size();
      sky.sun = v->sun_table.data();
      for (const std::uint32_t start : lights.sky_starts()) v->sky_starts.push_back(static_cast<float>(start));
      for (const std::size_t entry : lights.sky_entries()) v->sky_entries.push_back(static_cast<float>(entry));
      sky.count = v->sky_entries.size();
      sky.starts = v->sky_starts.data();
      sky.entries = v->sky_entries.data();
      for (std::size_t i = 0; i < lights.entries().size(); ++i) {
        if (i >= sky.first_entry) {  // the sky's: no triangle
          v->light_triangle.insert(v->light_triangle.end(), 16, 0.0f);
          v->inv_area.push_back(0.0f);
          v->light_sphere.push_back(0.0f);
          v->light_textured.push_back(0.0f);
          continue;
        }
        const LightSampler::Entry& e = lights.entries()[i];
        const Shape& shape = scene.shapes[e.shape];
        const Material& m = scene.materials[shape.material];
        const Triangle& t = e.triangle;
        const bool sphere = shape.kind == Shape::Kind::Sphere;
        const vec3 sphere_fields(shape.radius, shape.flip_normals ? 1.0f : 0.0f, 0.0f);
        for (const vec3& c : {sphere ? shape.center : t.p0, sphere ? sphere_fields : t.p1, t.p2, t.n, m.emission})
          v->light_triangle.insert(v->light_triangle.end(), {c.x, c.y, c.z});
        v->light_sphere.push_back(sphere ? 1.0f : 0.0f);
        v->light_textured.push_back(m.emission_textured ? 1.0f : 0.0f);
        v->light_triangle.push_back(m.two_sided_emission ? 1.0f : 0.0f);
        v->inv_area.push_back(LightSampler::area_density(e));
      }
      const std::size_t n_lights = lights.entries().size();
      if (n_lights >= 1 && n_lights <= 16) {  // small enough to keep by column
        v->light_columns.assign(16 * vs::kLightColumns, 0.0f);
        for (std::size_t l = 0; l < n_lights; ++l) {
          for (int f = 0; f < vs::kLightCdf; ++f) v->light_columns[16 * f + l] = v->light_triangle[16 * l + f];
          if (!lights.cdf().empty()) v->light_columns[16 * vs::kLightCdf + l] = lights.cdf()[l];  // none under bvh
          v->light_columns[16 * vs::kLightPmf + l] = lights.pmf()[l];
          v->light_columns[16 * vs::kLightInvArea + l] = v->inv_area[l];
        }
      }
      sc.lights = {n_lights, lights.cdf().data(), lights.pmf().data(), v->inv_area.data(), v->light_triangle.data(),
                   v->light_columns.empty() ? nullptr : v->light_columns.data()};
      sc.lights.bvh = lights.light_sampler() == LightSamplerKind::Bvh;
      if (std::find(v->light_sphere.begin(), v->light_sphere.end(), 1.0f) != v->light_sphere.end())
        sc.lights.sphere = v->light_sphere.data();
      if (std::find(v->light_textured.begin(), v->light_textured.end(), 1.0f) != v->light_textured.end()) {
        sc.lights.textured = v->light_textured.data();
        v->general.push_back("the emission textures' reads at light samples");
      }
      if (const LightBvh* bvh = lights.bvh(); bvh && !bvh->empty()) {
        // The light BVH as core walks it (core/simd/light_bvh-inl.h), in lanes.
        for (std::uint32_t l = 0; l < bvh->trails().size(); ++l)
          v->bvh_entry.push_back(static_cast<std::int32_t>(lights.bvh_entry(l)));
        for (std::size_t e = 0; e < n_lights; ++e) v->bvh_light.push_back(static_cast<std::int32_t>(lights.bvh_light(e)));
        sc.lights.bvh_nodes = bvh->node_table().data();
        sc.lights.bvh_trail = bvh->trails().data();
        sc.lights.bvh_entry = v->bvh_entry.data();
        sc.lights.bvh_light = v->bvh_light.data();
        sc.lights.bvh_grid = lights.bvh_grid();
      }
    }
    // Per shape: its material's parameters and its geometry.
    // Gathers index these tables with 32-bit float indices: kShapeFields per shape, 12 per triangle (9 of vertex
    // normals), 16 per light.
    if (compiled.triangles().size() >= (std::size_t{1} << 27)) return no("more than 2^27 triangles");
    if (scene.shapes.size() >= (std::size_t{1} << 24)) return no("more than 2^24 shapes");
    // The light pick's indices are floats (pick_cdf, core/simd/lights-inl.h).
    if (sc.lights.count > kMaxExactFloatIndex || sc.deltas.count > kMaxExactFloatIndex) return no("more than 2^24 lights");
    std::vector<std::int32_t> energy_at;  // per material: its tables' offset in v->energy, -1 if not there yet
    std::vector<std::string> textured_names;  // materials the lanes shade whose hits core resolves (textures)
    std::vector<std::string> texel_names;     // materials whose texels alone core reads at hits
    for (std::uint32_t i = 0; i < scene.shapes.size(); ++i) {
      const Shape& sh = scene.shapes[i];
      const Material& m = scene.materials[sh.material];
      float f[vs::kShapeFields] = {};
      for (int c = 0; c < 3; ++c) {
        f[vs::kAlbedo + c] = m.albedo[c];
        f[vs::kEmission + c] = m.emission[c];
        f[vs::kCenter + c] = sh.center[c];
      }
      f[vs::kTwoSided] = m.two_sided_emission ? 1.0f : 0.0f;
      f[vs::kEmits] = m.emits() ? 1.0f : 0.0f;
      f[vs::kScatters] = m.scatters() ? 1.0f : 0.0f;
      f[vs::kFirstLight] = std::bit_cast<float>(static_cast<std::int32_t>(lights.first_entry(i)));
      f[vs::kFirstTriangle] = std::bit_cast<float>(static_cast<std::int32_t>(compiled.first_triangle(i)));
      f[vs::kIsSphere] = sh.kind == Shape::Kind::Sphere ? 1.0f : 0.0f;
      f[vs::kRadius] = sh.radius;
      f[vs::kFlipped] = sh.flip_normals ? 1.0f : 0.0f;
      f[vs::kOneSided] = m.one_sided ? 1.0f : 0.0f;
      sc.one_sided = sc.one_sided || m.one_sided;
      // A mesh with vertex normals or tangents has a shading frame of its own, which the lanes make (kNormalsAt,
      // kTangentsAt) and shade in (with Surfel's rules under a shading normal); so has a shape whose material
      // reads textures (kTexturedHits), whose frame a normal map may tilt. Not under the cosine strategy, whose
      // scatter is core's everywhere.
      const bool reads_textures = m.reads_textures_at_hits();
      const bool shaded_in_lanes = m.scatters() && in_lanes(m);
      // An emitter that scatters nothing but whose emission is a texture: the lanes resolve its hits too (in a
      // frame no lane shades in), for the texel core reads for the emission there.
      const bool emission_texels = !m.scatters() && m.emission_textured;
      const bool framed = (shaded_in_lanes && !cosine && (shading_frame(sh) || reads_textures)) || emission_texels;
      // A textured mesh or sphere: the lanes resolve its hits, frame, normal map's tilt and footprint included,
      // and core reads only the texels.
      const bool textured_hits = framed && reads_textures;
      // The frame the lanes make: of vertex normals, of tangents (about those normals, or the geometric one);
      // an emitter that scatters nothing shades in no frame, so it gets Frame(n) and no tables.
      const bool normals_in_lanes = framed && !emission_texels && sh.mesh.has_normals();
      const bool tangents_in_lanes = framed && !emission_texels && !sh.mesh.tangents.empty();
      if (textured_hits) {
        add_name(texel_names, "'" + m.name + "'");
      } else if (shaded_in_lanes && reads_textures) {
        add_name(textured_names, "'" + m.name + "'");
      } else if (shaded_in_lanes && shading_frame(sh) && !framed) {
        v->general.push_back("the shading frame of " + sh.description);
      }
      // Each triangle's three vertices' attribute (n floats each) appended to `table`, the shape's `field`
      // holding its triangle 0's index there (-1 without); false beyond the gathers' 2^27 triangles.
      const auto per_triangle = [&](std::vector<float>& table, const auto& attribute, int n, vs::ShapeField field) {
        const std::size_t stride = 3 * static_cast<std::size_t>(n);
        if (table.size() / stride + sh.mesh.triangles.size() >= (std::size_t{1} << 27)) return false;
        f[field] = std::bit_cast<float>(static_cast<std::int32_t>(table.size() / stride));
        const std::size_t at = table.size();
        table.resize(at + stride * sh.mesh.triangles.size());
        float* out = table.data() + at;
        parallel_for(0, sh.mesh.triangles.size(), 4096, [&](std::size_t b, std::size_t e) {
          for (std::size_t t = b; t < e; ++t)
            for (int k = 0; k < 3; ++k)
              for (int c = 0; c < n; ++c) out[stride * t + n * k + c] = attribute[sh.mesh.triangles[t][k]][c];
        });
        return true;
      };
      for (vs::ShapeField field : {vs::kNormalsAt, vs::kTangentsAt, vs::kUvsAt})
        f[field] = std::bit_cast<float>(std::int32_t{-1});
      if (normals_in_lanes && !per_triangle(v->vertex_normals, sh.mesh.normals, 3, vs::kNormalsAt))
        return no("more than 2^27 triangles with vertex normals");
      if (tangents_in_lanes && !per_triangle(v->vertex_tangents, sh.mesh.tangents, 4, vs::kTangentsAt))
        return no("more than 2^27 triangles with tangents");
      if (textured_hits && sh.mesh.has_uvs() && !per_triangle(v->triangle_uvs, sh.mesh.uvs, 2, vs::kUvsAt))
        return no("more than 2^27 textured triangles");
      const bool general = m.scatters() && (cosine || !in_lanes(m) || (shading_frame(sh) && !framed));
      // Every hit on a textured emitter is resolved, its texel read into the slot's SurfaceParams, whose emission
      // add_emission() takes: in the lanes (kTexturedHits) or by core (kResolveByCore).
      if (m.emission_textured && !textured_hits && !general)
        throw std::logic_error("wavefront: the emission texture of '" + m.name + "' would not be read at hits");
      f[vs::kGeneral] = general ? 1.0f : 0.0f;
      f[vs::kFramed] = framed ? 1.0f : 0.0f;
      sc.framed = sc.framed || framed;
      f[vs::kTexturedHits] = textured_hits ? 1.0f : 0.0f;
      f[vs::kNormalMapped] = textured_hits && m.normal_map ? 1.0f : 0.0f;
      f[vs::kTexturedParams] = textured_hits && m.is_textured() ? 1.0f : 0.0f;
      f[vs::kNormalMapScale] = m.normal_map ? m.normal_map->scale : 0.0f;
      sc.textured_hits = sc.textured_hits || textured_hits;
      f[vs::kTexturedEmission] = m.emission_textured ? 1.0f : 0.0f;
      f[vs::kResolveByCore] = general && (shading_frame(sh) || m.reads_textures_at_hits()) ? 1.0f : 0.0f;
      f[vs::kLaneMaterial] = m.type == MaterialType::Mirror       ? static_cast<float>(vs::kLaneMirror)
                             : m.type == MaterialType::Dielectric ? static_cast<float>(vs::kLaneDielectric)
                             : m.type == MaterialType::Disney     ? static_cast<float>(vs::kLaneDisney)
                                                                  : static_cast<float>(vs::kLaneLambert);
      f[vs::kIor] = m.glass.ior;
      for (int c = 0; c < 3; ++c) {
        f[vs::kReflectance + c] = m.glass.reflectance[c];
        f[vs::kTransmittance + c] = m.glass.transmittance[c];
      }
      const disney::Closure& c = m.closure;
      vs::for_each_closure_field(c, [&f](const auto& value, vs::ShapeField field, vs::FloatArray) {
        if constexpr (std::is_same_v<std::decay_t<decltype(value)>, float>)
          f[field] = value;
        else
          for (int k = 0; k < 3; ++k) f[field + k] = value[k];
      });
      f[vs::kEnergy] = std::bit_cast<float>(std::int32_t{-1});
      // (A textured material's Surfel reads the closure core evaluated per hit, which has no tables.)
      if (m.type == MaterialType::Disney && c.energy.on && !general && !m.is_textured()) {
        // Its energy tables, once per material.
        const std::size_t mi = static_cast<std::size_t>(&m - scene.materials.data());
        if (energy_at.size() <= mi) energy_at.resize(scene.materials.size(), -1);
        if (energy_at[mi] < 0) {
          energy_at[mi] = static_cast<std::int32_t>(v->energy.size());
          for (const Spectrum& e : c.energy.specular) v->energy.insert(v->energy.end(), {e.x, e.y, e.z});
          v->energy.insert(v->energy.end(), c.energy.coat.begin(), c.energy.coat.end());
          const Spectrum& k = c.energy.diffuse_scale;
          v->energy.insert(v->energy.end(), {k.x, k.y, k.z});
        }
        f[vs::kEnergy] = std::bit_cast<float>(energy_at[mi]);
      }
      sc.general = sc.general || general;
      sc.impulses = sc.impulses || (m.scatters() && !general && m.is_pure_impulse());
      v->shape.insert(v->shape.end(), std::begin(f), std::end(f));
    }
    if (!textured_names.empty())
      v->general.push_back("the texture reads (and shading frames) at hits on " + list_names(textured_names));
    if (!texel_names.empty())
      v->general.push_back("the texels at hits on " + list_names(texel_names) + " (OpenImageIO's lookups)");
    static_assert(vs::kEnergyCoat == 3 * disney::kEnergyTableSize &&
                  vs::kEnergyDiffuseScale == vs::kEnergyCoat + disney::kEnergyTableSize &&
                  vs::kEnergyFloats == vs::kEnergyDiffuseScale + 3);
    sc.energy = v->energy.empty() ? nullptr : v->energy.data();
    sc.shape = v->shape.data();
    sc.compiled = &compiled;
    sc.shape_count = scene.shapes.size();
    sc.zsobol = settings.sampler == SamplerKind::ZSobol;
    sc.zsobol_bits = sampler.zsobol_bits();
    if (scene.shapes.size() <= 16) {
      v->shape_columns.assign(16 * vs::kShapeFields, 0.0f);
      for (std::size_t i = 0; i < scene.shapes.size(); ++i)
        for (int f = 0; f < vs::kShapeFields; ++f) v->shape_columns[16 * f + i] = v->shape[vs::kShapeFields * i + f];
      sc.shape_columns = v->shape_columns.data();
    }
    static_assert(sizeof(Triangle) == 12 * sizeof(float));
    sc.triangles = compiled.triangles().empty() ? nullptr : &compiled.triangles().data()->p0.x;
    sc.vertex_normals = v->vertex_normals.empty() ? nullptr : v->vertex_normals.data();
    sc.triangle_uvs = v->triangle_uvs.empty() ? nullptr : v->triangle_uvs.data();
    sc.vertex_tangents = v->vertex_tangents.empty() ? nullptr : v->vertex_tangents.data();
    sc.prefetch = sizeof(float) * (12 * compiled.triangles().size() + v->vertex_normals.size() +
                                   v->triangle_uvs.size() + v->vertex_tangents.size()) >
                  vs::Scene::kPrefetchBytes;
    // The camera.
    const Camera& camera = compiled.camera();
    const Camera::Plane p = camera.plane();
    const CameraDesc& d = camera.desc();
    v->camera = vs::Camera{{d.position.x, d.position.y, d.position.z},
                           {p.forward.x, p.forward.y, p.forward.z},
                           {p.right.x, p.right.y, p.right.z},
                           {p.up.x, p.up.y, p.up.z},
                           p.tan_half_fov, p.aspect, p.inv_width, p.inv_height, d.aperture_radius, d.focus_distance};
    return v;
  }

  // Whether the lanes shade m: Lambert, by lambert.h (every shading path but
  // General, which shades it through the Disney closure; core/surfel.cpp),
  // Disney (either sampling of its glossy lobes), a mirror (mirror.h) or a
  // dielectric (dielectric.h), textured or not (the lanes resolve a textured
  // hit's parameters and frame; core reads only its texels).
  static bool in_lanes(const Material& m) {
    if (m.is_pure_impulse()) return true;
    const bool lambert = m.type == MaterialType::Diffuse && m.shading.path != ShadingPath::General;
    return lambert || disney_features(m) != 0;
  }
  // The lobes the lanes shade a Disney material with (Scene::disney): those
  // of the scene's shading path, under either sampling of the glossy lobes;
  // 0 if not in lanes.
  static unsigned disney_features(const Material& m) {
    if (m.type != MaterialType::Disney) return 0;
    switch (m.shading.path) {
      case ShadingPath::Disney: return disney::kDisneyLobes;
      case ShadingPath::DisneyClearcoat: return disney::kDisneyLobes | disney::kClearcoat;
      case ShadingPath::LambertOnly:
      case ShadingPath::General: break;
    }
    return 0;
  }
  // Whether a shape shades in a frame of its own (not the geometric normal's).
  static bool shading_frame(const Shape& shape) { return shape.mesh.has_normals() || !shape.mesh.tangents.empty(); }
};

// vector_stages::compact() writes finished paths as FilmSamples, byte for byte.
static_assert(std::is_trivially_copyable_v<FilmSample> && sizeof(FilmSample) == sizeof(vector_stages::Sample));
static_assert(offsetof(FilmSample, film) == offsetof(vector_stages::Sample, film_x) &&
              offsetof(FilmSample, L) == offsetof(vector_stages::Sample, L) &&
              offsetof(FilmSample, rays) == offsetof(vector_stages::Sample, rays) &&
              offsetof(FilmSample, hits) == offsetof(vector_stages::Sample, hits));
static_assert(sizeof(vec2) == 2 * sizeof(float) && sizeof(Spectrum) == 3 * sizeof(float));

// A wave's paths for the vectorised stages: one array per scalar
// (vector_stages::Wave names them).
struct WavefrontTracer::Lanes {
  std::vector<float> f[vector_stages::kFloatArrays];
  std::vector<std::uint32_t> u[vector_stages::kUintArrays];
  std::vector<std::uint8_t> b[vector_stages::kByteArrays];
  std::vector<std::uint64_t> rng, zindex, zkey;
  std::vector<SurfaceParams> params;  // a textured scene's only (textured())
  // The wave's finished samples, in its own order: compact() writes them
  // here (a region the caches hold) and the wave copies them out at its end
  // in one sequential pass, instead of scattering them over the render's
  // sample buffer.
  std::vector<FilmSample> samples;
  vector_stages::Wave view;  // pointers into the arrays; view.n live paths

  void resize(std::size_t size) {
    // A block of lanes is loaded whole, past the last path (vector_stages.h).
    const std::size_t padded = size + vector_stages::kPadding;
    // The shadow rays' arrays hold up to two a path (a delta light's and an area light's).
    const std::size_t queries = 2 * size + vector_stages::kPadding;
    namespace vs = vector_stages;
    for (int a = 0; a < vs::kFloatArrays; ++a) f[a].resize(a >= vs::kQOx && a <= vs::kQUnB ? queries : padded);
    for (int a = 0; a < vs::kUintArrays; ++a) u[a].resize(a == vs::kQPath || a == vs::kQAlphaKey ? queries : padded);
    for (int a = 0; a < vs::kByteArrays; ++a) b[a].resize(a == vs::kQOccluded ? queries : padded);
    rng.resize(padded);
    zindex.resize(padded);
    zkey.resize(padded);
    samples.resize(size);
    for (int a = 0; a < vector_stages::kFloatArrays; ++a) view.f[a] = f[a].data();
    for (int a = 0; a < vector_stages::kUintArrays; ++a) view.u[a] = u[a].data();
    for (int a = 0; a < vector_stages::kByteArrays; ++a) view.b[a] = b[a].data();
    view.rng = rng.data();
    view.zindex = zindex.data();
    view.zkey = zkey.data();
  }
  std::size_t capacity() const { return samples.size(); }
  // Room for every slot's hit parameters (Wave::params).
  void textured() {
    if (params.size() < rng.size()) params.resize(rng.size());
    view.params = params.data();
  }
  static constexpr std::size_t bytes_per_path() {
    namespace vs = vector_stages;
    constexpr std::size_t query_floats = vs::kQUnB - vs::kQOx + 1;  // twice over, with kQPath and kQOccluded
    return (vs::kFloatArrays + query_floats) * sizeof(float) + (vs::kUintArrays + 2) * sizeof(std::uint32_t) +
           vs::kByteArrays + 1 + 3 * sizeof(std::uint64_t) + sizeof(FilmSample);
  }
};

WavefrontTracer::WavefrontTracer(const CompiledScene& scene, const RenderSettings& settings, std::size_t wave_size,
                                 RayModes modes, WavefrontStages stages)
    : Tracer(scene, settings),
      wave_size_(std::max<std::size_t>(wave_size, 1)),
      modes_(modes),
      vector_(stages == WavefrontStages::Auto ? VectorStages::make(scene, settings, sampler(), &scalar_reason_) : nullptr) {
  if (stages == WavefrontStages::Scalar) scalar_reason_ = "asked for";
}

WavefrontTracer::~WavefrontTracer() = default;

bool WavefrontTracer::vectorised() const { return vector_ != nullptr; }

std::string WavefrontTracer::stages_description() const {
  if (!vector_) return "scalar stages (" + scalar_reason_ + ")";
  std::string d = std::string("every stage vectorised (") + simd_target_name(active_simd_target()) + ", " +
                  std::to_string(vector_stages::lanes()) + " paths at a time, paths as structure of arrays)";
  std::vector<std::string> general = vector_->general;
  if (!vector_->general_materials.empty())
    general.insert(general.begin(), std::string(vector_->general_materials.size() > 1 ? "materials " : "material ") +
                                        list_names(vector_->general_materials));
  for (std::size_t i = 0; i < general.size(); ++i) d += (i == 0 ? "; by core, one path at a time: " : "; ") + general[i];
  return d;
}

std::size_t WavefrontTracer::bytes_per_path() const {
  if (vector_) return Lanes::bytes_per_path() + (vector_->scene.textured ? sizeof(SurfaceParams) : 0);
  // A textured scene's paths also carry their cone and their hit's parameters.
  return scalar_bytes_per_path() + (scene_.has_textures() ? sizeof(RayCone) + sizeof(SurfaceParams) : 0);
}

// Stage: the first surface along each live path's ray. The rays go to
// Embree straight from the path state, as one batch (camera rays as coherent
// ones); the hits' triangles are prefetched before any is resolved into a
// Surfel, so their cache misses overlap instead of queueing one behind the
// other.
void WavefrontTracer::intersect(Wave& w) const {
  const std::size_t n = w.n;
  if (n == 0) return;
  const bool camera_rays = w.vertex[0] == 1;
  const std::span<const Ray> rays(w.ray.data(), n);
  const std::span<RayHit> hits(w.hit.data(), n);
  const std::span<std::uint8_t> found(w.found.data(), n);
  const std::uint64_t t0 = clock_ns();
  scene_.intersect_batch(rays, hits, found, camera_rays ? modes_.camera : modes_.bounce, camera_rays);
  w.clock.batch(camera_rays ? kCameraQueries : kBounceQueries, t0, n);
  std::uint64_t t_resolve = clock_ns();
  for (std::size_t i = 0; i < n; ++i)
    if (found[i]) scene_.prefetch(hits[i]);
  const bool textured = scene_.has_textures();  // then w.cone and w.params are sized
  for (std::size_t i = 0; i < n; ++i) {
    ++w.rays[i];
    if (found[i])
      scene_.resolve(rays[i], hits[i], &w.surfel[i], textured ? w.cone[i] : RayCone{}, textured ? &w.params[i] : nullptr);
  }
  w.clock.stage(WavefrontStage::Resolve, &t_resolve);
}

// Stage: the emission found at each hit (as the strategy weighs it), and
// the end of paths that escape, pass the depth cap or reach a surface that
// does not scatter.
void WavefrontTracer::add_emission(Wave& w, PathObserver* obs) const {
  const int cap = max_vertex(settings_);
  const Strategy strategy = settings_.strategy;
  for (std::size_t i = 0; i < w.n; ++i) {
    const Surfel& s = w.surfel[i];
    if (!w.found[i]) {
      if (!embree_accepts(w.ray[i])) {  // refused by the accel: a bad sample, as in the reference tracer
        w.L[i] = Spectrum(std::numeric_limits<float>::quiet_NaN());
        w.alive[i] = 0;
        continue;
      }
      const LightSampler::Sky sky = scene_.lights().sky(w.ray[i].dir);
      const Spectrum Le = sky.Le;
      const float we = is_black(Le) ? 0.0f : emission_weight(strategy, w.prev[i], sky.pdf);
      w.L[i] += w.beta[i] * (we * Le);
      if (obs) {
        obs->on_escape({w.vertex[i], Le, we, w.beta[i] * we * Le});
        obs->on_end({w.vertex[i], PathEnd::Escaped});
      }
      w.alive[i] = 0;
      continue;
    }
    const vec3 wo = -w.ray[i].dir;
    const Spectrum Le = s.emitted(wo);
    float we = is_black(Le) ? 0.0f : emission_weight(strategy, w.prev[i], scene_.lights().pdf(w.prev[i].ref, s));
    if (PATHLAB_FAULT(WavefrontMisWeightLostAtDepth2) && w.vertex[i] == 3 && we > 0.0f) we = 1.0f;
    const Spectrum added = w.beta[i] * (we * Le);
    w.L[i] += added;
    if (obs)
      obs->on_hit({w.vertex[i], s.p, s.n, glm::dot(s.n, wo) > 0.0f,
                   static_cast<std::uint32_t>(s.material - scene_.scene().materials.data()), s.shape, s.prim, s.instance,
                   Le, we,
                   added, w.beta[i]});
    if (w.vertex[i] > cap || !s.material->scatters()) {
      if (obs) obs->on_end({w.vertex[i], w.vertex[i] > cap ? PathEnd::MaxDepth : PathEnd::Absorbed});
      w.alive[i] = 0;
    }
  }
}

namespace {
// shadow_state of a light sample rejected before its shadow ray.
constexpr std::uint8_t kRejected = 4;
std::uint8_t rejected_state(LightRejection r) { return static_cast<std::uint8_t>(kRejected + static_cast<int>(r)); }
}  // namespace

// Stage: next-event estimation, up to two light samples per path (a point
// light in every strategy; an area light as the strategy says), each with
// the contribution it brings if nothing blocks its shadow ray.
void WavefrontTracer::sample_lights(Wave& w, PathObserver* obs) const {
  const LightSampler& lights = scene_.lights();
  const Strategy strategy = settings_.strategy;
  const bool keep = obs != nullptr || w.record != nullptr;  // someone reads the light samples back
  for (std::size_t i = 0; i < w.n; ++i) {
    w.shadow_state[2 * i] = w.shadow_state[2 * i + 1] = 0;
    if (!w.alive[i]) continue;
    const Surfel& s = w.surfel[i];
    const vec3 wo = -w.ray[i].dir;
    if (lights.has_delta_lights()) {
      const auto ls = lights.sample_delta(s.p, w.u(i, Dim::DeltaLightChoice));
      if (obs && !ls) w.shadow_state[2 * i] = rejected_state(LightRejection::NoSample);
      if (ls) {
        const Spectrum f = s.eval(ls->wi, wo);
        if (obs && is_black(f)) {
          w.light[2 * i] = *ls;
          w.shadow_state[2 * i] = rejected_state(black_light_sample_reason(s.n, ls->wi, wo));
        }
        if (!is_black(f)) {
          if (keep) w.light[2 * i] = *ls;  // only the observer and the stage records read it back
          w.unoccluded[2 * i] = delta_light_contribution(f, ls->Le, ls->pdf);
          w.light_weight[2 * i] = 1.0f;
          w.shadow[2 * i] = shadow_ray(s, *ls);
          w.shadow[2 * i].alpha_key = scene_.alpha_key(w.rng[i], w.vertex[i]);
          w.shadow_state[2 * i] = 1;
        }
      }
    }
    if (samples_area_lights(strategy, [&] { return w.u(i, Dim::Technique); })) {
      const auto ls = lights.sample(light_query(s, wo), w.u(i, Dim::LightChoice), w.u2(i, Dim::LightX));
      if (!ls) {
        if (obs && lights.has_area_lights()) w.shadow_state[2 * i + 1] = rejected_state(LightRejection::NoSample);
        continue;
      }
      const Spectrum f = s.eval(ls->wi, wo);
      if (is_black(f)) {
        if (obs) {
          w.light[2 * i + 1] = *ls;
          w.shadow_state[2 * i + 1] = rejected_state(black_light_sample_reason(s.n, ls->wi, wo));
        }
        continue;
      }
      const float lw = light_sample_weight(strategy, ls->pdf, s.pdf(ls->wi, wo));
      if (keep) w.light[2 * i + 1] = *ls;
      w.unoccluded[2 * i + 1] = light_contribution(f, ls->Le, lw, ls->pdf);
      w.light_weight[2 * i + 1] = lw;
      w.shadow[2 * i + 1] = shadow_ray(s, *ls);
      w.shadow[2 * i + 1].alpha_key = scene_.alpha_key(w.rng[i], w.vertex[i]);
      w.shadow_state[2 * i + 1] = 1;
    }
  }
}

// Stage: occlusion queries for every pending shadow ray, as one batch.
void WavefrontTracer::trace_shadow_rays(Wave& w) const {
  std::size_t n = 0;
  for (std::size_t i = 0; i < w.n; ++i)
    for (std::size_t s = 2 * i; s < 2 * i + 2; ++s)
      if (w.shadow_state[s] == 1) {
        w.query[n] = w.shadow[s];
        w.query_slot[n++] = static_cast<std::uint32_t>(s);
        ++w.rays[i];
      }
  if (n == 0) return;
  const std::span<std::uint8_t> occluded(w.query_result.data(), n);
  const std::uint64_t t0 = clock_ns();
  scene_.occluded_batch(std::span<const Ray>(w.query.data(), n), occluded, modes_.shadow);
  w.clock.batch(kShadowQueries, t0, n);
  for (std::size_t r = 0; r < n; ++r) w.shadow_state[w.query_slot[r]] = occluded[r] ? 3 : 2;
}

// Stage: the light of visible samples, point light first (the reference's order).
void WavefrontTracer::add_light(Wave& w, PathObserver* obs) const {
  for (std::size_t i = 0; i < w.n; ++i) {
    for (std::size_t k = 2 * i; k < 2 * i + 2; ++k) {
      if (w.shadow_state[k] == 0) continue;
      if (w.shadow_state[k] >= kRejected) {  // set only with an observer
        const auto reason = static_cast<LightRejection>(w.shadow_state[k] - kRejected);
        if (obs)
          obs->on_light(rejected_light_event(w.vertex[i], k == 2 * i,
                                           reason == LightRejection::NoSample ? nullptr : &w.light[k], reason));
        continue;
      }
      const bool visible = w.shadow_state[k] == 2;
      const Spectrum added = visible ? w.beta[i] * w.unoccluded[k] : Spectrum(0.0f);
      w.L[i] += added;
      if (obs) {
        const LightSample& ls = w.light[k];
        obs->on_light({w.vertex[i], k == 2 * i, ls.infinite, ls.light, ls.p, ls.wi, ls.dist, ls.pdf, ls.Le, visible,
                       w.light_weight[k], added, w.shadow[k]});
      }
    }
  }
}

// Stage: sample the continuation, apply Russian roulette, spawn the next ray.
void WavefrontTracer::scatter(Wave& w, PathObserver* obs) const {
  const Strategy strategy = settings_.strategy;
  const bool textured = scene_.has_textures();
  for (std::size_t i = 0; i < w.n; ++i) {
    if (!w.alive[i]) continue;
    const Surfel& s = w.surfel[i];
    const vec3 wo = -w.ray[i].dir;
    const int v = w.vertex[i];
    const vec2 u_dir = w.u2(i, Dim::DirectionX);
    bool cosine = false;
    const std::optional<BsdfSample> bs = scatter_for(strategy, s, wo, w.u(i, Dim::LobeChoice), u_dir, &cosine);
    if (!bs || is_black(bs->weight)) {
      if (obs) obs->on_end({v, bs ? PathEnd::NoSample : PathEnd::Absorbed});
      w.alive[i] = 0;
      continue;
    }
    Spectrum weight = bs->weight;
    float survival = 1.0f;
    if (v > settings_.rr_depth) {
      if (!survives_roulette(w.beta[i], w.u(i, Dim::Roulette), &weight, &survival)) {
        if (obs) {
          obs->on_scatter({v, bs->lobe, bs->impulse, cosine, bs->wi, bs->pdf, weight, survival, Spectrum(0.0f)});
          obs->on_end({v, PathEnd::Roulette});
        }
        w.alive[i] = 0;
        continue;
      }
    }
    w.beta[i] *= weight;
    Ray next = s.spawn(bs->wi);
    next.alpha_key = scene_.alpha_key(w.rng[i], v);
    if (obs) obs->on_scatter({v, bs->lobe, bs->impulse, cosine, bs->wi, bs->pdf, weight, survival, w.beta[i], next});
    w.prev[i] = previous_vertex(strategy, s, wo, *bs, [&] { return w.u(i, Dim::Technique); });
    if (textured)
      w.cone[i] = scattered_cone(w.cone[i], glm::length(s.p - w.ray[i].origin), bs->impulse, bs->pdf,
                                 settings_.texture_filter);
    w.ray[i] = next;
    w.vertex[i] = v + 1;
  }
}

// Stage: write out the paths that ended and move the survivors down to the
// front, keeping their order (a stable compaction: the work order - and
// nothing else - changes from bounce to bounce). A slot is only ever
// overwritten by a later one, after its own path has been written or moved.
void WavefrontTracer::compact(Wave& w, std::span<FilmSample> out) {
  std::size_t m = 0;
  for (std::size_t i = 0; i < w.n; ++i) {
    if (!w.alive[i]) {
      out[w.out_index[i]] = w.result(i);
      continue;
    }
    if (m != i) {
      w.move(i, m);
      w.alive[m] = 1;
    }
    ++m;
  }
  w.n = m;
}

// Stage: one camera ray per path.
void WavefrontTracer::generate_camera_rays(Wave& w, PathObserver* obs) const {
  const Camera& camera = scene_.camera();
  if (scene_.has_textures()) {
    w.textured(w.capacity());
    std::fill_n(w.cone.begin(), w.n, scene_.camera_cone(settings_.texture_filter));
  }
  for (std::size_t i = 0; i < w.n; ++i) {
    w.vertex[i] = 0;  // the camera's random numbers are those of vertex 0
    w.film[i] = vec2(static_cast<float>(w.x[i]), static_cast<float>(w.y[i])) + w.u2(i, Dim::FilmX);
    w.ray[i] = camera.generate_ray(w.film[i], [&] { return w.u2(i, Dim::LensX); });
    w.ray[i].alpha_key = scene_.alpha_key(w.rng[i], 0);
    w.beta[i] = Spectrum(1.0f);
    w.L[i] = Spectrum(0.0f);
    w.prev[i] = PreviousVertex{};
    w.rays[i] = 0;
    w.alive[i] = 1;
    w.vertex[i] = 1;
    if (obs) obs->on_camera({w.x[i], w.y[i], w.sample[i], w.film[i], w.ray[i].origin, w.ray[i].dir});
  }
}

void WavefrontTracer::run_wave(Wave& w, std::span<FilmSample> out, PathObserver* obs) const {
  w.clock = Clock{};
  const std::uint64_t t0 = clock_ns();
  std::uint64_t t_stage = t0;  // the running stage's start (Clock::stage)
  generate_camera_rays(w, obs);
  w.clock.stage(WavefrontStage::Camera, &t_stage);
  for (int vertex = 1; w.n > 0; ++vertex) {
    intersect(w);  // clocks its Embree batch and its resolve itself
    t_stage = clock_ns();
    add_emission(w, obs);
    w.clock.stage(WavefrontStage::Emission, &t_stage);
    // The light samples, and packing their shadow rays (Embree's batch apart).
    const std::uint64_t shadow_ns = w.clock.nanoseconds[kShadowQueries];
    sample_lights(w, obs);
    trace_shadow_rays(w);
    w.clock.stage(WavefrontStage::Lights, &t_stage);
    w.clock.nanoseconds[kFirstStage + static_cast<int>(WavefrontStage::Lights)] -=
        w.clock.nanoseconds[kShadowQueries] - shadow_ns;
    add_light(w, obs);
    w.clock.stage(WavefrontStage::AddLight, &t_stage);
    const bool recorded = w.record != nullptr && vertex == w.record_vertex;
    if (recorded) record_stage(w);
    scatter(w, obs);
    if (recorded) record_survival(w);
    w.clock.stage(WavefrontStage::Scatter, &t_stage);
    compact(w, out);
    w.clock.stage(WavefrontStage::Compact, &t_stage);
  }
  w.clock.nanoseconds[kWave] = clock_ns() - t0;
  publish(w.clock);
}

void WavefrontTracer::record_stage(Wave& w) {
  for (std::size_t i = 0; i < w.n; ++i) {
    StageRecord& r = w.record[w.out_index[i]];
    r.reached = true;
    r.throughput = w.beta[i];
    r.dir = w.ray[i].dir;
    r.distance = w.found[i] ? w.hit[i].t : std::numeric_limits<float>::infinity();
    r.light_sampled = w.shadow_state[2 * i + 1] != 0;
    r.light_pdf = r.light_sampled ? w.light[2 * i + 1].pdf : 0.0f;
  }
}

void WavefrontTracer::record_survival(Wave& w) {
  for (std::size_t i = 0; i < w.n; ++i) w.record[w.out_index[i]].survived = w.alive[i] != 0;
}

// The vectorised twin of run_wave: the same stages and the same Embree
// batches, over Lanes.
void WavefrontTracer::run_wave_vector(Lanes& lanes, std::span<FilmSample> out, std::uint32_t first_slot) const {
  namespace vs = vector_stages;
  const vs::Scene& sc = vector_->scene;
  const vs::Wave& w = lanes.view;
  Clock clock;
  const std::uint64_t t0 = clock_ns();
  const std::size_t paths = w.n;
  std::uint64_t t_stage = t0;  // the running stage's start (Clock::stage)
  vs::generate_camera_rays(sc, vector_->camera, w);
  clock.stage(WavefrontStage::Camera, &t_stage);
  for (bool camera_rays = true; lanes.view.n > 0; camera_rays = false) {
    const std::size_t n = w.n;
    const RayArrays rays{w.f[vs::kOx], w.f[vs::kOy], w.f[vs::kOz], w.f[vs::kDx], w.f[vs::kDy], w.f[vs::kDz], w.f[vs::kTmax],
                         sc.alpha ? w.u[vs::kAlphaKey] : nullptr};
    const HitArrays hits{w.f[vs::kHitT], w.f[vs::kHitU], w.f[vs::kHitV], w.u[vs::kShape], w.u[vs::kPrim], w.b[vs::kFound],
                         sc.instanced ? w.u[vs::kInstance] : nullptr};
    const std::uint64_t t = clock_ns();
    scene_.intersect_arrays(rays, n, hits, camera_rays ? modes_.camera : modes_.bounce, camera_rays);
    clock.batch(camera_rays ? kCameraQueries : kBounceQueries, t, n);
    t_stage = clock_ns();
    if (sc.prefetch) vs::prefetch_hits(sc, w);  // overlap the hits' cache misses (as intersect() does)
    vs::resolve(sc, w);
    clock.stage(WavefrontStage::Resolve, &t_stage);
    vs::add_emission(sc, w);
    clock.stage(WavefrontStage::Emission, &t_stage);
    const std::size_t q = vs::sample_lights(sc, w);
    clock.stage(WavefrontStage::Lights, &t_stage);
    if (q > 0) {
      const RayArrays shadow{w.f[vs::kQOx], w.f[vs::kQOy], w.f[vs::kQOz], w.f[vs::kQDx],
                             w.f[vs::kQDy], w.f[vs::kQDz], w.f[vs::kQTmax], sc.alpha ? w.u[vs::kQAlphaKey] : nullptr};
      const std::uint64_t ts = clock_ns();
      scene_.occluded_arrays(shadow, q, w.b[vs::kQOccluded], modes_.shadow);
      clock.batch(kShadowQueries, ts, q);
      t_stage = clock_ns();
      vs::add_light(w, q);
      clock.stage(WavefrontStage::AddLight, &t_stage);
    }
    vs::scatter(sc, w);
    clock.stage(WavefrontStage::Scatter, &t_stage);
    lanes.view.n = vs::compact(sc, w, lanes.samples.data(), first_slot);
    clock.stage(WavefrontStage::Compact, &t_stage);
  }
  std::copy_n(lanes.samples.begin(), paths, out.begin());
  clock.nanoseconds[kWave] = clock_ns() - t0;
  publish(clock);
}

WavefrontTimes WavefrontTracer::times() const {
  auto seconds = [&](int k) { return 1e-9 * static_cast<double>(nanoseconds_[k].load(std::memory_order_relaxed)); };
  auto queries = [&](int k) { return WavefrontTimes::Queries{rays_[k].load(std::memory_order_relaxed), seconds(k)}; };
  WavefrontTimes t{queries(kCameraQueries), queries(kBounceQueries), queries(kShadowQueries), seconds(kWave)};
  for (int k = 0; k < kWavefrontStages; ++k) t.stage_seconds[k] = seconds(kFirstStage + k);
  return t;
}

void WavefrontTracer::render_batch(std::uint32_t first, std::uint32_t count, std::span<FilmSample> out) const {
  render_waves(first, count, out, 0, {});
}

void WavefrontTracer::render_batch_recording(std::uint32_t first, std::uint32_t count, std::span<FilmSample> out,
                                             int vertex, std::span<StageRecord> records) const {
  if (records.size() != out.size()) throw std::invalid_argument("render_batch_recording: one record per sample");
  std::fill(records.begin(), records.end(), StageRecord{});
  render_waves(first, count, out, vertex, records);
}

void WavefrontTracer::render_waves(std::uint32_t first, std::uint32_t count, std::span<FilmSample> out,
                                   int record_vertex, std::span<StageRecord> records) const {
  const auto width = static_cast<std::uint32_t>(scene_.scene().film.width);
  // At least ~64 waves per batch so that small batches still keep every
  // thread busy, but never below 256 paths; the size depends only on the
  // batch, never on the thread count.
  const std::size_t wave_size =
      std::min(wave_size_, std::max<std::size_t>(256, ((out.size() + 63) / 64 + 15) / 16 * 16));
  const std::size_t waves = (out.size() + wave_size - 1) / wave_size;
  // Wave k always holds the same samples, whichever thread runs it, so the
  // batches Embree sees - and hence the image - do not depend on threads.
  // Path i of wave k: its output slot, pixel, sample and random stream.
  // Sample j of pixel p is entry p * count + j of the batch; step through
  // them without a division per path.
  auto fill = [&](std::size_t begin, std::size_t n, auto&& set) {
    auto pixel = static_cast<std::uint32_t>(begin / count);
    auto j = static_cast<std::uint32_t>(begin % count);
    std::uint32_t x = pixel % width, y = pixel / width;
    for (std::size_t i = 0; i < n; ++i) {
      set(i, static_cast<std::uint32_t>(begin + i), x, y, pixel, first + j);
      if (++j == count) {
        j = 0;
        ++pixel;
        if (++x == width) x = 0, ++y;
      }
    }
  };
  // Each thread keeps its wave's arrays from one batch to the next
  // (allocating and page-faulting them in per wave cost more than tracing).
  const std::size_t n_max = std::min(wave_size, out.size());
  if (vector_ && records.empty()) {  // the records are the scalar stages' arrays
    parallel_for(0, waves, 1, [&](std::size_t k0, std::size_t k1) {
      const bool zsobol = vector_->scene.zsobol;
      thread_local Lanes lanes;
      if (lanes.capacity() < n_max) lanes.resize(n_max);
      if (vector_->scene.textured) lanes.textured();
      namespace vs = vector_stages;
      for (std::size_t k = k0; k < k1; ++k) {
        const std::size_t begin = k * wave_size;
        lanes.view.n = std::min(wave_size, out.size() - begin);
        fill(begin, lanes.view.n,
             [&](std::size_t i, std::uint32_t slot, std::uint32_t x, std::uint32_t y, std::uint32_t pixel,
                 std::uint32_t sample) {
               lanes.u[vs::kOutIndex][i] = slot;
               lanes.u[vs::kPixelX][i] = x;
               lanes.u[vs::kPixelY][i] = y;
               lanes.rng[i] = SampleStream::pixel_sample(pixel, sample);  // hashed into the key below
               if (zsobol) {
                 lanes.zindex[i] = sampler().zsobol_index(x, y, sample);
                 lanes.zkey[i] = sampler().zsobol_key(sample);
               }
             });
        vs::hash_keys(lanes.rng.data(), lanes.view.n, SampleStream::seed_key(settings_.seed));
        run_wave_vector(lanes, out.subspan(begin, lanes.view.n), static_cast<std::uint32_t>(begin));
      }
    });
    return;
  }
  parallel_for(0, waves, 1, [&](std::size_t k0, std::size_t k1) {
    thread_local Wave w;
    if (w.capacity() < n_max) w.resize(n_max);
    w.record = records.empty() ? nullptr : records.data();
    w.record_vertex = record_vertex;
    for (std::size_t k = k0; k < k1; ++k) {
      const std::size_t begin = k * wave_size;
      w.n = std::min(wave_size, out.size() - begin);
      fill(begin, w.n,
           [&](std::size_t i, std::uint32_t slot, std::uint32_t x, std::uint32_t y, std::uint32_t /*pixel*/,
               std::uint32_t sample) {
             w.out_index[i] = slot;
             w.x[i] = x;
             w.y[i] = y;
             w.sample[i] = sample;
             w.rng[i] = stream(x, y, sample);
           });
      run_wave(w, out, nullptr);
    }
  });
}

FilmSample WavefrontTracer::trace_sample(std::uint32_t x, std::uint32_t y, std::uint32_t sample,
                                         PathObserver* observer) const {
  Wave w;
  w.resize(1);
  w.out_index[0] = 0;
  w.x[0] = x;
  w.y[0] = y;
  w.sample[0] = sample;
  w.rng[0] = stream(x, y, sample);
  w.n = 1;
  FilmSample result;
  run_wave(w, std::span<FilmSample>(&result, 1), observer);
  if (observer) observer->on_result(result.L);
  return result;
}

}  // namespace pathlab
