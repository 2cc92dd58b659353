// An environment light given by a latitude-longitude image (Mitsuba 3's
// `envmap`; pbrt-v4's ImageInfiniteLight with a lat-long parametrisation
// instead of its octahedral one). One source for both tracers: the radiance
// a ray that escapes sees, and importance sampling for next-event estimation.
//
// Scene keys (docs/scene-format.md, Lights): "file" (an EXR or HDR image,
// 2:1, RGB or one grey channel), "scale" (default 1, multiplies every texel),
// "transform" (rotations only; default none), "clamp_negative" (default
// true: negative texel components are read as 0, with a warning; false
// refuses them).
//
// Lat-long convention (Mitsuba 3's): +y is up. In the map's own frame a
// texel's centre (u, v) in [0, 1)^2, u = (column + 1/2) / width and
// v = (row + 1/2) / height with row 0 the top row of the image, is the
// direction
//   theta = pi v, phi = 2 pi u,
//   d = (sin theta sin phi, cos theta, -sin theta cos phi):
// row 0 looks up (+y), the last row down; the left edge of column 0 looks
// along -z, a quarter of the way across along +x, the middle along +z and
// three quarters along -x. Seen from inside the sphere of directions the
// image is therefore not mirrored (a panorama taken looking along -z).
// `transform` rotates the map: the world direction of d is to_world d.
//
// Lookup is piecewise constant (the texel a direction falls in, no
// filtering): then the importance sampler's density, a piecewise-constant
// density in (u, v) proportional to luminance x sin(theta at the texel's
// centre), is exactly what sample() draws, and radiance / pdf is bounded
// inside every texel. Bilinear lookup would need a bilinear sampler to keep
// that property; a map is usually fine enough for nearest to be invisible.
//
// The density in solid angle of a direction with lat-long coordinates
// (u, v) is p(u, v) / (2 pi^2 sin theta) (the Jacobian of the map); at the
// poles (sin theta = 0) it is taken as 0: sample() never returns a pole.
#pragma once

#include "core/image_io.h"
#include "core/math.h"
#include "core/sampling.h"

#include <filesystem>
#include <optional>
#include <string>

namespace pathlab {

class EnvironmentMap {
 public:
  // `texels` in scene radiance (already scaled), finite and >= 0, width =
  // 2 height; `to_world` a rotation (orthonormal). Throws InputError if the
  // texels break that (load_environment_map checks first, with the file's name).
  EnvironmentMap(Image texels, const mat3& to_world, std::string source);

  int width() const { return texels_.width; }
  int height() const { return texels_.height; }
  const Image& texels() const { return texels_; }
  const mat3& to_world() const { return to_world_; }
  const mat3& to_local() const { return to_local_; }
  // The importance sampler's density in (u, v) (row y of the map is row y
  // of the distribution), for code that samples the map in bulk.
  const Distribution2D& distribution() const { return distribution_; }
  const std::string& source() const { return source_; }  // the file, for messages

  // Radiance arriving from world direction `dir` (unit): the radiance of
  // rays that travel along -dir, i.e. what a ray with direction `dir` sees.
  Spectrum radiance(const vec3& dir) const { return lookup(dir).radiance; }
  // Density in solid angle with which sample() returns `dir` (0 if the map
  // is black, at a pole or in a black texel).
  float pdf(const vec3& dir) const { return lookup(dir).pdf; }
  // Both, from one texel lookup (an escaping ray needs both).
  struct Lookup {
    Spectrum radiance{0.0f};
    float pdf = 0.0f;
  };
  Lookup lookup(const vec3& dir) const;

  struct Sample {
    vec3 wi{0.0f};
    float pdf = 0.0f;
    Spectrum radiance{0.0f};
  };
  // A direction in proportion to luminance (x sin theta's share of the solid
  // angle), with the density and radiance of the texel drawn. Nothing for a
  // black map, or if the draw lands on a pole.
  std::optional<Sample> sample(vec2 u) const;

  // Integral over the sphere of the luminance of radiance(dir), for the
  // power with which LightSampler picks the map.
  double luminance_integral() const { return luminance_integral_; }
  bool is_black() const { return all_black_; }
  // The radiance if every texel is the same, else nothing.
  std::optional<Spectrum> constant() const { return constant_; }

  // The convention above, in the map's own frame: a unit direction to its
  // (u, v) in [0, 1)^2 and back, and (u, v) to the texel it lies in.
  static vec2 direction_to_uv(const vec3& local);
  static vec3 uv_to_direction(vec2 uv);
  glm::ivec2 texel_of(vec2 uv) const;

 private:
  Image texels_;
  mat3 to_world_{1.0f};
  mat3 to_local_{1.0f};
  std::string source_;
  Distribution2D distribution_;
  double luminance_integral_ = 0.0;
  bool all_black_ = true;
  std::optional<Spectrum> constant_;
};

// Reads a lat-long map for a scene: OpenEXR, Radiance HDR or anything
// OpenImageIO reads as float, 3 channels (RGB) or 1 (grey, used for all
// three). Each texel is multiplied by `scale` (>= 0). Throws InputError
// naming `file` and the problem: missing or unreadable, not 2:1, another
// channel count, a texel that is NaN or infinite (its column, row and
// channel), one that `scale` makes infinite, or negative components (how
// many, and the most negative one's place) unless `clamp_negative`, which
// reads them as 0 and describes them in `*warning` instead.
EnvironmentMap load_environment_map(const std::filesystem::path& file, float scale, const mat3& to_world,
                                    bool clamp_negative = false, std::string* warning = nullptr);

}  // namespace pathlab
