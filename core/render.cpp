#include "core/render.h"

#include "core/texture.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <new>

namespace pathlab {
namespace {

// pbrt-style firefly clamp: scale a finite sample down so that its largest
// component is `limit`, keeping its colour. Biased: off unless asked for.
// Samples outside the film's range pass through untouched (the film counts
// and locates them).
void clamp_samples(std::span<FilmSample> out, float limit, RenderStats& stats) {
  for (FilmSample& s : out) {
    if (!in_film_range(s.L)) continue;
    const double before = average(s.L);
    stats.energy_total.add(before);
    const Spectrum clamped = clamp_radiance(s.L, limit);
    if (clamped != s.L) {
      s.L = clamped;
      ++stats.clamped_samples;
      stats.energy_clamped.add(before - average(s.L));
    }
  }
}

std::string float_text(float v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", static_cast<double>(v));
  return text;
}

}  // namespace

Spectrum clamp_radiance(const Spectrum& L, float limit) {
  if (!(limit > 0.0f) || !in_film_range(L)) return L;
  const float m = max_component(L);
  return m > limit ? L * (limit / m) : L;
}

std::vector<std::pair<std::string, std::string>> sample_settings(const RenderSettings& r) {
  std::vector<std::pair<std::string, std::string>> out{
      {"strategy", strategy_name(r.strategy)},
      {"seed", std::to_string(r.seed)},
      {"sampler", sampler_name(r.sampler)},
      {"max_depth", std::to_string(r.max_depth)},
      {"rr_depth", std::to_string(r.rr_depth)},
      {"bsdf_sampling", bsdf_sampling_name(r.bsdf_sampling)},
      {"light_sampling", light_sampling_name(r.light_sampling)},
      {"light_sampler", light_sampler_name(r.light_sampler)},
      {"clamp", float_text(r.clamp)},
      {"min_pdf", float_text(r.min_pdf)},
      {"general_shading", r.force_general_shading ? "on" : "off"},
      {"texture_filter", texture_filter_name(r.texture_filter)},
      {"intersection", intersection_name(r.intersection)},
      {"bvh", r.compact_bvh ? "compact" : "fast"},
  };
  // zsobol's numbers depend on spp rounded up to a power of two (core/rng.h).
  if (r.sampler == SamplerKind::ZSobol)
    out.emplace_back("zsobol_spp",
                     std::to_string(1ull << SamplerSetup::log2_spp_of(static_cast<std::uint32_t>(std::max(r.spp, 1)))));
  return out;
}

const char* git_revision() { return PATHLAB_GIT_COMMIT; }

SampleBuffer::SampleBuffer(std::size_t size) : size_(size) {
  if (size > static_cast<std::size_t>(-1) / sizeof(FilmSample)) throw std::bad_array_new_length();
  // FilmSample is an aggregate, so malloc'ed storage holds FilmSamples for
  // the tracer to write into (implicit object creation, C++20).
  data_.reset(static_cast<FilmSample*>(std::malloc(std::max<std::size_t>(size, 1) * sizeof(FilmSample))));
  if (!data_) throw std::bad_alloc();
}

void SampleBuffer::Free::operator()(FilmSample* p) const noexcept { std::free(p); }

std::uint32_t batch_size(int width, int height, int spp) {
  const std::uint64_t pixels = static_cast<std::uint64_t>(width) * height;
  const std::uint64_t per_batch = std::max<std::uint64_t>(1, (std::uint64_t{1} << 18) / std::max<std::uint64_t>(pixels, 1));
  return static_cast<std::uint32_t>(std::min<std::uint64_t>(per_batch, static_cast<std::uint64_t>(std::max(spp, 1))));
}

RenderStats render(const Tracer& tracer, Film& film, const ProgressFn& progress) {
  return render_samples(tracer, film, 0, static_cast<std::uint32_t>(std::max(tracer.settings().spp, 0)), progress);
}

RenderStats render_samples(const Tracer& tracer, Film& film, std::uint32_t first, std::uint32_t last,
                           const ProgressFn& progress, const BatchDoneFn& batch_done) {
  const auto start = std::chrono::steady_clock::now();
  RenderStats stats;
  if (last > first) {
    const std::uint32_t batch = batch_size(film.width(), film.height(), static_cast<int>(last - first));
    const std::size_t pixels = static_cast<std::size_t>(film.width()) * film.height();
    SampleBuffer samples(pixels * batch);
    const float clamp = tracer.settings().clamp;
    for (std::uint32_t begin = first; begin < last; begin += batch) {
      const std::uint32_t count = std::min(batch, last - begin);
      const std::span<FilmSample> out = samples.first(pixels * count);
      tracer.render_batch(begin, count, out);
      if (clamp > 0.0f) clamp_samples(out, clamp, stats);
      const std::uint64_t rays_before = film.rays_cast();
      film.add_batch(begin, count, out);
      stats.rays += film.rays_cast() - rays_before;
      stats.samples += out.size();
      if (progress) progress(static_cast<double>(begin + count - first) / (last - first));
      if (batch_done) {
        stats.bad_samples = film.bad_sample_count();
        stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (!batch_done(begin + count, stats)) break;
      }
    }
  }
  stats.bad_samples = film.bad_sample_count();
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

double estimated_relmse(const Film& film) {
  double sum = 0.0;
  for (int y = 0; y < film.height(); ++y)
    for (int x = 0; x < film.width(); ++x) {
      const Spectrum m = film.mean(x, y), v = film.variance_of_mean(x, y);
      for (int c = 0; c < 3; ++c) sum += static_cast<double>(v[c]) / ((m[c] + 0.01) * (m[c] + 0.01));
    }
  return sum / (3.0 * film.width() * film.height());
}

UntilResult render_until(const Tracer& tracer, Film& film, const StopRule& rule, const ProgressFn& progress,
                         std::uint32_t start_spp, const BatchDoneFn& batch_done) {
  const auto start = std::chrono::steady_clock::now();
  const auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  const std::uint32_t max_spp = static_cast<std::uint32_t>(std::max(rule.max_spp, 1));
  const std::uint32_t pass = rule.pass_spp > 0 ? rule.pass_spp : batch_size(film.width(), film.height(), rule.max_spp);
  UntilResult r;
  r.spp = start_spp;
  // A resumed render decides as the uninterrupted one would have at this pass.
  if (start_spp > 0 && rule.target_relmse > 0.0) r.estimated_relmse = estimated_relmse(film);
  while (r.spp < max_spp) {
    if (r.passes > 0 || start_spp > 0) {
      const double now = elapsed();
      if (r.passes > 0 && rule.time_budget_seconds > 0.0 && now + now / r.passes > rule.time_budget_seconds) break;
      if (rule.target_relmse > 0.0 && r.estimated_relmse < rule.target_relmse) break;
    }
    // On the grid of whole passes from 0, whatever spp a resume starts at.
    const std::uint32_t last = std::min(max_spp, (r.spp / pass + 1) * pass);
    const RenderStats base = r.stats;
    bool go_on = true;
    const auto done = [&](std::uint32_t end, const RenderStats& so_far) {
      RenderStats all = base;
      all += so_far;
      all.seconds = elapsed();
      return go_on = batch_done(end, all);
    };
    const RenderStats s = batch_done ? render_samples(tracer, film, r.spp, last, {}, done)
                                     : render_samples(tracer, film, r.spp, last);
    r.stats += s;
    r.last_pass_seconds = s.seconds;
    const auto pixels = static_cast<std::uint64_t>(film.width()) * film.height();
    const std::uint32_t reached = r.spp + static_cast<std::uint32_t>(s.samples / std::max<std::uint64_t>(pixels, 1));
    ++r.passes;
    if (!go_on) {
      r.spp = reached;
      break;
    }
    r.spp = last;
    if (rule.target_relmse > 0.0) r.estimated_relmse = estimated_relmse(film);
    if (progress) {
      double f = static_cast<double>(r.spp) / max_spp;
      if (rule.time_budget_seconds > 0.0) f = std::max(f, elapsed() / rule.time_budget_seconds);
      progress(std::min(f, 1.0));
    }
  }
  if (rule.target_relmse <= 0.0) r.estimated_relmse = estimated_relmse(film);
  r.stats.bad_samples = film.bad_sample_count();
  r.stats.seconds = elapsed();
  return r;
}

}  // namespace pathlab
