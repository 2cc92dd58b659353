// Image files through OpenImageIO 2.4. See image_io.h for the contract.
#include "core/image_io.h"

#include "core/error.h"
#include "core/temp_files.h"

#include <OpenImageIO/imageio.h>

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <string_view>
#include <system_error>

namespace pathlab {
namespace fs = std::filesystem;

namespace {

constexpr std::string_view kMetadataPrefix = "pathlab:";

// Process-wide counter so that concurrent writes (and probes) from several
// threads of one process never pick the same temporary name.
std::atomic<unsigned> g_temp_counter{0};

std::string unique_suffix() {
  return std::to_string(::getpid()) + "-" + std::to_string(g_temp_counter.fetch_add(1));
}

// The folder a file lives in; "." for a bare file name.
fs::path folder_of(const fs::path& file) {
  return file.parent_path().empty() ? fs::path(".") : file.parent_path();
}

// OIIO error texts may span lines or end with a newline; the user gets one line.
std::string one_line(std::string text) {
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text.empty() ? std::string("unknown OpenImageIO error") : text;
}

// Writes `spec`-shaped `pixels` of type `type` with the OIIO writer `format`
// to a hidden sibling of `file`, then renames it into place.
void write_atomically(const fs::path& file, const char* format, const OIIO::ImageSpec& spec,
                      OIIO::TypeDesc type, const void* pixels) {
  const auto fail = [&](const std::string& reason) {
    throw SystemError(file.string() + ": cannot write image: " + one_line(reason));
  };
  write_via_temp_file(file, "image", [&](const fs::path& temp) {
    // Created by format name, so write_exr always writes EXR whatever the
    // extension of `file`.
    std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create(format);
    if (!out) fail(OIIO::geterror());
    if (!out->open(temp.string(), spec)) fail(out->geterror());
    if (!out->write_image(type, pixels)) fail(out->geterror());
    if (!out->close()) fail(out->geterror());
  });
}

void check_shape(const fs::path& file, const Image& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.pixels.size() != static_cast<std::size_t>(image.width) * image.height) {
    throw SystemError(file.string() + ": cannot write image: invalid image size " +
                      std::to_string(image.width) + "x" + std::to_string(image.height));
  }
}

OIIO::ImageSpec exr_spec(int width, int height, std::vector<std::string> channels, const ImageMetadata& metadata) {
  OIIO::ImageSpec spec(width, height, static_cast<int>(channels.size()), OIIO::TypeFloat);
  spec.channelnames = std::move(channels);
  spec.attribute("compression", "zip");
  for (const auto& [key, value] : metadata) {
    spec.attribute(std::string(kMetadataPrefix) + key, value);
  }
  return spec;
}

}  // namespace

void make_output_folder(const fs::path& file) {
  std::error_code ec;
  const fs::path folder = folder_of(file);
  fs::create_directories(folder, ec);
  if (ec) throw InputError(file.string() + ": cannot write output: cannot create folder " + folder.string() + ": " + ec.message());
}

void write_via_temp_file(const fs::path& file, std::string_view what,
                         const std::function<void(const fs::path& temp)>& write) {
  ensure_writable(file);
  make_output_folder(file);
  // Keep the real extension: whatever later inspects the temporary name
  // (OIIO, VTK, a file manager) sees the right type.
  const std::string prefix = "." + file.stem().string() + ".tmp-";
  // What a killed writer of this file left behind (kill -9 cannot be caught).
  remove_stale_temp_files(folder_of(file), prefix);
  const fs::path temp = folder_of(file) / (prefix + unique_suffix() + file.extension().string());
  // A signal that ends the process removes it (apps/cli/interrupt.cpp).
  const TempFileRegistration registered(temp);
  bool committed = false;
  // Removes the temporary file unless the write was committed, also when
  // `write` throws.
  const auto cleanup = [&] {
    if (committed) return;
    std::error_code ignored;
    fs::remove(temp, ignored);
  };
  try {
    write(temp);
  } catch (...) {
    cleanup();
    throw;
  }
  std::error_code ec;
  fs::rename(temp, file, ec);
  if (ec) {
    cleanup();
    throw SystemError(file.string() + ": cannot write " + std::string(what) + ": cannot move " + temp.string() +
                      " into place: " + ec.message());
  }
  committed = true;
}

