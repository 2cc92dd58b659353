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
  void on_light(const LightEvent& e) override { shadow.push_back({e.vertex, e.ray}); }
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
    std::vector<Ray> rays;
    rays.reserve(all.size());
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

std::size_t cast_batch(const CompiledScene& scene, std::span<const Ray> rays, RayKind kind, RayBatchMode mode,
                       std::span<RayHit> hits, std::span<std::uint8_t> found) {
  if (kind == RayKind::Shadow)
    scene.occluded_batch(rays, found.first(rays.size()), mode);
  else
    scene.intersect_batch(rays, hits.first(rays.size()), found.first(rays.size()), mode, kind == RayKind::Camera);
  std::size_t n = 0;
  for (std::uint8_t f : found.first(rays.size())) n += f;
  return n;
}

std::size_t cast(const CompiledScene& scene, const std::vector<Ray>& rays, RayKind kind, RayBatchMode mode) {
  std::atomic<std::size_t> hits{0};
  parallel_for(0, rays.size(), 256, [&](std::size_t b, std::size_t e) {
    thread_local std::vector<RayHit> hit;
    thread_local std::vector<std::uint8_t> found;
    hit.resize(e - b), found.resize(e - b);
    hits += cast_batch(scene, std::span<const Ray>(rays.data() + b, e - b), kind, mode, hit, found);
  });
  return hits;
}

}  // namespace pathlab::bench
