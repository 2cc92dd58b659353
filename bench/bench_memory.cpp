// What a scene costs to load and build, and what it keeps in memory:
//
//   pathlab_bench_memory [--bvh fast|compact] SCENE [SCENE...]
//
// For each scene, in a process of its own (so that one scene's freed pages
// do not hide the next one's): the load time (parsing, meshes) and the build
// time (CompiledScene: Embree's BVHs, the triangle table, the light
// sampler), the resident memory the compiled scene keeps and the peak on the
// way, each per unique triangle (stored once) and per instanced triangle
// (as many as the renders see), and the processor, for the record.
// Memory is read from /proc/self/status (VmRSS, VmHWM, after malloc_trim
// for what is kept), so it includes everything the process holds: Embree,
// the meshes, the scene, the allocator's own overhead.
#include "bench/processor.h"
#include "core/compiled_scene.h"
#include "core/scene_loader.h"

#include <malloc.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

namespace pathlab {
namespace {

// A field of /proc/self/status in bytes ("VmRSS", "VmHWM").
double status_bytes(const std::string& field) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(field + ":", 0) == 0) return std::strtod(line.c_str() + field.size() + 1, nullptr) * 1024.0;
  return 0.0;
}

int measure(const char* file, const char* bvh) {
  using Clock = std::chrono::steady_clock;
  const double rss0 = status_bytes("VmRSS");
  const auto t0 = Clock::now();
  Scene scene = load_scene(file);
  if (bvh != nullptr) scene.render.compact_bvh = std::string(bvh) == "compact";
  const auto t1 = Clock::now();
  std::size_t unique = 0, instanced = 0;
  for (const Shape& s : scene.shapes)
    if (!s.in_group) unique += s.mesh.triangles.size(), instanced += s.mesh.triangles.size();
  for (const ShapeGroup& g : scene.groups)
    for (const std::uint32_t s : g.shapes) unique += scene.shapes[s].mesh.triangles.size();
  for (const Instance& inst : scene.instances)
    for (const std::uint32_t s : scene.groups[inst.group].shapes) instanced += scene.shapes[s].mesh.triangles.size();
  const CompiledScene compiled(std::move(scene));
  const auto t2 = Clock::now();
  const double peak = status_bytes("VmHWM") - rss0;
  malloc_trim(0);  // what was freed on the way goes back to the system: not kept
  const double kept = status_bytes("VmRSS") - rss0;
  const auto seconds = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); };
  std::printf("%s (bvh %s)\n  %zu unique triangles, %zu instanced (%zu instances)\n", file, compiled.scene().render.compact_bvh ? "compact" : "fast", unique, instanced,
              compiled.scene().instances.size());
  std::printf("  load %.2f s, build %.2f s\n", seconds(t0, t1), seconds(t1, t2));
  std::printf("  kept %.1f MiB: %.1f B per unique triangle, %.3f B per instanced triangle\n", kept / 1048576.0,
              kept / static_cast<double>(unique), kept / static_cast<double>(instanced));
  std::printf("  peak %.1f MiB: %.1f B per unique triangle\n", peak / 1048576.0, peak / static_cast<double>(unique));
  return 0;
}

}  // namespace
}  // namespace pathlab

int main(int argc, char** argv) {
  int first = 1;
  const char* bvh = nullptr;
  if (argc > 2 && std::string(argv[1]) == "--bvh") bvh = argv[2], first = 3;
  if (argc <= first) {
    std::fprintf(stderr, "usage: pathlab_bench_memory [--bvh fast|compact] SCENE [SCENE...]\n");
    return 2;
  }
  std::printf("processor: %s\n", pathlab::bench::processor().c_str());
  int status = 0;
  for (int i = first; i < argc; ++i) {
    std::fflush(stdout);
    const pid_t child = fork();
    if (child == 0) {
      try {
        return pathlab::measure(argv[i], bvh);
      } catch (const std::exception& e) {
        std::fprintf(stderr, "pathlab_bench_memory: %s\n", e.what());
        return 2;
      }
    }
    int code = 0;
    waitpid(child, &code, 0);
    if (!WIFEXITED(code) || WEXITSTATUS(code) != 0) status = 1;
  }
  return status;
}
