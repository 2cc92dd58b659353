// Image textures, looked up through OpenImageIO's TextureSystem.
//
// A scene lists the images its materials read (Scene::textures: one entry per
// file and colour space); a material parameter that is textured holds a
// TextureRef (which image, which channel, wrap mode, scale and offset). A
// CompiledScene whose scene has images owns one `Textures`: one OIIO
// TextureSystem of its own (not OIIO's shared one, so that two scenes, and
// the tests, never share a cache), with every image's handle resolved once,
// at load. A lookup is then a handle, the thread's OIIO per-thread record and
// the texture coordinates: no string is hashed per hit. A scene without
// images creates none of this.
//
// What is refused at load (InputError naming the file): a file that is
// missing or unreadable, more than 4 or no channels, a texel that is NaN or
// infinite (every image is scanned once, whole; the message names the texel).
//
// Colour spaces. OIIO 2.4's TextureSystem returns the stored values (it has
// no colour transform per lookup), and filtering sRGB-encoded values would
// average in the wrong space (a 50 % black-and-white checker filters to 0.5
// encoded = 0.21 linear instead of 0.5). So an image read as "srgb" is
// decoded once at load (IEC 61966-2-1, exactly, to 32-bit float, alpha left
// alone) and written as a tiled, MIP-mapped TX file in a temporary folder the
// Textures object removes again; the TextureSystem reads that, and every
// MIP level and filtered lookup is in linear space. A "linear" image that is
// already tiled and MIP-mapped (a TX file from maketx) is read in place; any
// other is converted the same way, without the decoding. So every texture
// reaches the TextureSystem as tiles, which come and go within `cache_mb`
// however large the images are (an untiled image would enter the cache
// whole, and Debian's OIIO aborts when that exceeds ten times the cache).
// The load-time scan still reads each finest level once.
//
// Coordinates. pathlab's uv has its origin at the bottom left, v up
// (core/mesh.h); OIIO's t runs down the image, so a lookup reads t = 1 - v.
#pragma once

#include "core/math.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace pathlab {

// How uv outside [0, 1] reads the image (OIIO's wrap modes; "repeat" is
// OIIO's "periodic", glTF's REPEAT).
enum class TextureWrap : std::uint8_t { Repeat, Clamp, Black, Mirror };
const char* texture_wrap_name(TextureWrap wrap);
std::optional<TextureWrap> parse_texture_wrap(std::string_view name);

// How an image's values are encoded: "srgb" (the sRGB transfer curve;
// colour textures by default, as in glTF) or "linear" (data textures:
// roughness, metallic, normal maps, alpha).
enum class TextureColorSpace : std::uint8_t { Srgb, Linear };
const char* texture_color_space_name(TextureColorSpace space);
std::optional<TextureColorSpace> parse_texture_color_space(std::string_view name);

// How lookups are filtered (RenderSettings::texture_filter).
enum class TextureFilter : std::uint8_t {
  Cone,   // the ray cone's footprint (core/ray_cone.h) as OIIO's derivatives: MIP-mapped, filtered
  Point,  // zero derivatives: the finest level, bilinear between its texels
};
const char* texture_filter_name(TextureFilter filter);
std::optional<TextureFilter> parse_texture_filter(std::string_view name);

// One image a scene reads.
struct TextureImage {
  std::filesystem::path file;
  TextureColorSpace colorspace = TextureColorSpace::Srgb;
  std::string where;  // for messages: the scene file and the key that named it first
};

// A textured parameter: value = scale * decoded texel + offset, per channel.
struct TextureRef {
  std::uint32_t image = 0;  // index into Scene::textures
  TextureWrap wrap = TextureWrap::Repeat;
  // The first channel read: a colour reads channels [channel, channel + 3)
  // (a one- or two-channel image is grey: its channel 0 given thrice), a
  // number reads channel `channel`.
  std::uint8_t channel = 0;
  Spectrum scale{1.0f};
  Spectrum offset{0.0f};
};

// Where a lookup reads: uv, and the footprint's width in uv units (0: the
// finest level, bilinear).
struct TextureFootprint {
  vec2 uv{0.0f};
  float width = 0.0f;
};

// A sphere's texture coordinates at the unit direction `d` from its centre
// (in its own space): pbrt's (phi, theta) about the z axis, u = phi / 2 pi
// in [0, 1), v = 1 - theta / pi (1 at +z); and sin theta, if asked (the
// generic sphere_uv of core/simd/environment-inl.h, which the wavefront's
// lanes run too).
vec2 sphere_uv(const vec3& d, float* sin_theta = nullptr);

class Textures {
 public:
  // Opens, scans and (for sRGB) decodes every image. `cache_mb` bounds
  // OIIO's tile cache. Throws InputError naming the image's `where` and the
  // problem; SystemError when a temporary file cannot be written.
  Textures(std::span<const TextureImage> images, float cache_mb);
  ~Textures();
  Textures(const Textures&) = delete;
  Textures& operator=(const Textures&) = delete;

  std::size_t size() const { return images_.size(); }
  int channels(std::uint32_t image) const { return images_[image].channels; }
  // Where channel `c` (0..3: R, G, B, A) of `image` is stored: a grey image
  // (one channel, or grey and alpha) reads as R = G = B = grey, as glTF
  // reads it; -1 for an alpha the image does not have (the constant 1).
  int stored_channel(std::uint32_t image, int c) const;
  // The mean of channel `c` over every texel of the finest level, decoded.
  float mean(std::uint32_t image, int c) const { return images_[image].mean[c]; }

  // scale * texel + offset, as a colour / as one number.
  Spectrum color(const TextureRef& ref, const TextureFootprint& at) const;
  float number(const TextureRef& ref, const TextureFootprint& at) const;
  // scale * texel + offset of the texel of the finest level that holds
  // `uv` (no filtering): alpha cut-outs (core/alpha.h), whose decision must
  // not depend on a footprint the BVH traversal does not know, and whose
  // edges stay where the texels put them.
  float nearest_number(const TextureRef& ref, vec2 uv) const;
  // The mean of color(ref, .) over the image's finest level.
  Spectrum mean_color(const TextureRef& ref) const;

  // The raw lookup: `n` channels from `first` (decoded, before scale and
  // offset) into `out`; bilinear over the footprint, or the nearest texel
  // of the finest level.
  void lookup(std::uint32_t image, TextureWrap wrap, int first, int n, const TextureFootprint& at, float* out,
              bool nearest = false) const;

 private:
  struct Image {
    void* handle = nullptr;  // OIIO::TextureSystem::TextureHandle
    int channels = 0;
    float mean[4] = {};
  };
  struct Oiio;
  std::unique_ptr<Oiio> oiio_;
  std::vector<Image> images_;
  std::filesystem::path temp_dir_;  // the decoded sRGB images; removed by the destructor
};

}  // namespace pathlab
