// "Model only what a scene requires", measured: the built-in Cornell box
// (Lambert materials only) rendered with shading specialised to its lobes
// (the Lambert-only path, no Disney code) and with the general path forced
// (every material through the full Disney-capable closure, which gives the
// same image), alternately in the same run, single-threaded. The counter
// general_over_specialised is the ratio of their times.
//
//   build-mat/bench/pathlab_bench_materials [--benchmark_min_time=2]
#include "core/compiled_scene.h"
#include "core/parallel.h"
#include "core/render.h"
#include "core/scene_loader.h"
#include "reference/reference_tracer.h"

#include <benchmark/benchmark.h>

#include <chrono>

namespace pathlab {
namespace {

struct Setup {
  explicit Setup(bool general) {
    Scene scene = builtin_cornell_box();
    scene.film.width = scene.film.height = 64;
    scene.render.spp = 4;
    scene.render.force_general_shading = general;
    settings = scene.render;
    compiled = std::make_unique<CompiledScene>(std::move(scene));
    tracer = std::make_unique<ReferenceTracer>(*compiled, settings);
  }
  double render_seconds() const {
    Film film(compiled->scene().film.width, compiled->scene().film.height, compiled->scene().film.filter,
              FilmMoments::Mean);
    return render(*tracer, film).seconds;
  }
  RenderSettings settings;
  std::unique_ptr<CompiledScene> compiled;
  std::unique_ptr<ReferenceTracer> tracer;
};

void BM_CornellLambertSpecialisedVsGeneral(benchmark::State& state) {
  const ThreadLimit one(1);
  const Setup specialised(false), general(true);
  double ts = 0.0, tg = 0.0;
  for (auto _ : state) {
    ts += specialised.render_seconds();
    tg += general.render_seconds();
  }
  state.counters["specialised_ms"] = 1e3 * ts / static_cast<double>(state.iterations());
  state.counters["general_ms"] = 1e3 * tg / static_cast<double>(state.iterations());
  state.counters["general_over_specialised"] = tg / ts;
  state.SetLabel(std::string("paths: ") + shading_path_name(specialised.compiled->scene().materials[0].shading.path) +
                 " vs " + shading_path_name(general.compiled->scene().materials[0].shading.path));
}
BENCHMARK(BM_CornellLambertSpecialisedVsGeneral)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace pathlab

BENCHMARK_MAIN();
