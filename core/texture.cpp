#include "core/texture.h"

#include "core/error.h"
#include "core/simd/width1.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>
#include <OpenImageIO/texture.h>

#include <atomic>
#include <cmath>
#include <sstream>
#include <unistd.h>

namespace pathlab {

vec2 sphere_uv(const vec3& d, float* sin_theta) {
  using namespace width1;
  F u, v, s;
  generic::sphere_uv(kScalar, lanes(d), u, v, s);
  if (sin_theta != nullptr) *sin_theta = s.raw;
  return vec2(u.raw, v.raw);
}

const char* texture_wrap_name(TextureWrap wrap) {
  switch (wrap) {
    case TextureWrap::Repeat: return "repeat";
    case TextureWrap::Clamp: return "clamp";
    case TextureWrap::Black: return "black";
    case TextureWrap::Mirror: return "mirror";
  }
  return "?";
}

std::optional<TextureWrap> parse_texture_wrap(std::string_view name) {
  if (name == "repeat" || name == "periodic") return TextureWrap::Repeat;
  if (name == "clamp") return TextureWrap::Clamp;
  if (name == "black") return TextureWrap::Black;
  if (name == "mirror") return TextureWrap::Mirror;
  return std::nullopt;
}

const char* texture_color_space_name(TextureColorSpace space) {
  return space == TextureColorSpace::Srgb ? "srgb" : "linear";
}

std::optional<TextureColorSpace> parse_texture_color_space(std::string_view name) {
  if (name == "srgb") return TextureColorSpace::Srgb;
  if (name == "linear") return TextureColorSpace::Linear;
  return std::nullopt;
}

const char* texture_filter_name(TextureFilter filter) { return filter == TextureFilter::Cone ? "cone" : "point"; }

std::optional<TextureFilter> parse_texture_filter(std::string_view name) {
  if (name == "cone") return TextureFilter::Cone;
  if (name == "point") return TextureFilter::Point;
  return std::nullopt;
}

namespace {

// The sRGB transfer curve's inverse (IEC 61966-2-1), in double so that
// every 8-bit code decodes to the float nearest the exact value.
float srgb_to_linear(float c) {
  const double v = c;
  return static_cast<float>(v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4));
}

OIIO::TextureOpt::Wrap oiio_wrap(TextureWrap wrap) {
  switch (wrap) {
    case TextureWrap::Repeat: return OIIO::TextureOpt::WrapPeriodic;
    case TextureWrap::Clamp: return OIIO::TextureOpt::WrapClamp;
    case TextureWrap::Black: return OIIO::TextureOpt::WrapBlack;
    case TextureWrap::Mirror: return OIIO::TextureOpt::WrapMirror;
  }
  return OIIO::TextureOpt::WrapPeriodic;
}

// A fresh folder for one Textures object's decoded images.
std::filesystem::path make_temp_dir() {
  static std::atomic<unsigned> counter{0};
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("pathlab-textures-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw SystemError("cannot create the folder " + dir.string() + " for decoded textures: " + ec.message());
  return dir;
}

}  // namespace

struct Textures::Oiio {
  OIIO::TextureSystem* ts = nullptr;
  ~Oiio() {
    if (ts) OIIO::TextureSystem::destroy(ts);
  }
};

Textures::Textures(std::span<const TextureImage> images, float cache_mb) : oiio_(std::make_unique<Oiio>()) {
  oiio_->ts = OIIO::TextureSystem::create(false);  // our own cache, not OIIO's process-wide one
  OIIO::TextureSystem& ts = *oiio_->ts;
  ts.attribute("max_memory_MB", cache_mb);
  ts.attribute("unassociatedalpha", 1);  // texels as stored: never premultiplied by alpha
  for (const TextureImage& image : images) {
    const std::string name = image.file.string();
    auto fail = [&](const std::string& problem) -> void {
      throw InputError(image.where + ": texture " + name + ": " + problem);
    };
    if (!std::filesystem::is_regular_file(image.file)) fail("no such file");
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = OIIO::ImageInput::open(name, &config);
    if (!in) fail("cannot read it (" + OIIO::geterror() + ")");
    const OIIO::ImageSpec spec = in->spec();
    if (spec.nchannels < 1 || spec.nchannels > 4)
      fail("has " + std::to_string(spec.nchannels) + " channels (1 to 4 are supported: grey, grey+alpha, RGB, RGBA)");
    if (spec.depth > 1) fail("is a volume (3D) image");
    // A tiled, MIP-mapped file (a .tx from maketx) is read in place, a tile
    // at a time, however large. Anything else is converted once, below: an
    // untiled image would enter OpenImageIO's cache whole, and one larger
    // than ten times the cache trips an assertion that aborts the process
    // in Debian's build (ImageCache::check_max_mem).
    const bool tiled_mipmap = spec.tile_width > 0 && in->seek_subimage(0, 1);
    if (!in->seek_subimage(0, 0)) fail("cannot read it (" + in->geterror() + ")");
    const std::size_t w = static_cast<std::size_t>(spec.width), h = static_cast<std::size_t>(spec.height);
    const std::size_t nc = static_cast<std::size_t>(spec.nchannels);
    std::vector<float> texels(w * h * nc);
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, texels.data()))
      fail("cannot read its pixels (" + in->geterror() + ")");
    in->close();
    // Refuse what no filter could average: the first texel that is not a
    // finite number, named (x, y from the top left, channel).
    for (std::size_t i = 0; i < texels.size(); ++i)
      if (!std::isfinite(texels[i])) {
        std::ostringstream m;
        const std::size_t px = i / nc;
        m << "texel (" << px % w << ", " << px / w << ") channel " << i % nc << " is "
          << (std::isnan(texels[i]) ? "NaN" : "infinite") << " (x, y from the top-left corner)";
        fail(m.str());
      }
    // Colour channels: the first three, or the one grey channel; alpha is
    // always linear.
    const std::size_t colour = nc >= 3 ? 3 : 1;
    if (image.colorspace == TextureColorSpace::Srgb)
      for (std::size_t i = 0; i < texels.size(); ++i)
        if (i % nc < colour) texels[i] = srgb_to_linear(texels[i]);
    Image out;
    out.channels = spec.nchannels;
    double sum[4] = {};
    for (std::size_t i = 0; i < texels.size(); ++i) sum[i % nc] += texels[i];
    for (std::size_t c = 0; c < nc; ++c) out.mean[c] = static_cast<float>(sum[c] / static_cast<double>(w * h));

