#include "debugtools/aov.h"

#include "core/parallel.h"
#include "debugtools/bounce_aov.h"
#include "core/rng.h"
#include "core/sample_dims.h"
#include "core/surfel.h"

#include <algorithm>
#include <stdexcept>

namespace pathlab {

namespace {
// The colour the albedo AOV shows for a material: the parameter a user
// thinks of as its colour.
// A textured material's colour is the one its hit read (`s.params`; the
// Disney base colour looked up there, unfiltered).
Spectrum surface_colour(const Surfel& s, const Textures* textures) {
  const Material& m = *s.material;
  switch (m.type) {
    case MaterialType::Disney:
      if (const TexturedParam* t = m.texture_of(MaterialParam::BaseColor); t && textures)
        return glm::clamp(textures->color(t->texture, {s.uv, 0.0f}), Spectrum(0.0f), Spectrum(1.0f));
      return m.disney.base_color;
    case MaterialType::Dielectric: return s.params ? s.params->glass.transmittance : m.glass.transmittance;
    default: return s.params ? s.params->albedo : m.albedo;
  }
}
}  // namespace

const char* aov_name(Aov a) {
  switch (a) {
    case Aov::Albedo: return "albedo";
    case Aov::Normal: return "normal";
    case Aov::Depth: return "depth";
    case Aov::Material: return "material";
    case Aov::Variance: return "variance";
    case Aov::PathLength: return "pathlength";
    case Aov::Bounces: return "bounces";
  }
  return "?";
}

std::optional<Aov> parse_aov(std::string_view name) {
  for (Aov a : kAllAovs)
    if (name == aov_name(a)) return a;
  return std::nullopt;
}

AovAccumulator::AovAccumulator(const CompiledScene& scene, const RenderSettings& settings)
    : scene_(scene),
      settings_(settings),
      width_(scene.scene().film.width),
      height_(scene.scene().film.height),
      pixels_(static_cast<std::size_t>(width_) * height_) {}

void AovAccumulator::add_batch(std::uint32_t first, std::uint32_t count, std::span<const FilmSample> samples) {
  const Camera& camera = scene_.camera();
  const RayCone cone = scene_.camera_cone(settings_.texture_filter);
  const SamplerSetup sampler(settings_.sampler, settings_.seed, static_cast<std::uint32_t>(width_),
                             static_cast<std::uint32_t>(height_), static_cast<std::uint32_t>(std::max(settings_.spp, 1)));
  parallel_for(0, static_cast<std::size_t>(height_), 1, [&](std::size_t y0, std::size_t y1) {
    SurfaceParams params;  // a textured material's parameters at a hit, read with the camera's cone
    for (std::size_t y = y0; y < y1; ++y) {
      for (int x = 0; x < width_; ++x) {
        const std::size_t index = y * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x);
        Pixel& px = pixels_[index];
        for (std::uint32_t j = 0; j < count; ++j) {
          const FilmSample& fs = samples[index * count + j];
          px.path_hits += fs.hits;
          px.nonfinite += is_finite(fs.L) ? 0u : 1u;
          ++px.samples;
          // The camera ray of this sample, as both tracers draw it.
          const SampleStream u = sampler.stream(static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y), first + j);
          const SampleStream::Pair f = u.get2(0, Dim::FilmX), l = u.get2(0, Dim::LensX);
          const vec2 film(static_cast<float>(x) + f.x, static_cast<float>(y) + f.y);
          Ray ray = camera.generate_ray(film, vec2(l.x, l.y));
          ray.alpha_key = scene_.alpha_key(u, 0);  // sees through what the render saw through
          Surfel s;
          const bool hit = scene_.intersect(ray, &s, cone, &params);
          if (first + j == 0) px.material = hit ? static_cast<int>(s.material - scene_.scene().materials.data()) : -1;
          if (!hit) continue;
          ++px.surface_hits;
          if (s.material->scatters()) px.albedo += dvec3(surface_colour(s, scene_.textures()));
          px.normal += dvec3(s.frame.n);
          px.depth += static_cast<double>(glm::length(s.p - ray.origin));
        }
      }
    }
  });
}

template <typename F>
Image AovAccumulator::map(F&& f) const {
  Image img(width_, height_);
  for (std::size_t i = 0; i < pixels_.size(); ++i) img.pixels[i] = f(pixels_[i]);
  return img;
}

Image AovAccumulator::albedo() const {
  return map([](const Pixel& p) { return p.samples ? vec3(p.albedo / static_cast<double>(p.samples)) : vec3(0.0f); });
}
Image AovAccumulator::normal() const {
  return map([](const Pixel& p) { return p.samples ? vec3(p.normal / static_cast<double>(p.samples)) : vec3(0.0f); });
}
Image AovAccumulator::depth() const {
  return map([](const Pixel& p) {
    return vec3(p.surface_hits ? static_cast<float>(p.depth / static_cast<double>(p.surface_hits)) : 0.0f);
  });
}
Image AovAccumulator::material() const {
  return map([](const Pixel& p) { return vec3(static_cast<float>(p.material)); });
}
Image AovAccumulator::path_length() const {
  return map([](const Pixel& p) {
    return vec3(p.samples ? static_cast<float>(static_cast<double>(p.path_hits) / static_cast<double>(p.samples)) : 0.0f);
  });
}
Image AovAccumulator::nonfinite() const {
  return map([](const Pixel& p) { return vec3(static_cast<float>(p.nonfinite)); });
}

float AovAccumulator::path_length(int x, int y) const {
  const Pixel& p = pixels_[static_cast<std::size_t>(y) * width_ + x];
  return p.samples ? static_cast<float>(static_cast<double>(p.path_hits) / static_cast<double>(p.samples)) : 0.0f;
}

std::uint64_t AovAccumulator::nonfinite(int x, int y) const {
  return pixels_[static_cast<std::size_t>(y) * width_ + x].nonfinite;
}

void add_exr_layer(std::vector<ExrChannel>& out, const std::string& layer, const Image& image, std::string_view channels) {
  for (std::size_t c = 0; c < channels.size(); ++c) {
    ExrChannel ch{layer.empty() ? std::string(1, channels[c]) : layer + "." + channels[c], {}};
    ch.values.reserve(image.pixels.size());
    for (const vec3& p : image.pixels) ch.values.push_back(p[static_cast<int>(c)]);
    out.push_back(std::move(ch));
  }
}

std::vector<ExrChannel> aov_channels(const Film& film, const AovAccumulator& aovs, std::span<const Aov> which,
                                     const BounceAccumulator* bounces) {
  std::vector<ExrChannel> channels;
  const auto add = [&](const std::string& layer, const Image& img, std::string_view names) {
    add_exr_layer(channels, layer, img, names);
  };
  add("", film.image(), "RGB");
  for (Aov a : which) {
    switch (a) {
      case Aov::Albedo: add("albedo", aovs.albedo(), "RGB"); break;
      case Aov::Normal: add("normal", aovs.normal(), "XYZ"); break;
      case Aov::Depth: add("depth", aovs.depth(), "Z"); break;
      case Aov::Material: add("material", aovs.material(), "Y"); break;
      case Aov::Variance: add("variance", film.variance_of_mean(), "RGB"); break;
      case Aov::PathLength: add("pathlength", aovs.path_length(), "Y"); break;
      case Aov::Bounces:
        if (!bounces) throw std::logic_error("aov_channels: the bounces layers need their accumulator");
        add_bounce_channels(channels, *bounces);
        break;
    }
  }
  return channels;
}

}  // namespace pathlab
