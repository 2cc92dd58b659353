// A scene as described by its file: camera, film, materials, shapes, lights
// and render defaults, all in world space. `CompiledScene` (compiled_scene.h)
// turns it into what tracers query. The file format is documented in
// docs/scene-format.md and parsed by scene_loader.h.
#pragma once

#include "core/camera.h"
#include "core/material.h"
#include "core/mesh.h"
#include "core/rng.h"

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace pathlab {

class EnvironmentMap;  // core/environment_map.h

// How a sample's radiance reaches the pixels (the reconstruction filter).
enum class FilterKind : std::uint8_t {
  Box,       // a sample counts for the pixel it lies in, with weight 1
  Bilinear,  // splatted to the 2x2 nearest pixel centres with tent weights
};

struct FilmDesc {
  int width = 256;
  int height = 256;
  FilterKind filter = FilterKind::Box;
};

enum class Strategy : std::uint8_t {
  Cosine,     // cosine-weighted directions, emission found by hitting it
  Bsdf,       // the material's own sampling, emission found by hitting it
  Light,      // next-event estimation; BSDF sampling continues the path
  LightBsdf,  // one-sample 50/50 choice of light or BSDF sampling (balance)
  Mis,        // next-event estimation and BSDF sampling, power heuristic
};
inline constexpr Strategy kAllStrategies[] = {Strategy::Cosine, Strategy::Bsdf, Strategy::Light, Strategy::LightBsdf,
                                              Strategy::Mis};
const char* strategy_name(Strategy s);
std::optional<Strategy> parse_strategy(std::string_view name);
// Every strategy's name, in the order of kAllStrategies.
std::vector<std::string_view> strategy_names();

// How an area light's point is sampled for next-event estimation
// (core/light_sampler.h; docs/scene-format.md, "Light sampling").
enum class LightSampling : std::uint8_t {
  Area,        // uniformly by area on the chosen triangle or sphere
  SolidAngle,  // uniformly in the solid angle the emitter subtends, where the rule allows
};
const char* light_sampling_name(LightSampling s);
std::optional<LightSampling> parse_light_sampling(std::string_view name);

// How next-event estimation picks the area light (core/light_sampler.h;
// docs/scene-format.md, "How a light is picked").
enum class LightSamplerKind : std::uint8_t {
  Power,  // in proportion to power, wherever the shading point is
  Bvh,    // down a light BVH, by importance for the shading point (core/light_bvh.h)
};
const char* light_sampler_name(LightSamplerKind k);
std::optional<LightSamplerKind> parse_light_sampler(std::string_view name);

// How Embree intersects triangles (RTC_SCENE_FLAG_ROBUST or not;
// docs/scene-format.md, render.intersection). A speed-for-accuracy trade
// with a measured bias: bench/bench_watertight.cpp, docs/performance.md.
enum class Intersection : std::uint8_t {
  Robust,  // watertight: no ray slips between two triangles sharing an edge
  Fast,    // Embree's fastest test; about 1e-7 to 1e-6 of rays slip through shared edges
};
const char* intersection_name(Intersection i);
std::optional<Intersection> parse_intersection(std::string_view name);

struct RenderSettings {
  int spp = 16;
  // Maximum number of scattering events on a path: 0 shows only emission
  // seen directly, 1 adds direct lighting, ... -1 means no cap (Russian
  // roulette ends paths, with a safety cap of kMaxVerticesUncapped).
  int max_depth = 8;
  // Russian roulette starts at the vertex after this many bounces.
  int rr_depth = 5;
  Strategy strategy = Strategy::Mis;
  // How next-event estimation samples a point on the chosen area light.
  LightSampling light_sampling = LightSampling::Area;
  // How next-event estimation picks the area light.
  LightSamplerKind light_sampler = LightSamplerKind::Power;
  std::uint64_t seed = 0;
  // Where the random numbers come from (core/rng.h; docs/scene-format.md,
  // Samplers). zsobol's numbers depend on spp too (rounded up to a power of
  // two).
  SamplerKind sampler = SamplerKind::Independent;
  // How glossy lobes are sampled (core/shading.h).
  BsdfSampling bsdf_sampling = BsdfSampling::Vndf;
  // Firefly controls, both biased and off (0) by default; never on in a test
  // of unbiasedness. `clamp`: a sample's radiance is scaled down so that its
  // largest component is at most this (core/render.cpp). `min_pdf`: BSDF
  // samples with a smaller density are discarded (Surfel::scatter).
  float clamp = 0.0f;
  float min_pdf = 0.0f;
  // Route every material through the general, Disney-capable shading code
  // instead of the code specialised to the scene's lobes (for benchmarks
  // and tests; the image is the same).
  bool force_general_shading = false;
  // Embree's BVH: false keeps vertices in its leaves (fastest), true makes
  // them point into the meshes' vertex arrays (RTC_SCENE_FLAG_COMPACT: about
  // a fifth less memory for a large mesh, about 10 % slower; the same hits,
  // so the same image). Measured in docs/performance.md.
  bool compact_bvh = false;
  // Robust by default: the closed-form tests rely on closed meshes staying
  // closed. Fast changes a sample's bits where a ray slips through an edge.
  Intersection intersection = Intersection::Robust;
  // Textures: how lookups are filtered, and OIIO's tile cache (MB).
  TextureFilter texture_filter = TextureFilter::Cone;
  float texture_cache_mb = 256.0f;
};
inline constexpr int kMaxVerticesUncapped = 1000;
// The last vertex a path may scatter at under `settings`: max_depth, or the
// safety cap where it is -1 (no cap).
inline int max_vertex(const RenderSettings& settings) {
  return settings.max_depth >= 0 ? settings.max_depth : kMaxVerticesUncapped;
}

struct Shape {
  enum class Kind : std::uint8_t { Triangles, Sphere };
  Kind kind = Kind::Triangles;
  std::string description;     // for messages, e.g. "shapes[2] (mesh bunny.ply)"
  std::uint32_t material = 0;  // index into Scene::materials
  TriangleMesh mesh;           // Kind::Triangles, world space, counter-clockwise = front
  vec3 center{0.0f};           // Kind::Sphere
  float radius = 0.0f;
  bool flip_normals = false;   // front side faces the other way
  // Defined in a group's own space (Scene::groups) and placed only by the
  // scene's instances; false for a shape placed in world space.
  bool in_group = false;
};

// Shapes defined once, in their own space, and placed many times by
// instances (Embree instances, one level: a group holds shapes, never
// instances). Its shapes are in Scene::shapes, marked in_group.
struct ShapeGroup {
  std::string name;
  std::vector<std::uint32_t> shapes;  // indices into Scene::shapes
};

// One placement of a group.
struct Instance {
  std::uint32_t group = 0;  // index into Scene::groups
  mat4 to_world{1.0f};      // affine, invertible
  std::string description;  // for messages, e.g. "instances[0][17] (dragon)"
};
// The instance of a hit on a shape placed in world space (RayHit, Surfel).
inline constexpr std::uint32_t kNoInstance = 0xffffffffu;

// A light no ray can hit, reached only by next-event estimation
// (docs/scene-format.md, Lights).
//   Point:       intensity I (W/sr per channel) in every direction from `position`.
//   Spot:        I on the axis `direction` (unit, pointing away from `position`),
//                times smoothstep(cos theta; cos_outer, cos_inner) (pbrt-v4's
//                SpotLight): 1 inside the inner cone, 0 outside the outer.
//   Directional: `intensity` is the irradiance E (W/m^2 per channel) on a
//                surface facing the light; `direction` (unit) is the way the
//                light travels. `position` unused. With an angular_radius
//                alpha > 0 it is no delta light but a sun disk: uniform
//                radiance E / (pi sin^2 alpha) from the cone of half-angle
//                alpha about -direction, which rays can hit; LightSampler
//                samples it with the area lights and the environment.
struct DeltaLight {
  enum class Kind : std::uint8_t { Point, Spot, Directional };
  vec3 position{0.0f};
  Spectrum intensity{0.0f};
  Kind kind = Kind::Point;
  vec3 direction{0.0f, 0.0f, -1.0f};
  float cos_outer = 0.0f;  // spot: cosine of the outer half-angle (cone_angle)
  float cos_inner = 0.0f;  // spot: cosine of the inner half-angle (falloff_start)
  float angular_radius = 0.0f;  // directional: half the angular diameter, radians (0: a delta light)
  bool is_sun_disk() const { return kind == Kind::Directional && angular_radius > 0.0f; }
};
// The largest radiance component of the scene's emitters when every one is
// a constant (emitting shapes' materials without an emission texture, a
// uniform environment); nullopt if there is none, or any other light (an
// emission texture, an environment image, point, spot or directional lights,
// sun disks), whose brightest sample this cannot bound.
std::optional<float> constant_emitters_peak(const Scene& scene);
// The brightest of the scene's constant emitters the image can see (placed
// shapes' materials without an emission texture, a uniform environment),
// whatever other lights it has: its largest radiance component, and what
// it is ("material 'lamp'", "the environment"); nullopt if there is none.
struct EmitterPeak {
  float radiance = 0.0f;
  std::string source;
  // Whether the scene has no other light (an emission texture, an
  // environment image, point, spot or directional lights, sun disks), so
  // that `radiance` bounds every emitter (constant_emitters_peak).
  bool bounds_every_light = true;
};
std::optional<EmitterPeak> brightest_constant_emitter(const Scene& scene);
// The spot profile: 1 for cos_theta >= cos_inner, 0 for cos_theta <= cos_outer,
// a smoothstep in cos theta between.
float spot_profile(float cos_theta, float cos_outer, float cos_inner);

struct Scene {
  std::filesystem::path file;  // empty for a built-in scene
  std::string name;            // file stem, or the built-in scene's name
  CameraDesc camera;
  FilmDesc film;
  RenderSettings render;
  std::vector<Material> materials;
  // The file's shapes in its order (a "gltf" entry adds one per primitive
  // copied into the world, then the shapes of its groups: meshes several
  // nodes place), then the groups' shapes.
  std::vector<Shape> shapes;
  std::vector<ShapeGroup> groups;
  std::vector<Instance> instances;
  std::vector<DeltaLight> delta_lights;  // point, spot and directional lights (and sun disks)
  std::vector<TextureImage> textures;    // the images materials read (TextureRef::image)
  std::optional<Spectrum> environment;  // uniform radiance from every direction
  // Or a lat-long image of the radiance from each direction (shared by the
  // copies of a scene; then `environment` is empty: there is one at most).
  std::shared_ptr<const EnvironmentMap> environment_map;
  std::vector<std::string> warnings;    // non-fatal problems found while loading
  // Every file the scene loaded besides its own (meshes, glTF files, ...),
  // as resolved, in the order loaded: what a render's fingerprint hashes
  // (core/partial_film.h).
  std::vector<std::filesystem::path> input_files;
  // The closed-form model whose answer this scene has ("furnace", ...; see
  // analytic-scenes/), or empty. Only `pathlab check` reads it.
  std::string analytic;
};

}  // namespace pathlab
