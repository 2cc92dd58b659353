#include "core/embree_accel.h"

#include "core/alpha.h"
#include "core/error.h"
#include "core/geometry.h"
#include "core/scene_limits.h"
#include "core/texture.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <vector>

namespace pathlab {
namespace {

// Hits set instID[0] only: instances place groups of shapes, never other
// instances, and Embree is built with one instance level.
static_assert(RTC_MAX_INSTANCE_LEVEL_COUNT == 1);
static_assert(kNoInstance == RTC_INVALID_GEOMETRY_ID);

// Embree reports errors through a callback registered when the device is
// created; we keep the first one and turn it into an exception after the
// call that caused it (library code never exits).
struct ErrorSink {
  std::mutex mutex;
  std::string first;
  static void callback(void* user, RTCError code, const char* message) {
    if (code == RTC_ERROR_NONE) return;
    auto* sink = static_cast<ErrorSink*>(user);
    std::lock_guard<std::mutex> lock(sink->mutex);
    if (sink->first.empty()) sink->first = message ? message : "unknown Embree error";
  }
  void check(const char* what) {
    std::lock_guard<std::mutex> lock(mutex);
    if (!first.empty()) throw SystemError(std::string("Embree: ") + what + ": " + first);
  }
};

// What the alpha filter of one geometry reads (its user data): the shape's
// coverage, and what turns Embree's IDs into the scene's shape and instance
// indices that the decision hashes (core/alpha.h).
struct AlphaGeometry {
  float alpha = 1.0f;
  float cutoff = -1.0f;              // Material::alpha_cutoff
  std::uint32_t shape = 0;           // index into Scene::shapes
  std::uint32_t first_instance = 0;  // geometry ID of instance 0 in the top scene
  // A textured coverage (else null): the texture, its images, and the mesh
  // whose texture coordinates (or, without them, the barycentrics, as
  // CompiledScene::resolve reads them) say where.
  const TextureRef* texture = nullptr;
  const Textures* textures = nullptr;
  const TriangleMesh* mesh = nullptr;

  // The coverage at barycentrics (b1, b2) of triangle `prim`.
  float at(unsigned prim, float b1, float b2) const {
    float a = alpha;
    if (texture) {
      a = std::clamp(textures->nearest_number(*texture, mesh->uv_at(prim, vec2(b1, b2))), 0.0f, 1.0f);
    }
    if (cutoff >= 0.0f) a = a >= cutoff ? 1.0f : 0.0f;
    return a;
  }
};

// Embree's intersection and occlusion filter for a geometry with alpha: a
// hit the alpha test rejects is made invalid, and traversal goes on past it.
// A pure function of (ray key, shape, triangle, instance), so Embree may
// call it for the same triangle any number of times, in any order.
void alpha_filter(const RTCFilterFunctionNArguments* args) {
  const auto* g = static_cast<const AlphaGeometry*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) continue;
    const unsigned key = RTCRayN_id(args->ray, args->N, i);
    const unsigned prim = RTCHitN_primID(args->hit, args->N, i);
    const unsigned inst = RTCHitN_instID(args->hit, args->N, i, 0);
    const std::uint32_t instance = inst == RTC_INVALID_GEOMETRY_ID ? kNoInstance : inst - g->first_instance;
    const float alpha = g->at(prim, RTCHitN_u(args->hit, args->N, i), RTCHitN_v(args->hit, args->N, i));
    if (!alpha_stops(alpha, alpha_uniform(key, g->shape, prim, instance))) args->valid[i] = 0;
  }
}

// A sphere as Embree user geometry (its user data): Embree's traversal
// finds the candidates through the box, and every ray - whichever of
// rtcIntersect1/16/1M/Np or rtcOccluded* brought it - is decided by the same
// scalar function, sphere_crossing (core/geometry.h). Embree's own
// RTC_GEOMETRY_TYPE_SPHERE_POINT kernels round t differently in their
// one-ray and 16-wide forms, so the hits, and shadow rays ending on a
// sphere, depended on how many rays shared a batch.
struct SphereGeometry {
  vec3 center{0.0f};
  float radius = 0.0f;
};

// The sphere's box, widened by 1e-5 of the radius and four floats of its
// largest coordinate: every ray sphere_crossing lets hit passes through the
// box's interior, well clear of any kernel's rounding of the box test.
void sphere_bounds(const RTCBoundsFunctionArguments* args) {
  const auto* s = static_cast<const SphereGeometry*>(args->geometryUserPtr);
  const vec3 c = s->center;
  const float largest = std::max({std::abs(c.x), std::abs(c.y), std::abs(c.z)}) + s->radius;
  const float margin = s->radius * (1.0f + 1e-5f) + 4.0f * largest * 0x1p-23f;
  RTCBounds* b = args->bounds_o;
  b->lower_x = c.x - margin, b->lower_y = c.y - margin, b->lower_z = c.z - margin;
  b->upper_x = c.x + margin, b->upper_y = c.y + margin, b->upper_z = c.z + margin;
}

