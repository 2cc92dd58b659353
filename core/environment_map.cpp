#include "core/environment_map.h"

#include "core/error.h"
#include "core/simd/width1.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace pathlab {

EnvironmentMap::EnvironmentMap(Image texels, const mat3& to_world, std::string source)
    : texels_(std::move(texels)), to_world_(to_world), to_local_(glm::transpose(to_world)), source_(std::move(source)) {
  const int w = texels_.width, h = texels_.height;
  if (w <= 0 || w != 2 * h) throw InputError(source_ + ": an environment map must be twice as wide as high");
  std::vector<float> weights(texels_.pixels.size());
  const double texel_phi = 2.0 * double(kPi) / w;
  constant_ = texels_.pixels.front();
  for (int y = 0; y < h; ++y) {
    // The sampler's weight uses sin theta at the row's centre (its density
    // in (u, v) is then constant over the texel); the power integral uses
    // the row's exact solid angle.
    const double theta0 = double(kPi) * y / h, theta1 = double(kPi) * (y + 1) / h;
    const float sin_centre = static_cast<float>(std::sin(0.5 * (theta0 + theta1)));
    const double solid_angle = texel_phi * (std::cos(theta0) - std::cos(theta1));
    for (int x = 0; x < w; ++x) {
      const Spectrum& L = texels_.at(x, y);
      if (!is_finite(L) || L.x < 0.0f || L.y < 0.0f || L.z < 0.0f)
        throw InputError(source_ + ": texel (" + std::to_string(x) + ", " + std::to_string(y) +
                         ") is not a finite radiance >= 0");
      const float Y = luminance(L);
      weights[static_cast<std::size_t>(y) * w + x] = Y * sin_centre;
      luminance_integral_ += double(Y) * solid_angle;
      all_black_ = all_black_ && pathlab::is_black(L);
      if (constant_ && L != *constant_) constant_.reset();
    }
  }
  distribution_ = Distribution2D(weights, static_cast<std::size_t>(w), static_cast<std::size_t>(h));
}

// The convention's steps are core/simd/environment-inl.h's, at width 1: the
// wavefront's lanes run the same source.

vec2 EnvironmentMap::direction_to_uv(const vec3& d) {
  using namespace width1;
  F u, v;
  generic::env_direction_to_uv(kScalar, lanes(d), u, v);
  return vec2(u.raw, v.raw);
}

vec3 EnvironmentMap::uv_to_direction(vec2 uv) {
  using namespace width1;
  F sin_theta;
  return scalars(generic::env_uv_to_direction(kScalar, F{uv.x}, F{uv.y}, sin_theta));
}

glm::ivec2 EnvironmentMap::texel_of(vec2 uv) const {
  using namespace width1;
  return glm::ivec2(static_cast<int>(generic::env_texel(kScalar, F{uv.x}, F{static_cast<float>(width())}).raw),
                    static_cast<int>(generic::env_texel(kScalar, F{uv.y}, F{static_cast<float>(height())}).raw));
}

namespace {
// m v for a rotation m, as the lanes compute it: (m[0] v.x + m[1] v.y) + m[2] v.z, glm's order.
width1::F3 rotate(const mat3& m, const width1::F3& v) {
  using namespace width1;
  return generic::to_world(lanes(m[0]), lanes(m[1]), lanes(m[2]), v.x, v.y, v.z);
}
}  // namespace

// lookup and sample are core/simd/environment-inl.h's env_lookup and
// env_sample_direction (after distribution2d_sample) at width 1, as the
// wavefront's lanes run them on the same cdfs.

EnvironmentMap::Lookup EnvironmentMap::lookup(const vec3& dir) const {
  using namespace width1;
  F x, y;
  const F pdf = generic::env_lookup(kScalar, lane1::M{true}, rotate(to_local_, lanes(dir)), distribution_.width(),
                                    distribution_.height(), Cdfs2D{distribution_}, x, y);
  Lookup out;
  out.radiance = texels_.at(static_cast<int>(x.raw), static_cast<int>(y.raw));
  out.pdf = pdf.raw;
  return out;
}

std::optional<EnvironmentMap::Sample> EnvironmentMap::sample(vec2 u) const {
  using namespace width1;
  const Distribution2D::Sample s = distribution_.sample(u);
  lane1::M ok{true};
  F pdf;
  const F3 wi = generic::env_sample_direction(kScalar, ok, F{s.p.x}, F{s.p.y}, F{s.pdf}, lanes(to_world_[0]),
                                              lanes(to_world_[1]), lanes(to_world_[2]), pdf);
  if (!ok.raw) return std::nullopt;
  Sample out;
  out.wi = scalars(wi);
  out.pdf = pdf.raw;
  // The radiance of the texel drawn (as its density: env_sample_direction).
  out.radiance = texels_.at(static_cast<int>(s.x), static_cast<int>(s.y));
  return out;
}

EnvironmentMap load_environment_map(const std::filesystem::path& file, float scale, const mat3& to_world,
                                    bool clamp_negative, std::string* warning) {
  const std::string name = file.string();
  // The channel count first: read_image takes the first three of any
  // number, but an alpha or a fourth colour channel has no meaning here.
  if (std::filesystem::exists(file) && !std::filesystem::is_directory(file)) {
    std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(name);
    if (in) {
      const int channels = in->spec().nchannels;
      in->close();
      if (channels != 1 && channels != 3)
        throw InputError(name + ": an environment map needs 3 channels (RGB) or 1 (grey); the file has " +
                         std::to_string(channels));
    }
  }
  Image image = read_image(file);
  if (image.width != 2 * image.height) {
    std::ostringstream m;
    m << name << ": an environment map must be twice as wide as high (latitude-longitude); the image is "
      << image.width << " x " << image.height;
    throw InputError(m.str());
  }
  const auto at = [](int x, int y, int c) {
    std::ostringstream m;
    m << "texel (column " << x << ", row " << y << ") channel " << "RGB"[c];
    return m.str();
  };
  std::size_t negatives = 0;
  float most_negative = 0.0f;
  std::string where_most;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      vec3& L = image.at(x, y);
      for (int c = 0; c < 3; ++c) {
        if (std::isnan(L[c])) throw InputError(name + ": " + at(x, y, c) + " is NaN");
        if (std::isinf(L[c])) throw InputError(name + ": " + at(x, y, c) + " is infinite");
        if (L[c] < 0.0f) {
          if (negatives++ == 0 || L[c] < most_negative) {
            most_negative = L[c];
            where_most = at(x, y, c);
          }
          if (clamp_negative) L[c] = 0.0f;
        }
      }
      L *= scale;
      if (!is_finite(L)) {
        std::ostringstream m;
        m << name << ": texel (column " << x << ", row " << y << ") times the scale " << scale
          << " exceeds the float range";
        throw InputError(m.str());
      }
    }
  if (negatives > 0) {
    // Out-of-gamut colours of an HDR photograph, typically: tiny negative
    // components left by a colour-space conversion. Radiance cannot be
    // negative: they are read as 0 with a warning (the scene's default), or
    // refused when the scene says "clamp_negative": false.
    std::ostringstream m;
    m << name << ": " << negatives << " texel component(s) are negative, the most " << where_most << " ("
      << most_negative << ")";
    if (!clamp_negative) throw InputError(m.str() + "; \"clamp_negative\": true (the default) reads them as 0");
    if (warning) *warning = m.str() + "; read as 0";
  }
  return EnvironmentMap(std::move(image), to_world, name);
}

}  // namespace pathlab
