#include "apps/cli/scene_options.h"

#include "apps/cli/validators.h"

#include "core/compiled_scene.h"
#include "core/error.h"
#include "core/scene_loader.h"
#include "core/simd/simd.h"

#include <charconv>
#include <sstream>

namespace pathlab::cli {

void SceneOptions::add_to(CLI::App& cmd, bool with_spp, bool allow_both) {
  const auto names = strategy_names();
  const std::vector<std::string> strategies(names.begin(), names.end());
  cmd.add_option("scene", scene_file, "Scene file (JSON); omit for the built-in Cornell box");
  if (allow_both)
    cmd.add_option("--tracer", tracer, "Tracer: reference, wavefront, or both (side by side, marking where they part)")
        ->check(CLI::IsMember({"reference", "wavefront", "both"}));
  else
    cmd.add_option("--tracer", tracer, "Tracer: reference or wavefront")->check(CLI::IsMember({"reference", "wavefront"}));
  cmd.add_option("--strategy", strategy, "Sampling strategy: cosine, bsdf, light, light+bsdf, mis")
      ->check(CLI::IsMember(strategies));
  if (with_spp) cmd.add_option("--spp", spp, "Samples per pixel")->check(CLI::Range(1, 1 << 24));
  cmd.add_option("--max-depth", max_depth, "Maximum bounces; -1 = until Russian roulette")
      ->check(CLI::Range(-1, kMaxVerticesUncapped));
  cmd.add_option("--rr-depth", rr_depth, "Bounces before Russian roulette starts")
      ->check(CLI::Range(0, kMaxVerticesUncapped));
  cmd.add_option("--seed", seed, "Random seed");
  cmd.add_option("--sampler", sampler,
                 "Random numbers: independent (a hash per number) or zsobol (Owen-scrambled Sobol' points, pixels in "
                 "Morton order; depends on --spp rounded up to a power of two)")
      ->check(CLI::IsMember({"independent", "zsobol"}));
  cmd.add_option("--resolution", resolution, "Image size WxH, e.g. 640x480");
  cmd.add_option("--bsdf-sampling", bsdf_sampling, "Glossy lobe sampling: vndf (exact GGX visible normals) or cospow")
      ->check(CLI::IsMember({"vndf", "cospow"}));
  cmd.add_option("--light-sampling", light_sampling,
                 "Area-light points for next-event estimation: area (uniform by area) or solid_angle (uniform in "
                 "the solid angle a triangle or sphere subtends; same expectation, less variance near lights)")
      ->check(CLI::IsMember({"area", "solid_angle"}));
  cmd.add_option("--light-sampler", light_sampler,
                 "How next-event estimation picks the area light: power (in proportion to power) or bvh (down a "
                 "light BVH, by each light's importance for the shading point; for many lights)")
      ->check(CLI::IsMember({"power", "bvh"}));
  cmd.add_option("--clamp", clamp, "Clamp each sample's radiance to this maximum component (biased; 0 = off)")
      ->check(number_range(0.0, 3.4e38));
  cmd.add_option("--min-pdf", min_pdf, "Discard BSDF samples with a smaller density (biased; 0 = off)")
      ->check(number_range(0.0, 3.4e38));
  cmd.add_option("--bvh", bvh, "Embree's BVH: fast, or compact (less memory, slower; the same image)")
      ->check(CLI::IsMember({"fast", "compact"}));
  cmd.add_option("--intersection", intersection,
                 "How Embree intersects triangles: robust (watertight: no ray slips between triangles sharing an "
                 "edge) or fast (faster, e.g. 1.3x on small scenes; about 1e-7 to 1e-6 of rays slip through edges: "
                 "docs/scene-format.md)")
      ->check(CLI::IsMember({"robust", "fast"}));
  cmd.add_option("--texture-filter", texture_filter,
                 "Texture lookups: cone (filtered over the ray cone's footprint) or point (the finest level)")
      ->check(CLI::IsMember({"cone", "point"}));
  cmd.add_option("--texture-cache-mb", texture_cache_mb, "OpenImageIO's texture tile cache, in MB")
      ->check(number_range(1.0, 1.0e6));
  cmd.add_option("--simd", simd,
                 "SIMD instruction set of the vectorised code: auto (the best this processor runs), avx512, avx2, "
                 "sse4, or scalar (the same source at width 1: the wavefront's scalar stages); the same image at "
                 "every one (default: $PATHLAB_SIMD, else auto)")
      ->check(CLI::IsMember({"auto", "avx512", "avx2", "sse4", "scalar"}));
  cmd.add_flag("--general-shading", general_shading,
               "Shade every material through the general Disney-capable code instead of code specialised to the "
               "scene's lobes (same image, slower)");
}

Scene SceneOptions::load() const {
  select_simd_target(simd ? parse_simd_target(*simd) : std::nullopt, "--simd");
  Scene scene = scene_file.empty() ? builtin_cornell_box() : load_scene(scene_file);
  RenderSettings& r = scene.render;
  if (strategy) r.strategy = *parse_strategy(*strategy);
  if (spp) r.spp = *spp;
  if (max_depth) r.max_depth = *max_depth;
  if (rr_depth) r.rr_depth = *rr_depth;
  if (bsdf_sampling) r.bsdf_sampling = *parse_bsdf_sampling(*bsdf_sampling);
  if (light_sampling) r.light_sampling = *parse_light_sampling(*light_sampling);
  if (light_sampler) r.light_sampler = *parse_light_sampler(*light_sampler);
  if (clamp) r.clamp = *clamp;
  if (min_pdf) r.min_pdf = *min_pdf;
  if (general_shading) r.force_general_shading = true;
  if (bvh) r.compact_bvh = *bvh == "compact";
  if (intersection) r.intersection = *parse_intersection(*intersection);
  if (texture_filter) r.texture_filter = *parse_texture_filter(*texture_filter);
  if (sampler) r.sampler = *parse_sampler(*sampler);
  if (texture_cache_mb) r.texture_cache_mb = *texture_cache_mb;
  if (seed) {
    std::uint64_t value = 0;
    const char* end = seed->data() + seed->size();
    const auto [ptr, ec] = std::from_chars(seed->data(), end, value);
    if (ec != std::errc() || ptr != end)
      throw InputError("--seed " + *seed + ": expected an integer in [0, 18446744073709551615]");
    r.seed = value;
  }
  if (resolution) apply_resolution(*resolution, scene.film);
  return scene;
}

void apply_resolution(const std::string& text, FilmDesc& film) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  std::istringstream in(text);
  if (!(in >> w >> x >> h) || (x != 'x' && x != 'X') || (in >> extra) || w < 1 || h < 1 || w > 65536 || h > 65536)
    throw InputError("--resolution " + text + ": expected WIDTHxHEIGHT with each in [1, 65536], e.g. 640x480");
  film.width = w;
  film.height = h;
}

