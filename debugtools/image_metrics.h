// Comparing two images: the error metrics of `pathlab diff`, their stable
// JSON, and a false-colour heatmap of the per-pixel error. Definitions and the
// JSON format: docs/diff.md.
//
// Conventions shared by every function here:
//  - A is the image under test, B the reference.
//  - A pixel is "finite" when its three channels are finite. A pixel that is
//    not finite in A or in B is left out of every metric (and of the means),
//    counted per image and located; it is never silently folded in.
//  - Every metric averages over the compared pixels and their 3 channels
//    (N = 3 * compared values), accumulated in double in pixel-major,
//    R-G-B order, so the result does not depend on anything but the inputs.
#pragma once

#include "core/image_io.h"

#include <nlohmann/json.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace pathlab {

struct PixelXY {
  int x = 0, y = 0;
  bool operator==(const PixelXY&) const = default;
};

// How many non-finite pixels one image has, and where the first ones are.
struct NonFinite {
  static constexpr std::size_t kMaxListed = 10;
  std::size_t count = 0;       // pixels with a NaN or ±Inf in any channel
  std::vector<PixelXY> first;  // the first kMaxListed of them, row-major order
};

struct ImageMetrics {
  int width = 0, height = 0;
  std::size_t pixels = 0;    // width * height
  std::size_t compared = 0;  // pixels finite in both A and B: the metrics' domain
  NonFinite nonfinite_a, nonfinite_b;

  // d = a - b per channel; means over the 3 * compared values. All NaN when
  // compared == 0.
  double mae = 0;      // mean |d|
  double mse = 0;      // mean d²
  double rmse = 0;     // sqrt(mse)
  double rel_mse = 0;  // mean d² / (b + 0.01)²
  double smape = 0;    // mean 2|d| / (|a| + |b|), 0/0 := 0; a fraction in [0, 2]
  double max_abs = 0;  // max |d|
  PixelXY max_at{-1, -1};  // the first pixel (row-major) where |d| = max_abs; (-1,-1) if none
  int max_channel = -1;    // its channel (0 R, 1 G, 2 B)

  double mean_a = 0, mean_b = 0;  // mean channel value of each image (compared pixels only)
  // 100 (mean_a - mean_b) / mean_b: 0 when the means are equal, ±Inf when
  // only mean_b is 0.
  double mean_diff_percent = 0;

  // PSNR in dB = 10 log10(peak² / mse), peak = the largest channel value of
  // the reference B over the compared pixels. +Inf when mse = 0; NaN
  // (undefined) when mse > 0 and peak <= 0.
  double psnr = 0;
  double psnr_peak = 0;
};

// Compares A against the reference B. Throws InputError if the sizes differ
// (the message gives both sizes).
ImageMetrics compare_images(const Image& a, const Image& b);

// The metrics `--metric` can check against `--tolerance`.
struct MetricInfo {
  std::string_view name;    // mae, mse, rmse, rel_mse, smape, max_abs, psnr
  bool higher_is_better;    // psnr: pass iff value >= tolerance; others: value <= tolerance
  double ImageMetrics::*field;
};
std::span<const MetricInfo> tolerance_metrics();
std::vector<std::string> tolerance_metric_names();
// Throws InputError for an unknown name, listing the known ones.
const MetricInfo& find_metric(std::string_view name);
// value <= tolerance (or >= for psnr). A NaN value never passes.
bool within_tolerance(double value, const MetricInfo& metric, double tolerance);

// {"format": "pathlab-diff", "version": 1, ...}: see docs/diff.md. Infinite
// and NaN numbers are written as null.
nlohmann::json to_json(const ImageMetrics& m);

// The number of channels stored in an image file (before read_image drops
// alpha or replicates grey). Throws InputError if it cannot be opened.
int image_channels(const std::filesystem::path& file);

// The heatmap colour scale: 8 control points of matplotlib's "inferno"
// (lightness rising monotonically from black to pale yellow), interpolated
// linearly in sRGB. t is clamped to [0, 1]. Returns 8-bit sRGB codes.
std::array<std::uint8_t, 3> heatmap_colour(double t);
inline constexpr std::array<std::uint8_t, 3> kHeatmapNonFinite = {255, 0, 255};  // magenta

// The per-pixel error e = mean over channels of |a - b|, mapped through
// heatmap_colour(e / scale); pixels not finite in A or B are magenta. The
// scale is the 99th percentile of e over the compared pixels (the largest e
// if that is 0, and 0 if every e is 0, when the whole map is the colour of
// 0); it is stored in *scale. The returned image holds *linear* values that
// write_png(file, image, 0) turns back into exactly those sRGB codes.
// Throws InputError if the sizes differ.
Image error_heatmap(const Image& a, const Image& b, double* scale);

}  // namespace pathlab
