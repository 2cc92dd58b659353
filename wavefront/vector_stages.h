// The wavefront's vectorised stages: paths kept as one array per scalar
// (structure of arrays), a block of them per SIMD register — 16 with
// AVX-512, 8 with AVX2, 4 with SSE4, whichever core/simd/simd.h's dispatch
// selected — for every scene (any camera, material, light, texture,
// instance, alpha). The lanes do the camera, world-space hit points (on
// instances too), alpha, emission and its weight, every light (triangles and
// spheres sampled by area or solid angle, the environment, sun disks, delta
// lights, the points of textured emitters), Lambert, Disney (either sampling
// of its glossy lobes), mirror and dielectric shading, textured or not, in
// the geometric normal's frame or the hit's own (vertex normals, tangents,
// a normal map's tilt: Scene::framed), textured meshes' texture coordinates
// and footprints, the ray cones, roulette and compaction. Core does, one
// path at a time between the lanes' steps: the texel reads (OpenImageIO's)
// at hits and at textured emitters' light samples, whole hits on textured
// spheres and emitters, the general shading path's materials, the strategy
// `cosine`, and environment images of 2^29 texels or more (Scene::general,
// textured, general_lights).
// `--simd scalar` runs the scalar stages of wavefront_tracer.cpp.
//
// Written once (vector_stages.cpp, over Google Highway, compiled for every
// target) on core's per-lane code (core/simd/*-inl.h, core/bsdf/*-inl.h,
// which core's scalar functions run at width 1). Same paths: every lane
// computes what the scalar code computes, operation for operation and in
// the same order, and Embree
// sees the same batches in the same order. tests/test_wavefront.cpp checks
// every sample of several scenes bit for bit against the scalar stages at
// every target the processor runs.
//
// This header is plain data: the per-target code lives in vector_stages.cpp.
#pragma once

#include "core/sample_dims.h"

#include <cstddef>
#include <cstdint>

namespace pathlab {
class CompiledScene;
struct SurfaceParams;
enum class Strategy : std::uint8_t;  // core/scene.h
}