void ensure_writable(const fs::path& file) {
  const auto fail = [&](const std::string& reason) {
    throw InputError(file.string() + ": cannot write output: " + reason);
  };
  if (!file.has_filename()) fail("not a file name");
  std::error_code ec;
  if (fs::is_directory(file, ec)) fail("is a folder");

  // The folder is made only when there is something to write in it
  // (write_via_temp_file): a render that fails leaves no empty folder. Here
  // its nearest existing ancestor must be a folder we may write in.
  fs::path folder = folder_of(file);
  while (!fs::exists(folder, ec) && folder.has_parent_path() && folder.parent_path() != folder)
    folder = folder.parent_path();
  if (!fs::exists(folder, ec)) folder = ".";
  if (!fs::is_directory(folder, ec)) fail(folder.string() + " is not a folder");

  // Probe by creating a file: access(2) says yes to root even on read-only
  // mounts and pseudo file systems such as /proc.
  const fs::path probe = folder / (".pathlab-probe-" + unique_suffix());
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) {
    fail("folder " + folder.string() + " is not writable: " +
         std::generic_category().message(errno));
  }
  ::close(fd);
  fs::remove(probe, ec);
}


void write_exr(const fs::path& file, const Image& image, const ImageMetadata& metadata) {
  check_shape(file, image);
  const OIIO::ImageSpec spec = exr_spec(image.width, image.height, {"R", "G", "B"}, metadata);
  // vec3 is three packed floats (checked below), so the pixel vector is
  // already the interleaved RGB buffer OIIO wants.
  static_assert(sizeof(vec3) == 3 * sizeof(float));
  write_atomically(file, "openexr", spec, OIIO::TypeFloat, image.pixels.data());
}

void write_exr_channels(const fs::path& file, int width, int height, const std::vector<ExrChannel>& channels,
                        const ImageMetadata& metadata) {
  const std::size_t pixels = static_cast<std::size_t>(std::max(width, 0)) * static_cast<std::size_t>(std::max(height, 0));
  std::vector<std::string> names;
  for (const ExrChannel& c : channels) {
    if (c.values.size() != pixels || pixels == 0)
      throw SystemError(file.string() + ": cannot write image: channel " + c.name + " does not hold " +
                        std::to_string(width) + "x" + std::to_string(height) + " values");
    names.push_back(c.name);
  }
  if (names.empty()) throw SystemError(file.string() + ": cannot write image: no channels");
  const std::size_t n = channels.size();
  std::vector<float> interleaved(pixels * n);
  for (std::size_t c = 0; c < n; ++c)
    for (std::size_t i = 0; i < pixels; ++i) interleaved[i * n + c] = channels[c].values[i];
  write_atomically(file, "openexr", exr_spec(width, height, std::move(names), metadata), OIIO::TypeFloat,
                   interleaved.data());
}

void write_png_rgb8(const fs::path& file, int width, int height, const std::vector<std::uint8_t>& rgb) {
  if (width <= 0 || height <= 0 || rgb.size() != static_cast<std::size_t>(width) * height * 3)
    throw SystemError(file.string() + ": cannot write image: invalid image size " + std::to_string(width) + "x" +
                      std::to_string(height));
  OIIO::ImageSpec spec(width, height, 3, OIIO::TypeUInt8);
  spec.channelnames = {"R", "G", "B"};
  spec.attribute("oiio:ColorSpace", "sRGB");  // tags the PNG with an sRGB chunk
  write_atomically(file, "png", spec, OIIO::TypeUInt8, rgb.data());
}