float crossing(const SphereGeometry& s, RTCRayN* ray, unsigned n, unsigned i) {
  const vec3 o(RTCRayN_org_x(ray, n, i), RTCRayN_org_y(ray, n, i), RTCRayN_org_z(ray, n, i));
  const vec3 d(RTCRayN_dir_x(ray, n, i), RTCRayN_dir_y(ray, n, i), RTCRayN_dir_z(ray, n, i));
  return sphere_crossing(o, d, RTCRayN_tnear(ray, n, i), RTCRayN_tfar(ray, n, i), s.center, s.radius);
}

// Closest hit: a crossing nearer than the ray's tfar becomes the hit. No
// filter runs (spheres take no alpha, and our contexts carry no filter).
// u, v are 0, as Embree's sphere kernels gave; Ng points outwards from the
// centre (pathlab reads neither: CompiledScene::resolve reprojects).
void sphere_intersect(const RTCIntersectFunctionNArguments* args) {
  const auto& s = *static_cast<const SphereGeometry*>(args->geometryUserPtr);
  RTCRayN* ray = RTCRayHitN_RayN(args->rayhit, args->N);
  RTCHitN* hit = RTCRayHitN_HitN(args->rayhit, args->N);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) continue;
    const float t = crossing(s, ray, args->N, i);
    if (std::isnan(t)) continue;
    RTCRayN_tfar(ray, args->N, i) = t;
    const vec3 o(RTCRayN_org_x(ray, args->N, i), RTCRayN_org_y(ray, args->N, i), RTCRayN_org_z(ray, args->N, i));
    const vec3 d(RTCRayN_dir_x(ray, args->N, i), RTCRayN_dir_y(ray, args->N, i), RTCRayN_dir_z(ray, args->N, i));
    const vec3 ng = o + t * d - s.center;
    RTCHitN_Ng_x(hit, args->N, i) = ng.x;
    RTCHitN_Ng_y(hit, args->N, i) = ng.y;
    RTCHitN_Ng_z(hit, args->N, i) = ng.z;
    RTCHitN_u(hit, args->N, i) = 0.0f;
    RTCHitN_v(hit, args->N, i) = 0.0f;
    RTCHitN_primID(hit, args->N, i) = args->primID;
    RTCHitN_geomID(hit, args->N, i) = args->geomID;
    RTCHitN_instID(hit, args->N, i, 0) = args->context->instID[0];
  }
}

// Any hit: a crossing before tfar occludes (Embree's convention: tfar = -inf).
void sphere_occluded(const RTCOccludedFunctionNArguments* args) {
  const auto& s = *static_cast<const SphereGeometry*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) continue;
    if (!std::isnan(crossing(s, args->ray, args->N, i)))
      RTCRayN_tfar(args->ray, args->N, i) = -std::numeric_limits<float>::infinity();
  }
}

}  // namespace

namespace {
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
// Rays refused because Embree would abort on them (embree_rejected_rays): a
// count for the render's warning, never read by the tracers.
std::atomic<std::uint64_t> g_rejected{0};
}  // namespace

