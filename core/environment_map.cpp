#include "core/environment_map.h"

#include "core/error.h"

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

vec2 EnvironmentMap::direction_to_uv(const vec3& d) {
  // atan2 in (-pi, pi]: the half turn below 0 is the second half of the map.
  float u = std::atan2(d.x, -d.z) * kInv2Pi;
  if (u < 0.0f) u += 1.0f;
  // theta by atan2 of the direction's sine and cosine: acos(d.y) loses all
  // precision near the poles, where d.y rounds to 1 long before d.x, d.z do.
  const float v = std::atan2(std::sqrt(d.x * d.x + d.z * d.z), d.y) * kInvPi;
  // u = 1 - tiny may round to 1 above; it is the left edge of column 0 again.
  return vec2(u < 1.0f ? u : 0.0f, v);
}

vec3 EnvironmentMap::uv_to_direction(vec2 uv) {
  const float theta = kPi * uv.y, phi = 2.0f * kPi * uv.x;
  const float sin_theta = std::sin(theta);
  return vec3(sin_theta * std::sin(phi), std::cos(theta), -sin_theta * std::cos(phi));
}

glm::ivec2 EnvironmentMap::texel_of(vec2 uv) const {
  return glm::ivec2(std::clamp(static_cast<int>(uv.x * static_cast<float>(width())), 0, width() - 1),
                    std::clamp(static_cast<int>(uv.y * static_cast<float>(height())), 0, height() - 1));
}

EnvironmentMap::Lookup EnvironmentMap::lookup(const vec3& dir) const {
  const vec3 local = to_local_ * dir;
  const glm::ivec2 t = texel_of(direction_to_uv(local));
  Lookup out;
  out.radiance = texels_.at(t.x, t.y);
  // sin theta from the direction itself, not the texel: the density of the
  // map's (u, v) -> direction is 1 / (2 pi^2 sin theta) at that point. From
  // x and z, not 1 - y^2, which is 0 within 3e-4 rad of a pole in float.
  const float sin_theta = std::sqrt(local.x * local.x + local.z * local.z);
  if (sin_theta > 0.0f)
    out.pdf = distribution_.pdf(static_cast<std::size_t>(t.x), static_cast<std::size_t>(t.y)) /
              (2.0f * kPi * kPi * sin_theta);
  return out;
}

std::optional<EnvironmentMap::Sample> EnvironmentMap::sample(vec2 u) const {
  const Distribution2D::Sample s = distribution_.sample(u);
  const float sin_theta = std::sin(kPi * s.p.y);
  if (!(s.pdf > 0.0f) || !(sin_theta > 0.0f)) return std::nullopt;
  Sample out;
  out.wi = glm::normalize(to_world_ * uv_to_direction(s.p));
  // The density and radiance of the texel drawn (as pbrt-v4's
  // ImageInfiniteLight does), not of a lookup of wi: a point drawn within
  // rounding of a texel's edge can map back into the neighbour, and next to
  // a sun that neighbour may be black (density 0). They equal pdf(wi) and
  // radiance(wi) everywhere else.
  out.pdf = s.pdf / (2.0f * kPi * kPi * sin_theta);
  if (std::isinf(out.pdf)) return std::nullopt;
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