void write_png(const fs::path& file, const Image& image, float exposure) {
  check_shape(file, image);
  const float scale = std::exp2(exposure);
  std::vector<std::uint8_t> bytes(image.pixels.size() * 3);
  for (std::size_t i = 0; i < image.pixels.size(); ++i) {
    const vec3& p = image.pixels[i];
    std::uint8_t* out = &bytes[3 * i];
    if (std::isnan(p.x) || std::isnan(p.y) || std::isnan(p.z)) {
      out[0] = 255, out[1] = 0, out[2] = 255;  // magenta: impossible to miss
      continue;
    }
    for (int c = 0; c < 3; ++c) {
      const float v = linear_to_srgb(std::clamp(p[c] * scale, 0.0f, 1.0f));
      out[c] = static_cast<std::uint8_t>(v * 255.0f + 0.5f);
    }
  }
  write_png_rgb8(file, image.width, image.height, bytes);
}

Image read_image(const fs::path& file, ImageMetadata* metadata) {
  const auto fail = [&](const std::string& reason) {
    throw InputError(file.string() + ": cannot read image: " + one_line(reason));
  };
  std::error_code ec;
  const fs::file_status status = fs::status(file, ec);
  if (!fs::exists(status)) fail("no such file");
  if (fs::is_directory(status)) fail("is a folder");

  std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(file.string());
  if (!in) fail(OIIO::geterror());
  const OIIO::ImageSpec spec = in->spec();  // subimage 0 after open
  if (spec.nchannels == 2) fail("has 2 channels (expected 1, 3 or more)");
  if (spec.nchannels < 1 || spec.width <= 0 || spec.height <= 0 || spec.depth != 1) {
    fail("unsupported image shape");
  }

  const int channels = spec.nchannels == 1 ? 1 : 3;
  Image image(spec.width, spec.height);
  std::vector<float> buffer(image.pixels.size() * channels);
  if (!in->read_image(0, 0, 0, channels, OIIO::TypeFloat, buffer.data())) fail(in->geterror());
  in->close();
  for (std::size_t i = 0; i < image.pixels.size(); ++i) {
    image.pixels[i] = channels == 1 ? vec3(buffer[i])
                                    : vec3(buffer[3 * i], buffer[3 * i + 1], buffer[3 * i + 2]);
  }

  // Note: OIIO 2.4's EXR reader skips string attributes whose value is
  // empty, so a ("key", "") pair written by write_exr does not come back.
  if (metadata != nullptr) {
    metadata->clear();
    for (const OIIO::ParamValue& attr : spec.extra_attribs) {
      const std::string& name = attr.name().string();
      if (attr.type() == OIIO::TypeString && attr.nvalues() == 1 &&
          name.compare(0, kMetadataPrefix.size(), kMetadataPrefix) == 0) {
        metadata->emplace_back(name.substr(kMetadataPrefix.size()),
                               attr.get<OIIO::ustring>().string());
      }
    }
  }
  return image;
}

float linear_to_srgb(float v) {
  // IEC 61966-2-1: linear segment below 0.0031308, offset power curve above.
  // Evaluated in double so that 1 maps to exactly 1.
  const double x = std::clamp(static_cast<double>(v), 0.0, 1.0);
  if (x <= 0.0031308) return static_cast<float>(12.92 * x);
  return static_cast<float>(1.055 * std::pow(x, 1.0 / 2.4) - 0.055);
}

float srgb_to_linear(float v) {
  const double x = std::clamp(static_cast<double>(v), 0.0, 1.0);
  if (x <= 0.04045) return static_cast<float>(x / 12.92);
  return static_cast<float>(std::pow((x + 0.055) / 1.055, 2.4));
}

void write_png_beside(const std::filesystem::path& exr, const std::filesystem::path& png, const Image& image,
                      float exposure) {
  try {
    write_png(png, image, exposure);
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(exr, ignored);
    throw;
  }
}

std::string lower_extension(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

}  // namespace pathlab