struct EmbreeAccel::Impl {
  ErrorSink errors;
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::uint32_t first_instance = 0;  // geometry ID of instance 0 in `scene`
  // A group's shapes have IDs 0, 1, ... in the group's Embree scene (IDs
  // there cost Embree memory up to the largest): the scene's shape of
  // geometry k in instance i's group is group_shapes[instance_group[i]][k].
  std::vector<std::vector<std::uint32_t>> group_shapes;
  std::vector<std::uint32_t> instance_group;  // per instance; empty for a scene without instances
  BvhOptions options;
  std::span<const Material> materials;  // read while building only; empty: every shape opaque
  const Textures* textures = nullptr;   // for alpha textures
  // The alpha filters' user data, one per shape with alpha (a group's shape
  // once, whatever places it); Embree holds pointers to them.
  std::vector<std::unique_ptr<AlphaGeometry>> alpha_geometries;
  // The spheres' user data, one per sphere shape (a group's once).
  std::vector<std::unique_ptr<SphereGeometry>> sphere_geometries;
  ~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
  RTCScene new_scene() const {
    RTCScene s = rtcNewScene(device);
    // ROBUST: no arithmetic shortcuts that could let a ray slip through an
    // edge shared by two triangles (Embree's watertight triangle test and
    // conservative box tests); without it Embree is faster and 1e-7 to 1e-6
    // of rays slip through (bench/bench_watertight.cpp).
    int flags = RTC_SCENE_FLAG_NONE;
    if (options.intersection == Intersection::Robust) flags |= RTC_SCENE_FLAG_ROBUST;
    if (options.compact) flags |= RTC_SCENE_FLAG_COMPACT;
    rtcSetSceneFlags(s, static_cast<RTCSceneFlags>(flags));
    rtcSetSceneBuildQuality(s, RTC_BUILD_QUALITY_HIGH);
    return s;
  }
  // Attaches `shape` (the scene's shape `index`) to `target` with geometry
  // ID `id`.
  void attach(RTCScene target, const Shape& shape, std::uint32_t index, std::uint32_t id);
  // The instance ID Embree reports, as RayHit::instance.
  std::uint32_t instance_of(unsigned inst_id) const {
    return inst_id == RTC_INVALID_GEOMETRY_ID ? kNoInstance : inst_id - first_instance;
  }
  // The scene's shape index of a hit on geometry `geom_id`, in the top scene
  // or in the group an instance placed.
  std::uint32_t shape_of(unsigned geom_id, unsigned inst_id) const {
    if (inst_id == RTC_INVALID_GEOMETRY_ID || geom_id == RTC_INVALID_GEOMETRY_ID) return geom_id;
    return group_shapes[instance_group[inst_id - first_instance]][geom_id];
  }
};

EmbreeAccel::EmbreeAccel(const std::vector<Shape>& shapes, std::span<const ShapeGroup> groups,
                         std::span<const Instance> instances, BvhOptions options, std::span<const Material> materials,
                         const Textures* textures)
    : impl_(std::make_unique<Impl>()) {
  impl_->options = options;
  impl_->materials = materials;
  impl_->textures = textures;
  // Set before any shape is attached: the filters read it.
  impl_->first_instance = static_cast<std::uint32_t>(shapes.size());
  impl_->device = rtcNewDevice(nullptr);
  if (!impl_->device)
    throw SystemError(std::string("Embree: cannot create device: error ") +
                      std::to_string(static_cast<int>(rtcGetDeviceError(nullptr))));
  rtcSetDeviceErrorFunction(impl_->device, &ErrorSink::callback, &impl_->errors);

  impl_->scene = impl_->new_scene();
  for (std::uint32_t id = 0; id < shapes.size(); ++id)
    if (!shapes[id].in_group) impl_->attach(impl_->scene, shapes[id], id, id);

  // Each group's BVH is built once, its shapes numbered from 0 in it.
  struct GroupScenes {  // released however the constructor ends: the instances hold their own references
    std::vector<RTCScene> scenes;
    ~GroupScenes() {
      for (RTCScene gs : scenes) rtcReleaseScene(gs);
    }
  } group_scenes;
  for (const ShapeGroup& group : groups) {
    group_scenes.scenes.push_back(impl_->new_scene());
    for (std::uint32_t k = 0; k < group.shapes.size(); ++k)
      impl_->attach(group_scenes.scenes.back(), shapes[group.shapes[k]], group.shapes[k], k);
    impl_->group_shapes.push_back(group.shapes);
    rtcCommitScene(group_scenes.scenes.back());
    impl_->errors.check(("building the BVH of group " + group.name).c_str());
  }
  for (std::uint32_t i = 0; i < instances.size(); ++i) {
    const Instance& inst = instances[i];
    RTCGeometry geom = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(geom, group_scenes.scenes[inst.group]);
    impl_->instance_group.push_back(inst.group);
    // glm is column-major: column c, row r is to_world[c][r].
    float xfm[12];
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 3; ++r) xfm[3 * c + r] = inst.to_world[c][r];
    rtcSetGeometryTransform(geom, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, xfm);
    rtcCommitGeometry(geom);
    rtcAttachGeometryByID(impl_->scene, geom, impl_->first_instance + i);
    rtcReleaseGeometry(geom);
    impl_->errors.check(inst.description.c_str());
  }
  rtcCommitScene(impl_->scene);
  impl_->errors.check("building the BVH");
}

