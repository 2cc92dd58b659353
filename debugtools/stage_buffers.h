// The wavefront's per-path arrays at one bounce, splatted to images
// (`render --dump-stage-buffers K DIR`, docs/aov.md): the course's
// "visualise the intermediate textures". The wavefront records its scalar
// stages' state at vertex K (WavefrontTracer::render_batch_recording); each
// record goes to the pixel its sample belongs to, and each image is the mean
// over the pixel's samples that qualify:
//
//   reached      fraction of the pixel's samples whose path was alive at vertex K
//   throughput   the throughput of the ray reaching vertex K   (over those that reached it)
//   direction    that ray's direction, world space, not renormalised   (same)
//   distance     the distance to its hit   (over those that hit something; 0 if none did)
//   survival     fraction of those that reached it still alive after that bounce's compaction
//   light_pdf    the area light sample's pdf at vertex K   (over those that took one; 0 if none)
#pragma once

#include "core/image_io.h"
#include "core/tracer.h"
#include "wavefront/wavefront_tracer.h"

#include <filesystem>
#include <string>
#include <vector>

namespace pathlab {

class StageBuffers {
 public:
  StageBuffers(int width, int height, int vertex);
  int vertex() const { return vertex_; }
  // Records of samples [first, first + count) of every pixel, pixel-major.
  void add_batch(std::uint32_t count, std::span<const StageRecord> records);

  Image reached() const;
  Image throughput() const;
  Image direction() const;
  Image distance() const;
  Image survival() const;
  Image light_pdf() const;

  // The six images above by name ("reached", ...), each with the channels
  // it means (`Y` for a scalar, `RGB`, `XYZ` for a direction, `Z`).
  struct Named {
    const char* name;
    Image image;
    const char* channels;
  };
  std::vector<Named> images() const;

  // Writes DIR/bounceK-<name>.exr for each image above (DIR created if
  // needed); returns the files written. Throws InputError if it cannot.
  std::vector<std::filesystem::path> write(const std::filesystem::path& dir, const ImageMetadata& meta) const;

 private:
  struct Pixel {
    std::uint64_t samples = 0, reached = 0, hits = 0, survived = 0, light_samples = 0;
    dvec3 throughput{0.0}, dir{0.0};
    double distance = 0.0, light_pdf = 0.0;
  };
  template <typename F>
  Image map(F&& f) const;
  int width_, height_, vertex_;
  std::vector<Pixel> pixels_;
};

// Forwards to the wavefront, rendering each batch with
// render_batch_recording (the scalar stages) and adding the records.
class StageBufferTracer final : public Tracer {
 public:
  StageBufferTracer(const WavefrontTracer& inner, StageBuffers& buffers)
      : Tracer(inner.scene(), inner.settings()), inner_(inner), buffers_(buffers) {}
  std::string_view name() const override { return inner_.name(); }
  void render_batch(std::uint32_t first, std::uint32_t count, std::span<FilmSample> out) const override;
  FilmSample trace_sample(std::uint32_t x, std::uint32_t y, std::uint32_t sample, PathObserver* observer) const override {
    return inner_.trace_sample(x, y, sample, observer);
  }

 private:
  const WavefrontTracer& inner_;
  StageBuffers& buffers_;
};

}  // namespace pathlab