std::string SceneOptions::trace_pixel_command(const Scene& scene, std::uint32_t x, std::uint32_t y,
                                              std::uint32_t sample) const {
  std::ostringstream cmd;
  cmd << "pathlab trace-pixel";
  if (!scene_file.empty()) cmd << " " << scene_file;
  cmd << " --pixel " << x << "," << y << " --sample " << sample << " --seed " << scene.render.seed << " --tracer "
      << tracer << " --strategy " << strategy_name(scene.render.strategy) << " --max-depth " << scene.render.max_depth
      << " --rr-depth " << scene.render.rr_depth << " --resolution " << scene.film.width << "x" << scene.film.height;
  if (scene.render.bsdf_sampling != BsdfSampling::Vndf) cmd << " --bsdf-sampling " << bsdf_sampling_name(scene.render.bsdf_sampling);
  if (scene.render.light_sampling != LightSampling::Area)
    cmd << " --light-sampling " << light_sampling_name(scene.render.light_sampling);
  if (scene.render.light_sampler != LightSamplerKind::Power)
    cmd << " --light-sampler " << light_sampler_name(scene.render.light_sampler);
  if (scene.render.min_pdf > 0.0f) cmd << " --min-pdf " << scene.render.min_pdf;
  if (scene.render.force_general_shading) cmd << " --general-shading";
  if (scene.render.texture_filter != TextureFilter::Cone) cmd << " --texture-filter " << texture_filter_name(scene.render.texture_filter);
  if (scene.render.intersection != Intersection::Robust)
    cmd << " --intersection " << intersection_name(scene.render.intersection);
  // zsobol's numbers depend on spp too.
  if (scene.render.sampler != SamplerKind::Independent)
    cmd << " --sampler " << sampler_name(scene.render.sampler) << " --spp " << scene.render.spp;
  return cmd.str();
}

}  // namespace pathlab::cli