void EmbreeAccel::Impl::attach(RTCScene target, const Shape& shape, std::uint32_t index, std::uint32_t id) {
  const Material* material = materials.empty() ? nullptr : &materials[shape.material];
  const bool has_alpha = material && material->has_alpha();
  if (has_alpha && material->alpha_texture && !textures)
    throw InputError(shape.description + ": an alpha texture, but the scene's textures were not given");
  if (has_alpha && shape.kind != Shape::Kind::Triangles)
    throw InputError(shape.description + ": alpha on a sphere is not supported (a ray crosses it twice at one "
                     "primitive, so the two crossings cannot be decided apart); use a mesh");
  RTCGeometry geom = nullptr;
  if (shape.kind == Shape::Kind::Triangles) {
    geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    const auto& m = shape.mesh;
    static_assert(sizeof(vec3) == 3 * sizeof(float) && sizeof(glm::uvec3) == 3 * sizeof(unsigned));
    // Embree reads the mesh's own arrays where it may (no copy: 18 bytes a
    // triangle less). Its vertex loads are 16 bytes wide, so the last vertex
    // needs 4 readable bytes after it: room the positions keep when
    // CompiledScene reserved one more element; otherwise they are copied.
    if (m.positions.capacity() > m.positions.size()) {
      rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, m.positions.data(), 0, sizeof(vec3),
                                 m.positions.size());
    } else if (auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                                      sizeof(vec3), m.positions.size()))) {
      std::memcpy(v, m.positions.data(), m.positions.size() * sizeof(vec3));
    }
    rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, m.triangles.data(), 0,
                               sizeof(glm::uvec3), m.triangles.size());
  } else {
    geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
    sphere_geometries.push_back(std::make_unique<SphereGeometry>(SphereGeometry{shape.center, shape.radius}));
    rtcSetGeometryUserPrimitiveCount(geom, 1);
    rtcSetGeometryUserData(geom, sphere_geometries.back().get());
    rtcSetGeometryBoundsFunction(geom, &sphere_bounds, nullptr);
    rtcSetGeometryIntersectFunction(geom, &sphere_intersect);
    rtcSetGeometryOccludedFunction(geom, &sphere_occluded);
  }
  errors.check(shape.description.c_str());
  if (has_alpha) {
    // Only the geometries with alpha get filters: Embree calls none on the
    // others, which trace as fast as in a scene without alpha.
    alpha_geometries.push_back(std::make_unique<AlphaGeometry>(AlphaGeometry{
        material->alpha, material->alpha_cutoff, index, first_instance,
        material->alpha_texture ? &*material->alpha_texture : nullptr, textures, &shape.mesh}));
    rtcSetGeometryUserData(geom, alpha_geometries.back().get());
    rtcSetGeometryIntersectFilterFunction(geom, &alpha_filter);
    rtcSetGeometryOccludedFilterFunction(geom, &alpha_filter);
  }
  rtcCommitGeometry(geom);
  rtcAttachGeometryByID(target, geom, id);
  rtcReleaseGeometry(geom);
  errors.check(shape.description.c_str());
}

EmbreeAccel::~EmbreeAccel() = default;

namespace {

void fill(RTCRay& r, const Ray& ray) {
  r.org_x = ray.origin.x;
  r.org_y = ray.origin.y;
  r.org_z = ray.origin.z;
  r.dir_x = ray.dir.x;
  r.dir_y = ray.dir.y;
  r.dir_z = ray.dir.z;
  r.tnear = 0.0f;
  r.tfar = ray.tmax;
  r.time = 0.0f;
  r.mask = 0xffffffffu;
  r.id = ray.alpha_key;
  r.flags = 0;
}

// A closest-hit query for `ray`, with no hit yet.
void fill(RTCRayHit& rh, const Ray& ray) {
  fill(rh.ray, ray);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  // Embree leaves these alone on a miss; intersect_arrays copies them anyway.
  rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.u = rh.hit.v = 0.0f;
}

}  // namespace