namespace pathlab::vector_stages {

// The area lights and the sky, as LightSampler::sample() picks and samples
// them: entries [0, Sky::first_entry) are triangles and spheres, the rest
// the sky's.
struct Lights {
  std::size_t count = 0;
  const float* cdf = nullptr;       // LightSampler::cdf()
  const float* pmf = nullptr;       // LightSampler::pmf()
  const float* inv_area = nullptr;  // 1 / area, as LightSampler computes it
  // Per light, 16 floats (LightField): p0, p1, p2, front normal, emitted
  // radiance, and 1 if it emits on both sides (else 0); a sphere's centre
  // in p0's place, its radius and 1 if its normals point inwards (else 0)
  // in p1.x and p1.y.
  const float* triangle = nullptr;
  // The same values by column when there are 1 to 16 lights (else null):
  // LightField f of light l at [16 f + l], then the cdf, pmf and 1 / area
  // rows (kLightCdf...). A lookup is then one permute of a register
  // instead of a gather from memory.
  const float* columns = nullptr;
  // Per light, 1 for a sphere (else 0), when some light is one (else null).
  const float* sphere = nullptr;
  // Per light, 1 where its emission is a texture (else 0), when some light's
  // is (else null): a sample's radiance is read by core, path by path
  // (LightSampler::emission_at_point), the rest is the lanes'.
  const float* textured = nullptr;
  // Under `light_sampler: bvh`: `bvh`; the grid points of LightChoice below
  // bvh_grid walk the tree (if any), the rest pick the sky's entries (Sky).
  bool bvh = false;
  // The tree (else bvh_nodes is null): kBvhFields
  // doubles per node (core/simd/light_bvh-inl.h, BvhField); per tree light its
  // trail (LightBvh::trails) and entry; per entry its tree light or -1; the
  // grid points of LightChoice that walk the tree (LightSampler::bvh_grid).
  const double* bvh_nodes = nullptr;
  const std::uint64_t* bvh_trail = nullptr;
  const std::int32_t* bvh_entry = nullptr;
  const std::int32_t* bvh_light = nullptr;
  std::uint32_t bvh_grid = 0;
};
enum LightField : int {
  kLightP0 = 0, kLightP1 = 3, kLightP2 = 6, kLightNormal = 9, kLightLe = 12, kLightTwoSided = 15,
  kLightCdf = 16, kLightPmf = 17, kLightInvArea = 18,  // rows of Lights::columns only
  kLightColumns = 19,
};

// The delta lights (point, spot, directional), as LightSampler::
// sample_delta() picks and samples them.
struct DeltaLights {
  std::size_t count = 0;
  const float* cdf = nullptr;    // LightSampler::delta_cdf()
  const float* table = nullptr;  // per light, kDeltaFields floats (DeltaField)
};
enum DeltaField : int {
  kDeltaKind = 0,        // DeltaKind, as a float
  kDeltaPosition = 1,    // 3 floats
  kDeltaDirection = 4,   // 3 floats
  kDeltaIntensity = 7,   // 3 floats
  kDeltaCosOuter = 10,
  kDeltaCosInner = 11,
  kDeltaPmf = 12,        // LightSampler::delta_pmf()
  kDeltaFields = 16,
};

enum DeltaKind : int { kDeltaPoint = 0, kDeltaSpot = 1, kDeltaDirectional = 2 };

// The sky (an environment of one radiance or an image, sun disks):
// LightSampler::sample's sky entries and LightSampler::sky() of an escaped ray.
struct Sky {
  std::size_t first_entry = 0;   // the first of the sky's light entries (Lights)
  std::int64_t environment = -1; // the environment's entry, or -1 if it is not sampled
  float Le[3] = {};              // an environment of one radiance: it (0 without one)
  float pmf = 0.0f;              // the environment's pick probability (0 if it is not sampled)
  // An environment image (else image is null; core/environment_map.h): its
  // texels (RGB, row-major), width and height (whole floats), the rotations
  // from the world to its frame and back (GLM's columns), and its importance
  // sampler's cdfs (Distribution2D): the rows' (height + 1 floats), then
  // each row's columns' (width + 1 floats a row).
  const float* image = nullptr;
  float width = 0.0f, height = 0.0f;
  float to_local[9] = {}, to_world[9] = {};
  const float* row_cdf = nullptr;
  const float* column_cdf = nullptr;
  std::size_t suns = 0;
  const float* sun = nullptr;    // per sun disk kSunFields floats (SunField)
  // Under `bvh`: the grid bounds of the sky's entries (LightSampler::
  // sky_starts, as floats: exact, at most 2^24) and the entries (sky_entries).
  std::size_t count = 0;
  const float* starts = nullptr;
  const float* entries = nullptr;
};
enum SunField : int {
  kSunS = 0, kSunT = 3, kSunN = 6,  // LightSampler::SunDisk::frame
  kSunOneMinusCos = 9, kSunSin2 = 10,
  kSunPdf = 11,                     // LightSampler::sun_pdf
  kSunLe = 12,                      // 3 floats
  kSunEntry = 15,                   // its light entry
  kSunFields = 16,
};

// What the stages read of the scene and the render settings.
struct Scene {
  // The sampling strategy (core/scene.h). Under cosine every surface
  // scatters by core's Surfel::scatter_cosine (every shape kGeneral).
  Strategy strategy{};
  int rr_depth = 0;
  int max_vertex = 0;  // paths end at a vertex beyond this (the depth cap)
  float min_pdf = 0.0f;
  std::size_t shape_count = 0;
  bool one_sided = false;  // some shape's material is one-sided (ShapeField kOneSided): else no lane looks
  // Some shape is not shaded in the lanes (ShapeField kGeneral): its paths'
  // BSDF is evaluated and sampled by core's Surfel, one path at a time;
  // resolve() keeps its shading frame from compiled->resolve() (kFsX...).
  bool general = false;
  // Some shape the lanes shade has a shading frame of its own (ShapeField
  // kFramed): made in resolve() from its vertex normals (kNormalsAt) and
  // tangents (kTangentsAt) or the geometric normal, tilted by a normal map;
  // and an emitter that scatters nothing but reads its emission from a
  // texture (a frame no lane shades in, resolved for that texel).
  bool framed = false;
  // Some shape the lanes shade is a mirror or a dielectric (ShapeField
  // kLaneMaterial): else every lane shaded in the lanes is Lambert's or
  // Disney's.
  bool impulses = false;
  // Some material the lanes shade is Disney's: the lobes every Disney
  // material of the scene is shaded with (disney::Features: kDisneyLobes,
  // with kClearcoat if the scene has a clear coat, as core's ShadingPath
  // says); else 0.
  unsigned disney = 0;
  // The Disney materials' glossy lobes are sampled by cosine-power lobes
  // (`bsdf_sampling: cospow`, disney-inl.h's CospowLobes), else by their
  // visible normals (VndfLobes).
  bool disney_cospow = false;
  const CompiledScene* compiled = nullptr;
  // light_sampling solid_angle: triangle and sphere lights are sampled in
  // the spherical triangle or cone they subtend where the fallback rule
  // says so (core/sampling_spherical.h), in the lanes' double halves.
  bool solid_angle = false;
  // Lights beyond triangles and spheres and the sky of Sky (an environment
  // image too large for the gathers' indices):
  // compiled->lights() samples them all
  // and gives their densities, path by path; `sky`: escaped rays find an
  // environment or a sun disk (LightSampler::sky; in the lanes by `skies`
  // unless general_lights).
  bool general_lights = false;
  bool sky = false;
  Sky skies;
  // The scene places shapes by instances: hits on them (kInstance set) are
  // resolved in their group's space and placed by `placements`, in the
  // lanes as CompiledScene::resolve does (by it, path by path, where it
  // resolves the hit anyway: textures, tangents).
  bool instanced = false;
  // Some material has alpha: every ray carries its alpha key (kAlphaKey,
  // kQAlphaKey) into Embree, whose filter decides (core/alpha.h).
  bool alpha = false;
  // The scene's delta lights (point, spot, directional); with any, each path
  // samples one too (LightSampler::sample_delta, in the lanes), a second
  // shadow ray.
  DeltaLights deltas;
  // The scene has textures: each path carries its ray cone (kConeWidth,
  // kConeSpread; CompiledScene::camera_cone, scattered_cone under
  // texture_filter, a TextureFilter), and a textured material's hit its
  // parameters (Wave::params), read by compiled->resolve().
  bool textured = false;
  float camera_cone_width = 0.0f, camera_cone_spread = 0.0f;
  std::uint8_t texture_filter = 0;
  // The zsobol sampler (else the independent one): SamplerSetup::zsobol_bits().
  bool zsobol = false;
  unsigned zsobol_bits = 0;
  Lights lights;
  // Energy compensation's tables (core/bsdf/energy.h) of the Disney
  // materials the lanes shade that have them, kEnergyFloats floats each
  // (EnergyField), at ShapeField kEnergy; null if none.
  const float* energy = nullptr;
  // Per shape, kShapeFields floats (ShapeField): its material's albedo, emission and
  // flags, its first light entry, and its geometry.
  const float* shape = nullptr;
  // The same by column when there are at most 16 shapes (else null): field
  // f of shape s at [16 f + s].
  const float* shape_columns = nullptr;
  // Every triangle (CompiledScene::triangles(): 12 floats each, p0 p1 p2 n).
  const float* triangles = nullptr;
  // The triangles (with their vertex normals, uvs and tangents) take more
  // than kPrefetchBytes: worth prefetch_hits()'s pass before resolve(). A
  // scene that small stays in the caches, where the pass costs time for
  // nothing (1.6 % of the process on Mitsuba's Cornell box).
  static constexpr std::size_t kPrefetchBytes = std::size_t{1} << 18;
  bool prefetch = true;
  // The vertex normals of each triangle of the kFramed meshes whose frames
  // the lanes make (ShapeField kNormalsAt): 9 floats a triangle, n0 n1 n2
  // (its vertices' Mesh::normals); null if there are none.
  const float* vertex_normals = nullptr;
  // The texture coordinates of each triangle of the kTexturedHits meshes
  // (ShapeField kUvsAt): 6 floats a triangle, uv0 uv1 uv2 (Mesh::uvs); null
  // if there are none.
  const float* triangle_uvs = nullptr;
  // The tangents (xyz and handedness w) of each triangle of the meshes with
  // ShapeField kTangentsAt: 12 floats a triangle, t0 t1 t2 (Mesh::tangents);
  // null if there are none.
  const float* vertex_tangents = nullptr;
  // Some shape is kTexturedHits.
  bool textured_hits = false;
  // Per instance, kPlacementFloats floats (PlacementField): its
  // CompiledScene::Placement; null without instances.
  const float* placements = nullptr;
};
// An instance's transforms (CompiledScene::Placement) by GLM's columns,
// their first three rows.
enum PlacementField : int {
  kToWorld = 0,     // 4 columns of 3 floats: x, y, z, the translation
  kToLocal = 12,    // its inverse, the same way
  kToNormal = 24,   // 3 columns of 3 floats: the inverse transpose of to_world's linear part
  kMirrors = 33,    // 1 if to_world's linear part has a negative determinant, else 0
  kPlacementFloats = 34,
};
enum ShapeField : int {
  kAlbedo = 0,         // 3 floats
  kEmission = 3,       // 3 floats
  kTwoSided = 6,       // 1 if it emits on both sides, else 0
  kEmits = 7,          // 1 if it emits
  kScatters = 8,       // 1 if it scatters
  kFirstLight = 9,     // bits of an int32: its triangle 0's light entry, -1 if not a light
  kFirstTriangle = 10, // bits of an int32: its triangle 0 in Scene::triangles (a mesh)
  kIsSphere = 11,      // 1 for a sphere, 0 for a mesh
  kCenter = 12,        // 3 floats (a sphere)
  kRadius = 15,        // a sphere's radius
  kFlipped = 16,       // 1 if a sphere's normals point inwards
  kOneSided = 17,      // 1 if its material is one-sided (black from behind the geometric normal)
  kGeneral = 18,       // 1 if it is shaded by core's Surfel (not untextured Lambert or Disney, flat mirror or glass)
  kTexturedEmission = 19,  // 1 if its emission is textured (add_emission reads the texel from Wave::params)
  kResolveByCore = 20,     // 1 if kGeneral and its Surfel needs CompiledScene::resolve (a shading frame of its
                           // own, textures); else resolve() makes its Frame(n) in the lanes
  kLaneMaterial = 21,      // what the lanes shade it with (LaneMaterial), unless kGeneral
  kIor = 22,               // a dielectric's DielectricParams
  kReflectance = 23,       // 3 floats
  kTransmittance = 26,     // 3 floats
  // A Disney material's disney::Closure (kLaneDisney; core/bsdf/closure.h).
  kDiffuse = 29,           // 3 floats
  kRoughness = 32,
  kSubsurface = 33,
  kSheen = 34,             // 3 floats
  kSpecular = 37,
  kSpec0 = 38,             // 3 floats
  kAx = 41,
  kAy = 42,
  kClearcoat = 43,
  kClearcoatAlpha = 44,
  kClearcoatLogA2 = 45,
  kClearcoatLog2A2 = 46,
  kEnergy = 47,            // bits of an int32: its energy tables' first float in Scene::energy, -1 if none
  kFramed = 48,            // 1 if the lanes shade it in a frame of its own (vertex normals, tangents,
                           // textures), which resolve() makes (kNormalsAt, kTangentsAt; Frame(n) for a flat
                           // kTexturedHits mesh or sphere; tilted by a normal map) (kFsX..., kShadingNormal);
                           // also 1 for an emitter that scatters nothing but has an emission texture
  kNormalsAt = 49,         // bits of an int32: a kFramed mesh's triangle 0 in Scene::vertex_normals, whose
                           // vertex normals make its frame in the lanes; -1 if it has none
  kTexturedHits = 50,      // 1 if its material reads textures at hits and the lanes resolve the hit (a kFramed
                           // mesh or sphere): they make its frame and the lookups' footprint, core reads the
                           // texels into the slot's SurfaceParams (its emission too, which add_emission takes)
                           // and the normal map's into kMapR..., path by path
  kUvsAt = 51,             // bits of an int32: a kTexturedHits mesh's triangle 0 in Scene::triangle_uvs; -1 if
                           // the mesh has no texture coordinates (its barycentrics are)
  kTangentsAt = 52,        // bits of an int32: a kFramed mesh's triangle 0 in Scene::vertex_tangents, whose
                           // tangents make its frame in the lanes (about its vertex normals' or geometric
                           // normal); -1 if it has none
  kNormalMapped = 53,      // 1 if a kTexturedHits shape's material has a normal map, which tilts its frame in
                           // the lanes (normal_mapped_frame) from the texel core reads (kMapR...)
  kNormalMapScale = 54,    // its NormalMap::scale
  kTexturedParams = 55,    // 1 if a kTexturedHits shape's material has textured parameters (kHasParams), 0 if
                           // it reads only a normal map
  kShapeFields = 56,
};

// A Disney material's EnergyTables in Scene::energy.
enum EnergyField : int {
  kEnergySpecular = 0,        // kEnergyTableSize entries of 3 floats
  kEnergyCoat = 99,           // kEnergyTableSize floats
  kEnergyDiffuseScale = 132,  // 3 floats
  kEnergyFloats = 135,
};

// The materials the lanes shade (ShapeField kLaneMaterial), as floats.
enum LaneMaterial : int { kLaneLambert = 0, kLaneMirror = 1, kLaneDielectric = 2, kLaneDisney = 3 };

// A camera (Camera::generate_ray).
struct Camera {
  float position[3], forward[3], right[3], up[3];
  float tan_half_fov, aspect, inv_width, inv_height;
  float aperture_radius, focus_distance;  // a pinhole if aperture_radius <= 0
};

// The state of a wave's paths, one array per scalar, each with room for a
// whole wave. Slots [0, n) hold the live paths.
enum FloatArray : int {
  kOx, kOy, kOz, kDx, kDy, kDz, kTmax,  // the ray to trace next
  kBetaR, kBetaG, kBetaB,               // throughput
  kLR, kLG, kLB,                        // radiance so far
  kPrevX, kPrevY, kPrevZ, kPrevPdf,     // PreviousVertex
  kPrevNx, kPrevNy, kPrevNz,            // PreviousVertex::ref.n (the light BVH's query)
  kFilmX, kFilmY,
  kConeWidth, kConeSpread,              // the ray's cone (Scene::textured)
  kTexU, kTexV, kTexWidth,              // a kTexturedHits hit's texture footprint (TextureFootprint)
  kMapR, kMapG, kMapB,                  // and its normal map's texel (kNormalMapped)
  // A hit's textured parameters where kHasParams says so, as the lanes read
  // them (Wave::params' SurfaceParams, copied by core where it evaluated
  // them): the albedo, the dielectric's tints, the Disney closure's lobes.
  kPrmAlbedo, kPrmAlbedoG, kPrmAlbedoB,
  kPrmReflectance, kPrmReflectanceG, kPrmReflectanceB,
  kPrmTransmittance, kPrmTransmittanceG, kPrmTransmittanceB,
  kPrmDiffuse, kPrmDiffuseG, kPrmDiffuseB, kPrmRoughness, kPrmSubsurface,
  kPrmSheen, kPrmSheenG, kPrmSheenB, kPrmSpecular, kPrmSpec0, kPrmSpec0G, kPrmSpec0B,
  kPrmAx, kPrmAy, kPrmClearcoat, kPrmClearcoatAlpha, kPrmClearcoatLogA2, kPrmClearcoatLog2A2,
  // This bounce only: the hit and the Surfel made of it.
  kHitT, kHitU, kHitV,
  kPx, kPy, kPz, kErrX, kErrY, kErrZ, kNx, kNy, kNz,
  // The shading frame (s, t, n) of a hit on a shape core's Surfel shades
  // (ShapeField kGeneral) or with a frame of its own (kFramed), as
  // CompiledScene::resolve (or the lanes, for a flat kGeneral shape) made it.
  kFsX, kFsY, kFsZ, kFtX, kFtY, kFtZ, kFnX, kFnY, kFnZ,
  // The shadow rays to trace, packed in path order for Embree (up to two a
  // path: room for 2 n), and what each brings if nothing blocks it.
  kQOx, kQOy, kQOz, kQDx, kQDy, kQDz, kQTmax, kQUnR, kQUnG, kQUnB,
  kFloatArrays
};
// The Disney closure's fields that the lanes read, in one list: each one's
// ShapeField (an untextured material's value, in the shape table) and
// FloatArray (a textured hit's, kPrm...). Calls f(field, shape_field,
// float_array) for each field of c, a disney::Closure or the lanes'
// ClosureLanes (core/bsdf/disney-inl.h); a field is a float or a
// Spectrum there, a vector or a Vec3 of them here. A field added to the
// closure is added here, and the tracer fills the table, the lanes read it
// and core's textured parameters reach the lanes by this list alone.
template <class Closure, class F>
void for_each_closure_field(Closure& c, F&& f) {
  f(c.diffuse, kDiffuse, kPrmDiffuse);
  f(c.roughness, kRoughness, kPrmRoughness);
  f(c.subsurface, kSubsurface, kPrmSubsurface);
  f(c.sheen, kSheen, kPrmSheen);
  f(c.specular, kSpecular, kPrmSpecular);
  f(c.spec0, kSpec0, kPrmSpec0);
  f(c.ax, kAx, kPrmAx);
  f(c.ay, kAy, kPrmAy);
  f(c.clearcoat, kClearcoat, kPrmClearcoat);
  f(c.clearcoat_alpha, kClearcoatAlpha, kPrmClearcoatAlpha);
  f(c.clearcoat_log_a2, kClearcoatLogA2, kPrmClearcoatLogA2);
  f(c.clearcoat_log2_a2, kClearcoatLog2A2, kPrmClearcoatLog2A2);
}

enum UintArray : int {
  kOutIndex, kRays, kVertex, kPixelX, kPixelY,
  kShape, kPrim,  // the hit's
  kInstance,      // the hit's instance (kNoInstance for a shape in world space), when Scene::instanced
  kAlphaKey,      // the next ray's alpha key (core/alpha.h), when Scene::alpha
  kQPath,         // per packed shadow ray: the slot of its path
  kQAlphaKey,     // per packed shadow ray: its alpha key, when Scene::alpha
  kUintArrays
};
enum ByteArray : int {
  kAlive, kFound, kPrevImpulse, kPrevBsdfTechnique,
  kShadingNormal,  // Surfel::shading_normal of a hit on a kGeneral or kFramed shape
  kHasParams,      // its Surfel reads Wave::params (a textured material's)
  kShadeByCore,    // this bounce's hit is shaded by core's Surfel (a kGeneral shape's, or a normal not finite)
  kQOccluded,  // per packed shadow ray
  kByteArrays
};
struct Wave {
  std::size_t n = 0;
  float* f[kFloatArrays] = {};
  std::uint32_t* u[kUintArrays] = {};
  std::uint8_t* b[kByteArrays] = {};
  std::uint64_t* rng = nullptr;  // SampleStream::key() per path
  // Under zsobol (Scene::zsobol): SamplerSetup::zsobol_index and zsobol_key per path.
  std::uint64_t* zindex = nullptr;
  std::uint64_t* zkey = nullptr;
  // Under Scene::textured: per slot, the parameters of this bounce's hit.
  SurfaceParams* params = nullptr;
};

// What compact() writes for each path that ended: FilmSample's fields, in
// its layout (wavefront_tracer.cpp checks that they agree).
struct Sample {
  float film_x, film_y, L[3];
  std::uint32_t rays, hits;
};

// Whether the vectorised stages run: the selected SIMD target is not
// `scalar` (core/simd/simd.h).
bool cpu_supported();
// Paths per block (lanes of the selected target): 16, 8 or 4.
std::size_t lanes();
// The arrays of a Wave need this many slots beyond its capacity, rounded up
// to a whole block of the widest target: a block is loaded whole.
constexpr std::size_t kPadding = 32;

// SampleStream keys for a wave: each of keys[0, n) holds
// SampleStream::pixel_sample(pixel, sample) and becomes SampleStream::key()
// (core/simd/stream-generic.h's stream_key, seed_key SampleStream::seed_key).
void hash_keys(std::uint64_t* keys, std::size_t n, std::uint64_t seed_key);

// The stages, in the order a bounce runs them (wavefront_tracer.cpp has the
// scalar twin of each). Tracing the rays themselves is Embree's.
// Each path's random stream, pixel and sample are set; make its camera ray
// and reset its state.
void generate_camera_rays(const Scene& scene, const Camera& camera, const Wave& wave);
// Prefetches the triangle each mesh hit landed on, for resolve(): one pass
// first lets the hits' cache misses overlap.
void prefetch_hits(const Scene& scene, const Wave& wave);
// The Surfel of each path whose ray found a surface, and one more ray per path.
void resolve(const Scene& scene, const Wave& wave);
// The emission each ray found, as the strategy weighs it, and the end of
// paths that escaped, passed the depth cap or cannot scatter (the scene has
// no environment light).
void add_emission(const Scene& scene, const Wave& wave);
// Next-event estimation for every live path: a delta light's sample (when
// the scene has them) and an area light's, as the strategy says; packs the
// shadow rays to trace into the kQ arrays, in path order, and returns how
// many.
std::size_t sample_lights(const Scene& scene, const Wave& wave);
// The light of every visible sample, once Embree has filled kQOccluded
// (kQPath says whose each packed shadow ray is).
void add_light(const Wave& wave, std::size_t queries);
// The continuation (Lambert, Disney, mirrors and glass in the lanes, any
// other surface by core's Surfel::scatter), Russian roulette and the next ray.
void scatter(const Scene& scene, const Wave& wave);
// Packs the survivors into slots [0, m) in order and returns m; each path
// that ended is written to samples[its kOutIndex - first_slot] (an array of
// Sample's layout, copied in bytes).
std::size_t compact(const Scene& scene, const Wave& wave, void* samples, std::uint32_t first_slot);

}  // namespace pathlab::vector_stages
