#include "debugtools/bounce_aov.h"

#include "core/parallel.h"
#include "debugtools/aov.h"

namespace pathlab {

const char* technique_name(Technique t) { return t == Technique::Bsdf ? "bsdf" : "nee"; }

std::string bounce_layer_name(int depth) {
  return depth >= kBounceDepths ? std::string("Lrest") : "L" + std::to_string(depth);
}

Spectrum BounceLayers::total() const {
  Spectrum s(0.0f);
  for (const auto& layer : L)
    for (const Spectrum& v : layer) s += v;
  return s;
}

BounceAccumulator::BounceAccumulator(int width, int height)
    : width_(width),
      height_(height),
      sums_(static_cast<std::size_t>(width) * height * kBounceLayers * kTechniques),
      count_(static_cast<std::size_t>(width) * height, 0) {}

void BounceAccumulator::add(std::size_t pixel, const BounceLayers& layers) {
  ++count_[pixel];
  for (int d = 0; d < kBounceLayers; ++d)
    for (int t = 0; t < kTechniques; ++t) {
      const dvec3 v(layers.L[static_cast<std::size_t>(d)][static_cast<std::size_t>(t)]);
      Sums& s = sums_[index(pixel, d, static_cast<Technique>(t))];
      s.sum += v;
      s.sum_sq += v * v;
    }
}

void BounceAccumulator::add(const BounceAccumulator& other) {
  for (std::size_t i = 0; i < count_.size(); ++i) count_[i] += other.count_[i];
  for (std::size_t i = 0; i < sums_.size(); ++i) {
    sums_[i].sum += other.sums_[i].sum;
    sums_[i].sum_sq += other.sums_[i].sum_sq;
  }
}

Image BounceAccumulator::mean(int depth, Technique t) const {
  Image img(width_, height_);
  for (std::size_t p = 0; p < count_.size(); ++p)
    if (count_[p] > 0) img.pixels[p] = vec3(sums_[index(p, depth, t)].sum / static_cast<double>(count_[p]));
  return img;
}

Image BounceAccumulator::variance_of_mean(int depth, Technique t) const {
  Image img(width_, height_);
  for (std::size_t p = 0; p < count_.size(); ++p) {
    if (count_[p] < 2) continue;
    const auto n = static_cast<double>(count_[p]);
    const Sums& s = sums_[index(p, depth, t)];
    const dvec3 m = s.sum / n;
    // Sample variance (n - 1), divided by n for the variance of the mean.
    img.pixels[p] = vec3(glm::max(s.sum_sq - n * m * m, dvec3(0.0)) / ((n - 1.0) * n));
  }
  return img;
}

void BounceTracer::render_batch(std::uint32_t first, std::uint32_t count, std::span<FilmSample> out) const {
  const int width = scene_.scene().film.width;
  const int height = scene_.scene().film.height;
  parallel_for(0, static_cast<std::size_t>(height), 1, [&](std::size_t y0, std::size_t y1) {
    for (std::size_t y = y0; y < y1; ++y)
      for (int x = 0; x < width; ++x) {
        const std::size_t pixel = y * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
        for (std::uint32_t j = 0; j < count; ++j) {
          BounceObserver observer;
          const FilmSample fs =
              inner_.trace_sample(static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y), first + j, &observer);
          out[pixel * count + j] = fs;
          // As the film does, a sample whose radiance is not finite is left
          // out (and counted there; the `nonfinite` AOV shows where).
          if (is_finite(fs.L)) bounces_.add(pixel, observer.layers);
        }
      }
  });
}

void add_bounce_channels(std::vector<ExrChannel>& out, const BounceAccumulator& bounces) {
  for (int d = 0; d < kBounceLayers; ++d)
    for (Technique t : {Technique::Bsdf, Technique::Nee})
      add_exr_layer(out, bounce_layer_name(d) + "." + technique_name(t), bounces.mean(d, t), "RGB");
}

}  // namespace pathlab
