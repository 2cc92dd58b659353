// Image files: float32 OpenEXR with render metadata, and tone-mapped sRGB
// PNG, both through OpenImageIO. Every write goes to a temporary file in the
// destination folder and is renamed into place, so a crash or a failure never
// leaves a half-written image under the requested name.
#pragma once

#include "core/math.h"

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace pathlab {

// An RGB float image, row-major, top row first.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<vec3> pixels;

  Image() = default;
  Image(int w, int h) : width(w), height(h), pixels(static_cast<std::size_t>(w) * h, vec3(0.0f)) {}
  vec3& at(int x, int y) { return pixels[static_cast<std::size_t>(y) * width + x]; }
  const vec3& at(int x, int y) const { return pixels[static_cast<std::size_t>(y) * width + x]; }
};

// String metadata written into the EXR header as "pathlab:<key>".
using ImageMetadata = std::vector<std::pair<std::string, std::string>>;

// Throws InputError if `file` is a folder, or if the nearest existing
// folder on its path is not a folder or not writable. Creates nothing (a
// probe file only, removed at once): write_via_temp_file makes the missing
// folders when there is something to write. Called before a render so that
// a bad `-o` fails in a second, not after an hour.
void ensure_writable(const std::filesystem::path& file);
// The file's extension in lower case (".exr" for "out.EXR"), for deciding
// what to write.
std::string lower_extension(const std::filesystem::path& file);

// Creates `file`'s folder (and its parents) if missing: just before the
// first write into it. Throws InputError if it cannot.
void make_output_folder(const std::filesystem::path& file);

// Calls write(temp) with a hidden temporary path in `file`'s folder (same
// extension), then renames the temporary file to `file`. If `write` throws or
// the rename fails the temporary file is removed, so `file` is either the
// complete new file or untouched. Throws InputError if `file` is not
// writable (ensure_writable), SystemError "<file>: cannot write <what>: ..."
// if the rename fails, and whatever `write` throws.
void write_via_temp_file(const std::filesystem::path& file, std::string_view what,
                         const std::function<void(const std::filesystem::path& temp)>& write);

// Writes float32 RGB OpenEXR. Throws InputError / SystemError on failure,
// leaving no file behind.
void write_exr(const std::filesystem::path& file, const Image& image, const ImageMetadata& metadata);

// One named channel of a multi-layer EXR ("R", "albedo.G", "depth.Z"):
// width * height floats, row-major, top row first.
struct ExrChannel {
  std::string name;
  std::vector<float> values;
};

// Writes float32 OpenEXR with any number of named channels (all of
// width x height). Throws as write_exr.
void write_exr_channels(const std::filesystem::path& file, int width, int height, const std::vector<ExrChannel>& channels,
                        const ImageMetadata& metadata);

// Writes an 8-bit sRGB PNG: radiance scaled by 2^exposure, clamped to [0,1],
// encoded with the sRGB transfer curve. NaN pixels become magenta so that
// they cannot hide (the renderer never produces them; diff inputs might).
void write_png(const std::filesystem::path& file, const Image& image, float exposure = 0.0f);
// write_png for the PNG that goes beside the EXR `exr` already written: the
// two are one result, so if the PNG cannot be written the EXR is removed
// before the error goes on.
void write_png_beside(const std::filesystem::path& exr, const std::filesystem::path& png, const Image& image,
                      float exposure);

// Writes 8-bit RGB bytes (already encoded, row-major, top row first) as a
// PNG, e.g. a screenshot.
void write_png_rgb8(const std::filesystem::path& file, int width, int height, const std::vector<std::uint8_t>& rgb);

// Reads the first three channels of any image OpenImageIO understands as
// linear float RGB (a one-channel image is replicated). Throws InputError.
Image read_image(const std::filesystem::path& file, ImageMetadata* metadata = nullptr);

// The sRGB opto-electronic transfer function (IEC 61966-2-1) on [0,1], and
// its inverse (both clamp their argument to [0,1]).
float linear_to_srgb(float v);
float srgb_to_linear(float v);

}  // namespace pathlab