bool EmbreeAccel::intersect(const Ray& ray, RayHit* hit) const {
  if (!embree_accepts(ray)) {
    g_rejected.fetch_add(1, std::memory_order_relaxed);
    hit->t = kNaN;
    return false;
  }
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh;
  fill(rh, ray);
  rtcIntersect1(impl_->scene, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  hit->t = rh.ray.tfar;
  hit->shape = impl_->shape_of(rh.hit.geomID, rh.hit.instID[0]);
  hit->prim = rh.hit.primID;
  hit->uv = vec2(rh.hit.u, rh.hit.v);
  hit->instance = impl_->instance_of(rh.hit.instID[0]);
  return true;
}

const char* ray_batch_mode_name(RayBatchMode mode) {
  switch (mode) {
    case RayBatchMode::Single: return "single";
    case RayBatchMode::Packet16: return "packet16";
    case RayBatchMode::Stream: return "stream";
  }
  return "?";
}

namespace {

constexpr int kPacket = 16;

RTCIntersectContext make_context(bool coherent) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
  return context;
}

// Lane k of a 16-wide packet (structure of arrays) from one ray.
template <typename Packet>
void fill_lane(Packet& r, int k, const Ray& ray) {
  r.org_x[k] = ray.origin.x;
  r.org_y[k] = ray.origin.y;
  r.org_z[k] = ray.origin.z;
  r.dir_x[k] = ray.dir.x;
  r.dir_y[k] = ray.dir.y;
  r.dir_z[k] = ray.dir.z;
  r.tnear[k] = 0.0f;
  r.tfar[k] = ray.tmax;
  r.time[k] = 0.0f;
  r.mask[k] = 0xffffffffu;
  r.id[k] = ray.alpha_key;
  r.flags[k] = 0;
}

// Lanes [n, 16) of a packet as well-formed rays that are inactive by both of
// Embree's conventions: masked off by the caller, and tnear > tfar. The valid
// mask alone does not do: a build of Embree without native 16-wide kernels
// (AVX2, no AVX-512) traces rtcIntersect16/rtcOccluded16 as a stream, which
// decides activity from the ray data and asserts that it is finite.
template <typename Packet>
void disable_lanes(Packet& r, std::size_t n) {
  for (auto k = n; k < static_cast<std::size_t>(16); ++k) {
    r.org_x[k] = r.org_y[k] = r.org_z[k] = 0.0f;
    r.dir_x[k] = r.dir_y[k] = 0.0f;
    r.dir_z[k] = 1.0f;
    r.tnear[k] = 1.0f;
    r.tfar[k] = 0.0f;
    r.time[k] = 0.0f;
    r.mask[k] = 0u;
    r.id[k] = 0;
    r.flags[k] = 0;
  }
}

// Lane masks for groups of up to 16 rays: -1 for a lane in use, 0 otherwise.
struct alignas(64) ValidMask {
  int lane[kPacket];
  explicit ValidMask(std::size_t n) {
    for (int k = 0; k < kPacket; ++k) lane[k] = static_cast<std::size_t>(k) < n ? -1 : 0;
  }
};

// Calls packet(b, m, valid) for rays [b, b + m) of n, 16 at a time (the
// last group may be shorter), valid being the lane mask Embree takes.
template <typename Packet>
void for_each_packet(std::size_t n, Packet&& packet) {
  for (std::size_t b = 0; b < n; b += kPacket) {
    const std::size_t m = std::min<std::size_t>(kPacket, n - b);
    const ValidMask valid(m);
    packet(b, m, valid.lane);
  }
}

// Ray i of `rays` in the one-ray form.
Ray ray_at(const RayArrays& r, std::size_t i) {
  return Ray{vec3(r.ox[i], r.oy[i], r.oz[i]), vec3(r.dx[i], r.dy[i], r.dz[i]), r.tmax[i],
             r.alpha_key ? r.alpha_key[i] : 0u};
}

// The number of rays Embree would refuse: a batch with any goes one ray at a
// time, the refused ones skipped (every mode gives the same answers).
std::size_t count_rejected(std::span<const Ray> rays) {
  std::size_t n = 0;
  for (const Ray& r : rays) n += embree_accepts(r) ? 0 : 1;
  return n;
}
std::size_t count_rejected(const RayArrays& r, std::size_t n) {
  std::uint32_t bad = 0;  // n < 2^32 (Embree's stream size is an unsigned)
  for (std::size_t i = 0; i < n; ++i)
    bad += embree_accepts(vec3(r.ox[i], r.oy[i], r.oz[i]), vec3(r.dx[i], r.dy[i], r.dz[i]), r.tmax[i]) ? 0u : 1u;
  return bad;
}

}  // namespace

std::uint64_t embree_rejected_rays() { return g_rejected.load(std::memory_order_relaxed); }

