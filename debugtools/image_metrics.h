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
#include <optional>
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
  double max_value_a = 0, max_value_b = 0;  // A's and B's value there

  double mean_a = 0, mean_b = 0;  // mean channel value of each image (compared pixels only)
  // 100 (mean_a - mean_b) / mean_b: 0 when the means are equal, ±Inf when
  // only mean_b is 0.
  double mean_diff_percent = 0;

  // PSNR in dB = 10 log10(peak² / mse), peak = the largest channel value of
  // the reference B over the compared pixels. +Inf when mse = 0; NaN
  // (undefined) when mse > 0 and peak <= 0.
  double psnr = 0;
  double psnr_peak = 0;

  // Locating differences. A pixel's error is e = max over its channels of
  // |d|; it is "over" the threshold when e > threshold (so threshold 0
  // counts every pixel that differs at all).
  double threshold = 0;
  std::size_t over = 0;      // compared pixels with e > threshold
  double over_fraction = 0;  // over / compared (NaN when compared == 0)
  PixelXY first_over{-1, -1};  // the first of them in row order (top row first); (-1,-1) if none
  int first_over_channel = -1; // its channel with the largest |d| (the first such)
  double first_over_a = 0, first_over_b = 0;  // A's and B's value there
};

// Compares A against the reference B. Throws InputError if the sizes differ
// (the message gives both sizes), or if threshold is negative or NaN.
ImageMetrics compare_images(const Image& a, const Image& b, double threshold = 0.0);

// ---------------------------------------------------------------- statistics
// The statistical mode of `pathlab diff`, when both images carry the
// variance of their pixel means (`render --aov variance`: variance.R/G/B).
// Per pixel and channel z = d / sigma with
//   sigma^2 = max over the 3x3 neighbourhood of (var_A + var_B) + threshold^2,
// the neighbourhood maximum as `pathlab check` takes it (a pixel whose few
// samples all missed a light estimates its own variance as ~0), and the
// threshold a floor so that rounding-level differences between noiseless
// pixels are never significant. A pixel channel fails when |z| exceeds the
// Šidák threshold for a family-wise false-alarm rate alpha over all
// 3 x compared tests. Channels of one pixel are positively correlated (the
// same paths) and the bilinear filter correlates neighbours; Šidák stays
// conservative under such positive dependence. The mean difference per
// channel is tested too (Šidák over the 3 channels): its standard error
// sqrt(sum sigma^2) / compared is inflated by 3 when either image was
// filtered bilinearly, whose shared samples make neighbouring errors
// correlated (the same factor as check).
struct PixelZ {
  PixelXY at{-1, -1};
  int channel = -1;
  double z = 0, a = 0, b = 0, sigma = 0;
};
struct StatisticalDiff {
  double alpha = 0;
  std::size_t tests = 0;     // 3 x compared
  double z_threshold = 0;    // per test, two-sided
  std::size_t failing = 0;   // tests with |z| > z_threshold
  std::size_t failing_pixels = 0;
  PixelZ worst;              // the largest |z| (the first such, row order)
  PixelZ first_failing;      // the first failing test in row order (channel order within a pixel)
  bool correlated = false;   // an input was filtered bilinearly: the bias test's error inflated 3x
  int bias_channel = 0;      // the channel with the largest |bias z|
  double bias = 0, bias_se = 0, bias_z = 0, bias_threshold = 0;
  bool pixels_pass = true, bias_pass = true, pass = true;
  std::vector<double> pixel_z;  // per pixel, max over channels |z|; NaN where not compared
};
// var_a, var_b: variance of the mean of each pixel of A and B. Throws
// InputError if the sizes differ or alpha is not in (0, 1).
StatisticalDiff statistical_diff(const Image& a, const Image& b, const Image& var_a, const Image& var_b, double alpha,
                                 double threshold, bool correlated);
nlohmann::json to_json(const StatisticalDiff& s);

// The variance layer (variance.R, .G, .B) of an EXR, or nothing if it has
// none. Throws InputError if the file cannot be read or has only part of it.
std::optional<Image> read_variance_layer(const std::filesystem::path& file);

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
// alpha or replicates grey), not counting those of named layers
// ("variance.R", "albedo.G": the AOVs of `render --aov`). Throws InputError if it cannot be opened.
int image_channels(const std::filesystem::path& file);

// The heatmap colour scale: 8 control points of matplotlib's "inferno"
// (lightness rising monotonically from black to pale yellow), interpolated
// linearly in sRGB. t is clamped to [0, 1]. Returns 8-bit sRGB codes.
std::array<std::uint8_t, 3> heatmap_colour(double t);
inline constexpr std::array<std::uint8_t, 3> kHeatmapNonFinite = {255, 0, 255};  // magenta

inline constexpr std::array<std::uint8_t, 3> kHeatmapNeutral = {128, 128, 128};  // mid grey: at or below the threshold

// The heatmap of a per-pixel quantity (row-major, NaN = not finite in A or
// B): pixels at or below `neutral` are mid grey (not on the colour scale),
// NaN magenta, the others heatmap_colour(t) with
//   t = (v - lo) / (hi - lo)               (linear), or
//   t = log(v / lo) / log(hi / lo)         (log; lo > 0),
// clamped to [0, 1]. Below the map a legend is drawn: the colour bar with
// lo, the middle (arithmetic or geometric) and hi written under it, a
// caption naming the quantity and the scale, and swatches for the neutral
// grey and magenta. The canvas is at least kLegendMinWidth wide (the map
// sits at the top left; the rest is black).
struct HeatmapRange {
  double lo = 0, hi = 0;
  bool log = false;
  double neutral = -1;  // values <= neutral are grey; < 0: none
};
inline constexpr int kLegendHeight = 44;
inline constexpr int kLegendMinWidth = 200;
Image draw_heatmap(const std::vector<double>& values, int width, int height, const HeatmapRange& range,
                   const std::string& caption);
// The default range of a quantity: hi = the 99th percentile (nearest rank:
// the ceil(0.99 n)-th smallest) of the values above `neutral` (the largest
// if that is not above lo; lo + 1 if there are none, when the map is all
// grey); lo = 0 for a linear scale, and for a log scale `neutral` if > 0,
// else the smallest positive value (hi / 1000 if that is not below hi).
HeatmapRange default_heatmap_range(const std::vector<double>& values, bool log, double neutral);
// The per-pixel error max over channels |a - b|, NaN where not finite in A or B.
std::vector<double> pixel_errors(const Image& a, const Image& b);

// Text in a 5x7 pixel font (digits, '.', '+', '-', 'e' and the letters and
// signs the legend uses; anything else is blank), scale x scale pixels per
// font pixel, with its top left at (x, y), clipped to the image. Each
// character advances 6 * scale. The legend draws with it; tests compare
// against it.
void draw_text(Image& image, int x, int y, const std::string& text, const vec3& colour, int scale = 1);
int text_width(const std::string& text, int scale = 1);
// "%.3g" of a legend number.
std::string legend_number(double v);

}  // namespace pathlab