    std::string source = name;
    if (image.colorspace == TextureColorSpace::Srgb || !tiled_mipmap) {
      if (temp_dir_.empty()) temp_dir_ = make_temp_dir();
      source = (temp_dir_ / (std::to_string(images_.size()) + ".tx")).string();
      OIIO::ImageSpec decoded(spec.width, spec.height, spec.nchannels, OIIO::TypeDesc::FLOAT);
      const OIIO::ImageBuf buf(decoded, texels.data());
      OIIO::ImageSpec tx;
      tx.format = OIIO::TypeDesc::FLOAT;
      if (!OIIO::ImageBufAlgo::make_texture(OIIO::ImageBufAlgo::MakeTxTexture, buf, source, tx))
        throw SystemError(image.where + ": texture " + name + ": cannot write its tiled, MIP-mapped copy " + source + ": " +
                          OIIO::geterror());
    }
    out.handle = ts.get_texture_handle(OIIO::ustring(source));
    if (out.handle == nullptr || !ts.good(static_cast<OIIO::TextureSystem::TextureHandle*>(out.handle)))
      fail("OpenImageIO's texture system cannot open it (" + ts.geterror() + ")");
    images_.push_back(out);
  }
}

Textures::~Textures() {
  oiio_.reset();  // closes the files before they go
  if (!temp_dir_.empty()) {
    std::error_code ec;
    std::filesystem::remove_all(temp_dir_, ec);
  }
}

void Textures::lookup(std::uint32_t image, TextureWrap wrap, int first, int n, const TextureFootprint& at,
                      float* out, bool nearest) const {
  // Debian's OpenImageIO keeps its assertions: channels past the image's
  // would abort the process inside OIIO, so callers map them first.
  if (first < 0 || first + n > images_[image].channels)
    throw std::logic_error("Textures::lookup: channels " + std::to_string(first) + ".." + std::to_string(first + n) +
                           " of an image with " + std::to_string(images_[image].channels));
  OIIO::TextureSystem& ts = *oiio_->ts;
  OIIO::TextureOpt opt;
  opt.firstchannel = first;
  opt.swrap = opt.twrap = oiio_wrap(wrap);
  // Not OIIO's default "smart bicubic": the same kernel at every level.
  opt.interpmode = nearest ? OIIO::TextureOpt::InterpClosest : OIIO::TextureOpt::InterpBilinear;
  opt.fill = 0.0f;
  // An isotropic footprint: the cone's width along both image axes.
  const float d = at.width;
  ts.texture(static_cast<OIIO::TextureSystem::TextureHandle*>(images_[image].handle), ts.get_perthread_info(), opt,
             at.uv.x, 1.0f - at.uv.y, d, 0.0f, 0.0f, d, n, out);
}

Spectrum Textures::color(const TextureRef& ref, const TextureFootprint& at) const {
  float v[3];
  if (images_[ref.image].channels < 3) {
    lookup(ref.image, ref.wrap, 0, 1, at, v);
    v[1] = v[2] = v[0];
  } else {
    lookup(ref.image, ref.wrap, ref.channel, 3, at, v);
  }
  return ref.scale * Spectrum(v[0], v[1], v[2]) + ref.offset;
}

// Channel c of a grey image (one channel, or grey and alpha) as an RGBA
// image would have it, as glTF reads such images: R = G = B = grey, and
// alpha the second channel or 1. -1: the constant 1.
int Textures::stored_channel(std::uint32_t image, int c) const {
  const int channels = images_[image].channels;
  if (c < channels && channels >= 3) return c;
  if (channels >= 3) return -1;  // alpha of an RGB image
  if (c < 3) return 0;
  return channels == 2 ? 1 : -1;
}

float Textures::number(const TextureRef& ref, const TextureFootprint& at) const {
  const int c = stored_channel(ref.image, ref.channel);
  float v = 1.0f;
  if (c >= 0) lookup(ref.image, ref.wrap, c, 1, at, &v);
  return ref.scale.x * v + ref.offset.x;
}

float Textures::nearest_number(const TextureRef& ref, vec2 uv) const {
  const int c = stored_channel(ref.image, ref.channel);
  if (c < 0) return ref.scale.x + ref.offset.x;  // the alpha of an image without one: 1
  float v = 0.0f;
  lookup(ref.image, ref.wrap, c, 1, {uv, 0.0f}, &v, true);
  return ref.scale.x * v + ref.offset.x;
}

Spectrum Textures::mean_color(const TextureRef& ref) const {
  const Image& im = images_[ref.image];
  const Spectrum m = im.channels < 3 ? Spectrum(im.mean[0])
                                     : Spectrum(im.mean[ref.channel], im.mean[ref.channel + 1], im.mean[ref.channel + 2]);
  return ref.scale * m + ref.offset;
}

}  // namespace pathlab