void EmbreeAccel::intersect_batch(std::span<const Ray> rays, std::span<RayHit> hits, std::span<std::uint8_t> found,
                                  RayBatchMode mode, bool coherent) const {
  RTCIntersectContext context = make_context(coherent);
  auto record = [&](std::size_t i, float tfar, unsigned geom, unsigned prim, float u, float v, unsigned inst) {
    found[i] = geom != RTC_INVALID_GEOMETRY_ID;
    if (found[i]) hits[i] = RayHit{tfar, impl_->shape_of(geom, inst), prim, vec2(u, v), impl_->instance_of(inst)};
  };
  if (const std::size_t bad = count_rejected(rays); bad > 0) {
    g_rejected.fetch_add(bad, std::memory_order_relaxed);
    mode = RayBatchMode::Single;
  }
  switch (mode) {
    case RayBatchMode::Single:
      for (std::size_t i = 0; i < rays.size(); ++i) {
        if (!embree_accepts(rays[i])) {
          found[i] = 0;
          hits[i].t = kNaN;
          continue;
        }
        RTCRayHit rh;
        fill(rh, rays[i]);
        rtcIntersect1(impl_->scene, &context, &rh);
        record(i, rh.ray.tfar, rh.hit.geomID, rh.hit.primID, rh.hit.u, rh.hit.v, rh.hit.instID[0]);
      }
      return;
    case RayBatchMode::Packet16:
      for_each_packet(rays.size(), [&](std::size_t b, std::size_t n, const int* valid) {
        RTCRayHit16 rh;
        for (std::size_t k = 0; k < n; ++k) {
          fill_lane(rh.ray, static_cast<int>(k), rays[b + k]);
          rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
          rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
        }
        disable_lanes(rh.ray, n);
        rtcIntersect16(valid, impl_->scene, &context, &rh);
        for (std::size_t k = 0; k < n; ++k)
          record(b + k, rh.ray.tfar[k], rh.hit.geomID[k], rh.hit.primID[k], rh.hit.u[k], rh.hit.v[k],
                 rh.hit.instID[0][k]);
      });
      return;
    case RayBatchMode::Stream: {
      thread_local std::vector<RTCRayHit> buffer;
      buffer.resize(rays.size());
      for (std::size_t i = 0; i < rays.size(); ++i) fill(buffer[i], rays[i]);
      rtcIntersect1M(impl_->scene, &context, buffer.data(), static_cast<unsigned>(buffer.size()), sizeof(RTCRayHit));
      for (std::size_t i = 0; i < rays.size(); ++i) {
        const RTCRayHit& rh = buffer[i];
        record(i, rh.ray.tfar, rh.hit.geomID, rh.hit.primID, rh.hit.u, rh.hit.v, rh.hit.instID[0]);
      }
      return;
    }
  }
}

// Debian's Embree 3.13 never returns from rtcOccluded16 with the coherent
// flag on a scene with instances (seen on AVX-512 cores; the test
// EmbreeAccel/EmbreeAccelModes.*/Instanced hangs without this): occlusion
// queries on such scenes are traced as incoherent, which gives the same
// answers.
namespace {
bool coherent_occlusion(bool coherent, bool has_instances) { return coherent && !has_instances; }
}  // namespace

void EmbreeAccel::occluded_batch(std::span<const Ray> rays, std::span<std::uint8_t> occluded, RayBatchMode mode,
                                 bool coherent) const {
  RTCIntersectContext context = make_context(coherent_occlusion(coherent, !impl_->instance_group.empty()));
  if (const std::size_t bad = count_rejected(rays); bad > 0) {
    g_rejected.fetch_add(bad, std::memory_order_relaxed);
    mode = RayBatchMode::Single;
  }
  switch (mode) {
    case RayBatchMode::Single:
      for (std::size_t i = 0; i < rays.size(); ++i) {
        if (!embree_accepts(rays[i])) {
          occluded[i] = 1;
          continue;
        }
        RTCRay r;
        fill(r, rays[i]);
        rtcOccluded1(impl_->scene, &context, &r);
        occluded[i] = r.tfar < 0.0f;
      }
      return;
    case RayBatchMode::Packet16:
      for_each_packet(rays.size(), [&](std::size_t b, std::size_t n, const int* valid) {
        RTCRay16 r;
        for (std::size_t k = 0; k < n; ++k) fill_lane(r, static_cast<int>(k), rays[b + k]);
        disable_lanes(r, n);
        rtcOccluded16(valid, impl_->scene, &context, &r);
        for (std::size_t k = 0; k < n; ++k) occluded[b + k] = r.tfar[k] < 0.0f;
      });
      return;
    case RayBatchMode::Stream: {
      thread_local std::vector<RTCRay> buffer;
      buffer.resize(rays.size());
      for (std::size_t i = 0; i < rays.size(); ++i) fill(buffer[i], rays[i]);
      rtcOccluded1M(impl_->scene, &context, buffer.data(), static_cast<unsigned>(buffer.size()), sizeof(RTCRay));
      for (std::size_t i = 0; i < rays.size(); ++i) occluded[i] = buffer[i].tfar < 0.0f;
      return;
    }
  }
}

