#include "debugtools/stage_buffers.h"

#include "core/error.h"
#include "core/parallel.h"

#include <cmath>

namespace pathlab {

StageBuffers::StageBuffers(int width, int height, int vertex)
    : width_(width), height_(height), vertex_(vertex), pixels_(static_cast<std::size_t>(width) * height) {}

void StageBuffers::add_batch(std::uint32_t count, std::span<const StageRecord> records) {
  parallel_for(0, pixels_.size(), 64, [&](std::size_t p0, std::size_t p1) {
    for (std::size_t p = p0; p < p1; ++p) {
      Pixel& px = pixels_[p];
      for (std::uint32_t j = 0; j < count; ++j) {
        const StageRecord& r = records[p * count + j];
        ++px.samples;
        if (!r.reached) continue;
        ++px.reached;
        px.throughput += dvec3(r.throughput);
        px.dir += dvec3(r.dir);
        if (std::isfinite(r.distance)) ++px.hits, px.distance += static_cast<double>(r.distance);
        if (r.survived) ++px.survived;
        if (r.light_sampled) ++px.light_samples, px.light_pdf += static_cast<double>(r.light_pdf);
      }
    }
  });
}

template <typename F>
Image StageBuffers::map(F&& f) const {
  Image img(width_, height_);
  for (std::size_t i = 0; i < pixels_.size(); ++i) img.pixels[i] = vec3(f(pixels_[i]));
  return img;
}

namespace {
double ratio(double a, std::uint64_t n) { return n > 0 ? a / static_cast<double>(n) : 0.0; }
dvec3 ratio(const dvec3& a, std::uint64_t n) { return n > 0 ? a / static_cast<double>(n) : dvec3(0.0); }
}  // namespace

Image StageBuffers::reached() const {
  return map([](const Pixel& p) { return dvec3(ratio(static_cast<double>(p.reached), p.samples)); });
}
Image StageBuffers::throughput() const { return map([](const Pixel& p) { return ratio(p.throughput, p.reached); }); }
Image StageBuffers::direction() const { return map([](const Pixel& p) { return ratio(p.dir, p.reached); }); }
Image StageBuffers::distance() const { return map([](const Pixel& p) { return dvec3(ratio(p.distance, p.hits)); }); }
Image StageBuffers::survival() const {
  return map([](const Pixel& p) { return dvec3(ratio(static_cast<double>(p.survived), p.reached)); });
}
Image StageBuffers::light_pdf() const {
  return map([](const Pixel& p) { return dvec3(ratio(p.light_pdf, p.light_samples)); });
}

std::vector<std::filesystem::path> StageBuffers::write(const std::filesystem::path& dir, const ImageMetadata& meta) const {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir))
    throw InputError(dir.string() + ": cannot create the folder for the stage buffers" +
                     (ec ? ": " + ec.message() : std::string()));
  std::vector<std::filesystem::path> files;
  const std::string prefix = "bounce" + std::to_string(vertex_) + "-";
  for (const Named& n : images()) {
    files.push_back(dir / (prefix + n.name + ".exr"));
    write_exr(files.back(), n.image, meta);
  }
  return files;
}

std::vector<StageBuffers::Named> StageBuffers::images() const {
  return {{"reached", reached(), "Y"},   {"throughput", throughput(), "RGB"}, {"direction", direction(), "XYZ"},
          {"distance", distance(), "Z"}, {"survival", survival(), "Y"},       {"light_pdf", light_pdf(), "Y"}};
}

void StageBufferTracer::render_batch(std::uint32_t first, std::uint32_t count, std::span<FilmSample> out) const {
  std::vector<StageRecord> records(out.size());
  inner_.render_batch_recording(first, count, out, buffers_.vertex(), records);
  buffers_.add_batch(count, records);
}

}  // namespace pathlab
