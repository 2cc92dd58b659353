#include "bench/ray_capture.h"

#include "core/parallel.h"
#include "reference/reference_tracer.h"

#include <algorithm>
#include <atomic>

namespace pathlab::bench {
namespace {

// Keeps the rays of one path as the tracer cast them: camera rays, the
// shadow rays (offset off the surface and short of the light, as traced) and
// the continuation rays.
class RayRecorder final : public PathObserver {
 public:
  struct Tagged {
    int vertex;
    Ray ray;
  };
  std::vector<Tagged> camera, bounce, shadow;

  void on_camera(const CameraEvent& e) override { camera.push_back({0, Ray{e.origin, e.dir, kInfinity}}); }
  // A rejected light sample (no sample, the emitter's back, edge-on) casts
  // no shadow ray: its event's ray is empty, and the tracers count no ray.
  void on_light(const LightEvent& e) override {
    if (e.rejected == LightRejection::None) shadow.push_back({e.vertex, e.ray});
  }
  void on_scatter(const ScatterEvent& e) override {
    if (!is_black(e.throughput)) bounce.push_back({e.vertex, e.next});
  }
};

}  // namespace

const char* ray_kind_name(RayKind kind) {
  switch (kind) {
    case RayKind::Camera: return "camera";
    case RayKind::Bounce: return "bounce";
    case RayKind::Shadow: return "shadow";
  }
  return "?";
}

std::string raw_name(RayKind kind, RayBatchMode mode) {
  return std::string("Raw/") + ray_kind_name(kind) + "/" + ray_batch_mode_name(mode);
}

void RayList::push_back(const Ray& r) {
  ox.push_back(r.origin.x), oy.push_back(r.origin.y), oz.push_back(r.origin.z);
  dx.push_back(r.dir.x), dy.push_back(r.dir.y), dz.push_back(r.dir.z);
  tmax.push_back(r.tmax);
}

RayArrays RayList::from(std::size_t first) const {
  return RayArrays{ox.data() + first, oy.data() + first, oz.data() + first, dx.data() + first,
                   dy.data() + first, dz.data() + first, tmax.data() + first};
}

CapturedRays capture_rays(const CompiledScene& scene, const RenderSettings& settings) {
  const ReferenceTracer tracer(scene, settings);
  const int width = scene.scene().film.width, height = scene.scene().film.height;
  std::vector<RayRecorder> rows(static_cast<std::size_t>(height));
  parallel_for(0, rows.size(), 1, [&](std::size_t y0, std::size_t y1) {
    for (std::size_t y = y0; y < y1; ++y)
      for (int x = 0; x < width; ++x)
        tracer.trace_sample(static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y), 0, &rows[y]);
  });
  auto gather = [&](std::vector<RayRecorder::Tagged> RayRecorder::*list) {
    std::vector<RayRecorder::Tagged> all;
    for (RayRecorder& row : rows) all.insert(all.end(), (row.*list).begin(), (row.*list).end());
    std::stable_sort(all.begin(), all.end(), [](const auto& a, const auto& b) { return a.vertex < b.vertex; });
    RayList rays;
    for (const auto& t : all) rays.push_back(t.ray);
    return rays;
  };
  CapturedRays c;
  c.camera = gather(&RayRecorder::camera);
  c.bounce = gather(&RayRecorder::bounce);
  c.shadow = gather(&RayRecorder::shadow);
  c.samples = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  return c;
}

std::size_t cast_batch(const CompiledScene& scene, const RayList& rays, std::size_t first, std::size_t n,
                       RayKind kind, RayBatchMode mode, HitBuffers& hits) {
  const HitArrays out = hits.arrays();
  if (kind == RayKind::Shadow)
    scene.occluded_arrays(rays.from(first), n, out.found, mode);
  else
    scene.intersect_arrays(rays.from(first), n, out, mode, kind == RayKind::Camera);
  std::size_t found = 0;
  for (std::size_t i = 0; i < n; ++i) found += out.found[i];
  return found;
}

std::size_t cast(const CompiledScene& scene, const RayList& rays, RayKind kind, RayBatchMode mode) {
  std::atomic<std::size_t> hits{0};
  parallel_for(0, rays.size(), kCastChunk, [&](std::size_t b, std::size_t e) {
    thread_local HitBuffers buffers(kCastChunk);
    hits += cast_batch(scene, rays, b, e - b, kind, mode, buffers);  // e - b <= kCastChunk
  });
  return hits;
}

}  // namespace pathlab::bench
