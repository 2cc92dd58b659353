// Options shared by every subcommand that renders or replays a scene: the
// scene file and the overrides of its render settings.
#pragma once

#include "core/scene.h"
#include "debugtools/tracers.h"

#include <CLI/CLI.hpp>

#include <memory>
#include <optional>
#include <string>

namespace pathlab {
class Tracer;
class CompiledScene;
}

namespace pathlab::cli {

struct SceneOptions {
  std::string scene_file;  // empty: the built-in Cornell box
  std::string tracer = "reference";
  std::optional<std::string> strategy;
  std::optional<int> spp, max_depth, rr_depth;
  std::optional<std::string> seed;  // parsed by load(): CLI11 would wrap "-1" around
  std::optional<std::string> resolution;  // "WxH"
  std::optional<std::string> bsdf_sampling;  // vndf | cospow
  std::optional<std::string> light_sampling;  // area | solid_angle
  std::optional<std::string> light_sampler;   // power | bvh
  std::optional<std::string> bvh;            // fast | compact
  std::optional<std::string> intersection;   // robust | fast
  std::optional<float> clamp, min_pdf;       // firefly controls (biased; 0 = off)
  bool general_shading = false;              // force the general shading path
  std::optional<std::string> texture_filter;  // cone | point
  std::optional<std::string> sampler;         // independent | zsobol
  std::optional<float> texture_cache_mb;
  std::optional<std::string> simd;  // auto | avx512 | avx2 | sse4 | scalar (not a scene setting: same bits)

  // Registers the options on `cmd`; `with_spp` for commands that render,
  // `allow_both` for trace-pixel's --tracer both.
  void add_to(CLI::App& cmd, bool with_spp, bool allow_both = false);
  // Loads the scene and applies the overrides; selects the SIMD target
  // (--simd, else $PATHLAB_SIMD, else the best this processor runs). Throws
  // InputError.
  Scene load() const;
  // "pathlab trace-pixel <scene> --pixel x,y --sample s ..." for one sample
  // of a render with `scene`'s final settings.
  std::string trace_pixel_command(const Scene& scene, std::uint32_t x, std::uint32_t y, std::uint32_t sample) const;
};

// Parses --resolution "WxH" into `film`. Throws InputError.
void apply_resolution(const std::string& text, FilmDesc& film);

// The tracers by name live in debugtools/tracers.h (shared with pathlab-debug).
using pathlab::make_tracer;

}  // namespace pathlab::cli
