// Random draws of (direction, parameters) at the edges of every range,
// through the Surfel as the tracers call it: eval, pdf and scatter must never
// give a NaN, an infinity or a negative value. Draws include roughness 0,
// 1e-7 and denormal, anisotropic 0.999 and 1, view and light cosines 1e-7,
// denormal, +0 and -0, base colours with denormal components, cosine-power
// exponents up to the cap 1e6 (roughness -> 0 with cospow sampling),
// dielectrics of ior 1 to 10 at every angle, and energy-compensated Disney
// materials at the corners of the ranges (a fixed pool).
#pragma once

#include "core/parallel.h"
#include "tests/bsdf_checks.h"

#include <atomic>
#include <chrono>
#include <mutex>

namespace pathlab::test::bsdf {

struct ExtremesResult {
  long draws = 0;
  long nan = 0, inf = 0, negative = 0;
  double seconds = 0.0;
  std::string first;  // the first bad draw, described
};

namespace detail {

// A number in [0, 1], often one of the edge values.
inline float edgy_unit(Uniform& u) {
  static constexpr float kEdges[] = {0.0f, 1e-7f, 1e-40f, 1.0f, 0.999f, 0.5f, 1.0f - 1e-7f, 1e-20f};
  const std::uint64_t b = u.bits();
  if (b % 3 == 0) return kEdges[(b >> 8) % std::size(kEdges)];
  return u.next();
}

// A cosine, often at the horizon (both zeros, 1e-7, denormal) or the pole.
inline float edgy_cos(Uniform& u) {
  static constexpr float kEdges[] = {0.0f, -0.0f, 1e-7f, -1e-7f, 1e-40f, -1e-40f, 1.0f, -1.0f, 1e-3f, 0.999999f};
  const std::uint64_t b = u.bits();
  if (b % 2 == 0) return kEdges[(b >> 8) % std::size(kEdges)];
  return 2.0f * u.next() - 1.0f;
}

inline vec3 edgy_dir(Uniform& u) {
  const float c = edgy_cos(u);
  const float s = std::sqrt(std::max(0.0f, 1.0f - c * c));
  const std::uint64_t b = u.bits();
  // Azimuths along the axes too (x or y exactly 0).
  const float phi = b % 4 == 0 ? 0.5f * kPi * static_cast<float>((b >> 8) % 4) : 2.0f * kPi * u.next();
  return vec3(s * std::cos(phi), s * std::sin(phi), c);
}

// Energy-compensated materials at the corners of the parameter ranges. Their
// tables take ~0.1 s each to build: too slow to draw afresh for every
// sample, so a fixed pool that the draws pick from.
inline const std::vector<Material>& compensated_pool() {
  static const std::vector<Material> pool = [] {
    std::vector<Material> v;
    for (const float r : {0.0f, 1e-7f, 1.0f})
      for (const float a : {0.0f, 0.999f})
        for (const float m : {0.0f, 1.0f}) {
          DisneyParams p;
          p.base_color = Spectrum(1.0f, 1e-40f, 0.0f);
          p.roughness = r;
          p.anisotropic = a;
          p.metallic = m;
          p.subsurface = 1.0f;
          p.sheen = 1.0f;
          p.specular = 1.0f;
          p.clearcoat = 1.0f;
          p.clearcoat_gloss = 1.0f - r;
          p.energy_compensation = true;
          v.push_back(disney_material(p));
        }
    return v;
  }();
  return pool;
}

inline Material edgy_material(Uniform& u) {
  const std::uint64_t b = u.bits();
  if (b % 8 == 2) return compensated_pool()[(b >> 8) % compensated_pool().size()];
  if (b % 8 == 0) {
    DielectricParams g;
    g.ior = (b >> 8) % 3 == 0 ? 1.0f : 1.0f + 9.0f * edgy_unit(u);
    g.reflectance = Spectrum(edgy_unit(u), edgy_unit(u), edgy_unit(u));
    g.transmittance = Spectrum(edgy_unit(u), edgy_unit(u), edgy_unit(u));
    return dielectric_material(g);
  }
  if (b % 8 == 1) return diffuse_material(Spectrum(edgy_unit(u), edgy_unit(u), edgy_unit(u)));
  DisneyParams p;
  p.base_color = Spectrum(edgy_unit(u), edgy_unit(u), edgy_unit(u));
  p.metallic = edgy_unit(u);
  p.subsurface = edgy_unit(u);
  p.specular = edgy_unit(u);
  p.specular_tint = edgy_unit(u);
  p.roughness = edgy_unit(u);
  p.anisotropic = edgy_unit(u);
  p.sheen = edgy_unit(u);
  p.sheen_tint = edgy_unit(u);
  p.clearcoat = edgy_unit(u);
  p.clearcoat_gloss = edgy_unit(u);
  return disney_material(p);
}

}  // namespace detail

inline ExtremesResult run_extremes(long draws, std::uint64_t seed) {
  const auto start = std::chrono::steady_clock::now();
  constexpr long kChunk = 1 << 16;
  const long chunks = (draws + kChunk - 1) / kChunk;
  std::atomic<long> nan{0}, inf{0}, negative{0};
  std::mutex first_mutex;
  std::string first;
  parallel_for(0, static_cast<std::size_t>(chunks), 1, [&](std::size_t cb, std::size_t ce) {
    for (std::size_t chunk = cb; chunk < ce; ++chunk) {
      Uniform u(seed * 0x9E3779B97F4A7C15ull + chunk);
      long my_nan = 0, my_inf = 0, my_neg = 0;
      const long end = std::min(draws, static_cast<long>(chunk + 1) * kChunk);
      for (long i = static_cast<long>(chunk) * kChunk; i < end; ++i) {
        Material m = detail::edgy_material(u);
        const std::uint64_t b = u.bits();
        m.shading.sampling = b % 2 ? BsdfSampling::Cospow : BsdfSampling::Vndf;
        m.shading.path = shading_path_for(m.lobes(), (b >> 1) % 2 == 0);
        Surfel s = flat_surfel(m);
        if ((b >> 2) % 2 == 0) {
          s.n = glm::normalize(vec3(2 * u.next() - 1, 2 * u.next() - 1, 2 * u.next() - 1 + 1e-3f));
          s.frame = Frame(s.n);
        }
        const vec3 wo = s.frame.to_world(detail::edgy_dir(u));
        const vec3 wi = s.frame.to_world(detail::edgy_dir(u));
        const float ul = u.next();
        const vec2 uu = (b >> 3) % 4 == 0 ? vec2(detail::edgy_unit(u), detail::edgy_unit(u)) : u.next2();
        float values[12];
        int k = 0;
        const Spectrum f = s.eval(wi, wo);
        values[k++] = f.x, values[k++] = f.y, values[k++] = f.z;
        values[k++] = s.pdf(wi, wo);
        const auto bs = s.scatter(wo, ul, uu);
        if (bs) {
          values[k++] = bs->weight.x, values[k++] = bs->weight.y, values[k++] = bs->weight.z;
          values[k++] = bs->pdf;
          values[k++] = bs->wi.x, values[k++] = bs->wi.y, values[k++] = bs->wi.z;
        }
        bool bad = false;
        for (int j = 0; j < k; ++j) {
          const bool is_dir = j >= 8;  // direction components may be negative
          if (std::isnan(values[j])) ++my_nan, bad = true;
          else if (std::isinf(values[j])) ++my_inf, bad = true;
          else if (!is_dir && values[j] < 0.0f) ++my_neg, bad = true;
        }
        if (bad) {
          const std::lock_guard<std::mutex> lock(first_mutex);
          if (first.empty()) {
            std::ostringstream d;
            d << material_type_name(m.type) << " rough " << m.disney.roughness << " aniso " << m.disney.anisotropic
              << " metal " << m.disney.metallic << " ior " << m.glass.ior << " path " << shading_path_name(m.shading.path)
              << " " << bsdf_sampling_name(m.shading.sampling) << " wo (" << wo.x << "," << wo.y << "," << wo.z << ") wi ("
              << wi.x << "," << wi.y << "," << wi.z << "): f (" << f.x << "," << f.y << "," << f.z << ") pdf "
              << values[3];
            if (bs) d << " sample weight (" << bs->weight.x << "," << bs->weight.y << "," << bs->weight.z << ") pdf " << bs->pdf;
            first = d.str();
          }
        }
      }
      nan += my_nan;
      inf += my_inf;
      negative += my_neg;
    }
  });
  return ExtremesResult{draws, nan.load(), inf.load(), negative.load(),
                        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), first};
}

}  // namespace pathlab::test::bsdf