namespace {

// Lanes [b, b + n) of `rays` as a 16-wide packet.
template <typename Packet>
void fill_packet(Packet& p, const RayArrays& rays, std::size_t b, std::size_t n) {
  const std::size_t bytes = n * sizeof(float);
  std::memcpy(p.org_x, rays.ox + b, bytes);
  std::memcpy(p.org_y, rays.oy + b, bytes);
  std::memcpy(p.org_z, rays.oz + b, bytes);
  std::memcpy(p.dir_x, rays.dx + b, bytes);
  std::memcpy(p.dir_y, rays.dy + b, bytes);
  std::memcpy(p.dir_z, rays.dz + b, bytes);
  std::memcpy(p.tfar, rays.tmax + b, bytes);
  for (std::size_t k = 0; k < n; ++k) {
    p.tnear[k] = 0.0f;
    p.time[k] = 0.0f;
    p.mask[k] = 0xffffffffu;
    p.id[k] = rays.alpha_key ? rays.alpha_key[b + k] : 0u;
    p.flags[k] = 0;
  }
  disable_lanes(p, n);
}

// The per-ray inputs of a pointer-SoA stream that the arrays do not hold:
// tnear 0, time 0, every mask bit, flags 0, id 0 unless the arrays hold
// alpha keys; and room for what Embree writes that the caller does not
// keep: an occlusion query's tfar, a hit's geometric normal, its instance
// where the caller keeps none.
struct StreamScratch {
  std::vector<float> zeros, tfar, ng;
  std::vector<unsigned> mask, zero_ids, inst;
  // This thread's scratch, with room for n rays.
  static StreamScratch& for_rays(std::size_t n) {
    thread_local StreamScratch s;
    if (s.zeros.size() < n) {
      s.zeros.assign(n, 0.0f), s.mask.assign(n, 0xffffffffu), s.zero_ids.assign(n, 0u);
      s.tfar.resize(n), s.ng.resize(n), s.inst.resize(n);
    }
    return s;
  }
  // Embree's pointer-SoA ray is not const, but it writes only tfar, which
  // `tfar` receives.
  RTCRayNp ray(const RayArrays& r, float* tfar_out) {
    return RTCRayNp{const_cast<float*>(r.ox), const_cast<float*>(r.oy), const_cast<float*>(r.oz), zeros.data(),
                    const_cast<float*>(r.dx), const_cast<float*>(r.dy), const_cast<float*>(r.dz), zeros.data(),
                    tfar_out, mask.data(),
                    r.alpha_key ? const_cast<unsigned*>(r.alpha_key) : zero_ids.data(), zero_ids.data()};
  }
};

}  // namespace

void EmbreeAccel::intersect_arrays(const RayArrays& rays_in, std::size_t n, const HitArrays& hits_in,
                                   RayBatchMode mode, bool coherent) const {
  RTCIntersectContext context = make_context(coherent);
  // Copies whose address Embree never sees, so that its opaque calls do not
  // force the array pointers to be reloaded for every ray.
  const RayArrays rays = rays_in;
  const HitArrays hits = hits_in;
  // Every field written, hit or miss: no branch on a coin flip per ray.
  auto record = [&](std::size_t i, float tfar, unsigned geom, unsigned prim, float u, float v, unsigned inst) {
    hits.found[i] = geom != RTC_INVALID_GEOMETRY_ID;
    hits.t[i] = tfar, hits.shape[i] = impl_->shape_of(geom, inst), hits.prim[i] = prim, hits.u[i] = u, hits.v[i] = v;
    if (hits.instance) hits.instance[i] = impl_->instance_of(inst);
  };
  if (const std::size_t bad = count_rejected(rays, n); bad > 0) {
    g_rejected.fetch_add(bad, std::memory_order_relaxed);
    mode = RayBatchMode::Single;
  }
  switch (mode) {
    case RayBatchMode::Single:
      for (std::size_t i = 0; i < n; ++i) {
        const Ray ray = ray_at(rays, i);
        if (!embree_accepts(ray)) {
          record(i, kNaN, RTC_INVALID_GEOMETRY_ID, RTC_INVALID_GEOMETRY_ID, 0.0f, 0.0f, RTC_INVALID_GEOMETRY_ID);
          continue;
        }
        RTCRayHit rh;
        fill(rh, ray);
        rtcIntersect1(impl_->scene, &context, &rh);
        record(i, rh.ray.tfar, rh.hit.geomID, rh.hit.primID, rh.hit.u, rh.hit.v, rh.hit.instID[0]);
      }
      return;
    case RayBatchMode::Packet16:
      for_each_packet(n, [&](std::size_t b, std::size_t m, const int* valid) {
        RTCRayHit16 rh;
        fill_packet(rh.ray, rays, b, m);
        for (std::size_t k = 0; k < m; ++k) {
          rh.hit.geomID[k] = rh.hit.instID[0][k] = rh.hit.primID[k] = RTC_INVALID_GEOMETRY_ID;
          rh.hit.u[k] = rh.hit.v[k] = 0.0f;  // copied on a miss too (record)
        }
        rtcIntersect16(valid, impl_->scene, &context, &rh);
        for (std::size_t k = 0; k < m; ++k)
          record(b + k, rh.ray.tfar[k], rh.hit.geomID[k], rh.hit.primID[k], rh.hit.u[k], rh.hit.v[k],
                 rh.hit.instID[0][k]);
      });
      return;
    case RayBatchMode::Stream: {
      // Embree writes the hits straight into the caller's arrays: tfar (the
      // distance; tmax where it finds nothing), u, v, primID, geomID (the
      // shape, renumbered below for instances) and instID; on a miss only
      // tfar is read back, so geomID and instID start as "none".
      StreamScratch& s = StreamScratch::for_rays(n);
      std::uint32_t* const inst = hits.instance ? hits.instance : s.inst.data();
      std::memcpy(hits.t, rays.tmax, n * sizeof(float));
      std::fill_n(hits.shape, n, RTC_INVALID_GEOMETRY_ID);
      std::fill_n(inst, n, RTC_INVALID_GEOMETRY_ID);
      const RTCRayHitNp rh{s.ray(rays, hits.t), RTCHitNp{s.ng.data(), s.ng.data(), s.ng.data(), hits.u, hits.v,
                                                         hits.prim, hits.shape, {inst}}};
      rtcIntersectNp(impl_->scene, &context, &rh, static_cast<unsigned>(n));
      for (std::size_t i = 0; i < n; ++i) hits.found[i] = hits.shape[i] != RTC_INVALID_GEOMETRY_ID;
      // kNoInstance is RTC_INVALID_GEOMETRY_ID: a scene without instances
      // needs no renumbering.
      if (!impl_->instance_group.empty())
        for (std::size_t i = 0; i < n; ++i) {
          hits.shape[i] = impl_->shape_of(hits.shape[i], inst[i]);
          inst[i] = impl_->instance_of(inst[i]);
        }
      return;
    }
  }
}

void EmbreeAccel::occluded_arrays(const RayArrays& rays, std::size_t n, std::uint8_t* occluded, RayBatchMode mode,
                                  bool coherent) const {
  RTCIntersectContext context = make_context(coherent_occlusion(coherent, !impl_->instance_group.empty()));
  if (const std::size_t bad = count_rejected(rays, n); bad > 0) {
    g_rejected.fetch_add(bad, std::memory_order_relaxed);
    mode = RayBatchMode::Single;
  }
  switch (mode) {
    case RayBatchMode::Single:
      for (std::size_t i = 0; i < n; ++i) {
        const Ray ray = ray_at(rays, i);
        if (!embree_accepts(ray)) {
          occluded[i] = 1;
          continue;
        }
        RTCRay r;
        fill(r, ray);
        rtcOccluded1(impl_->scene, &context, &r);
        occluded[i] = r.tfar < 0.0f;
      }
      return;
    case RayBatchMode::Packet16:
      for_each_packet(n, [&](std::size_t b, std::size_t m, const int* valid) {
        RTCRay16 r;
        fill_packet(r, rays, b, m);
        rtcOccluded16(valid, impl_->scene, &context, &r);
        for (std::size_t k = 0; k < m; ++k) occluded[b + k] = r.tfar[k] < 0.0f;
      });
      return;
    case RayBatchMode::Stream: {
      StreamScratch& s = StreamScratch::for_rays(n);
      std::memcpy(s.tfar.data(), rays.tmax, n * sizeof(float));
      const RTCRayNp r = s.ray(rays, s.tfar.data());
      rtcOccludedNp(impl_->scene, &context, &r, static_cast<unsigned>(n));
      for (std::size_t i = 0; i < n; ++i) occluded[i] = s.tfar[i] < 0.0f;
      return;
    }
  }
}

bool EmbreeAccel::occluded(const Ray& ray) const {
  if (!embree_accepts(ray)) {
    g_rejected.fetch_add(1, std::memory_order_relaxed);
    return true;
  }
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay r;
  fill(r, ray);
  rtcOccluded1(impl_->scene, &context, &r);
  return r.tfar < 0.0f;  // Embree sets tfar = -inf on a hit
}

}  // namespace pathlab
