// pathlab diff: the metrics (exact values on inputs whose float arithmetic is
// exact), non-finite pixels, bad input, tolerance exit codes, stable JSON and
// the heatmap. The CLI runs in-process.
#include "tests/cli_util.h"
#include "core/error.h"
#include "core/image_io.h"
#include "debugtools/image_metrics.h"

#include <OpenImageIO/imageio.h>
#include "tests/temp_dir.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include <cmath>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace pathlab {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

constexpr float kNaNf = std::numeric_limits<float>::quiet_NaN();

using test::CliResult;
using test::run_cli;

// Channel values k/16 in [0, 2): sums, differences and means of these are
// exact in float and double, so the expected metrics below are exact.
Image ramp(int w, int h) {
  Image image(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      image.at(x, y) = vec3(static_cast<float>((x + 3 * y) % 32) / 16.0f, static_cast<float>((2 * x + y) % 32) / 16.0f,
                            static_cast<float>((x * y + 1) % 32) / 16.0f);
  return image;
}

Image offset(const Image& image, float c) {
  Image out = image;
  for (vec3& p : out.pixels) p += vec3(c);
  return out;
}

// An 8-bit code from a PNG value read back as float.
int code(float v) { return static_cast<int>(std::lround(v * 255.0f)); }

class DiffTest : public test::TempDirTest {
 protected:
  std::string exr(const std::string& name, const Image& image) const {
    const fs::path file = dir_ / (name + ".exr");
    write_exr(file, image, {});
    return file.string();
  }
};

TEST_F(DiffTest, HandComputedMetrics) {
  Image a(2, 1), b(2, 1);
  a.at(0, 0) = vec3(1.0f, 0.0f, 0.5f);
  a.at(1, 0) = vec3(0.0f, 0.0f, 2.0f);
  b.at(0, 0) = vec3(0.5f, 0.0f, 0.5f);
  b.at(1, 0) = vec3(0.0f, 1.0f, 1.0f);
  const ImageMetrics m = compare_images(a, b);
  EXPECT_EQ(m.pixels, 2u);
  EXPECT_EQ(m.compared, 2u);
  EXPECT_DOUBLE_EQ(m.mae, 2.5 / 6.0);
  EXPECT_DOUBLE_EQ(m.mse, 2.25 / 6.0);
  EXPECT_DOUBLE_EQ(m.rmse, std::sqrt(2.25 / 6.0));
  EXPECT_DOUBLE_EQ(m.rel_mse, (0.25 / (0.51 * 0.51) + 2.0 / (1.01 * 1.01)) / 6.0);
  EXPECT_DOUBLE_EQ(m.smape, 5.0 / 9.0);  // 2/3 + 0 (0/0) + 0 + 0 (0/0) + 2 + 2/3, over 6
  EXPECT_EQ(m.max_abs, 1.0);
  EXPECT_EQ(m.max_at, (PixelXY{1, 0}));
  EXPECT_EQ(m.max_channel, 1);
  EXPECT_DOUBLE_EQ(m.mean_a, 3.5 / 6.0);
  EXPECT_DOUBLE_EQ(m.mean_b, 3.0 / 6.0);
  EXPECT_DOUBLE_EQ(m.mean_diff_percent, 100.0 / 6.0);
  EXPECT_EQ(m.psnr_peak, 1.0);
  EXPECT_DOUBLE_EQ(m.psnr, 10.0 * std::log10(1.0 / 0.375));
}

TEST_F(DiffTest, IdenticalImagesHaveZeroErrorAndInfinitePsnr) {
  const Image b = ramp(8, 6);
  const ImageMetrics m = compare_images(b, b);
  for (double v : {m.mae, m.mse, m.rmse, m.rel_mse, m.smape, m.max_abs, m.mean_diff_percent}) EXPECT_EQ(v, 0.0);
  EXPECT_TRUE(std::isinf(m.psnr) && m.psnr > 0);
  EXPECT_EQ(m.compared, 48u);

  const std::string fa = exr("a", b), fb = exr("b", b);
  const CliResult r = run_cli({"diff", fa, fb, "--tolerance", "0"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("pass: rmse = 0 <= tolerance 0"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("inf dB"), std::string::npos) << r.err;
  // psnr: +inf passes any tolerance; in JSON it is null.
  const CliResult p = run_cli({"diff", fa, fb, "--json", "--metric", "psnr", "--tolerance", "1000"});
  EXPECT_EQ(p.code, 0) << p.err;
  const json j = json::parse(p.out);
  EXPECT_TRUE(j["metrics"]["psnr"].is_null());
  EXPECT_EQ(j["metrics"]["mse"], 0.0);
}

TEST_F(DiffTest, ConstantOffsetGivesExactMetrics) {
  const float c = 0.25f;
  const Image b = ramp(8, 6);
  const Image a = offset(b, c);
  const ImageMetrics m = compare_images(a, b);
  EXPECT_EQ(m.mae, 0.25);
  EXPECT_EQ(m.mse, 0.0625);
  EXPECT_EQ(m.rmse, 0.25);
  EXPECT_EQ(m.max_abs, 0.25);
  EXPECT_EQ(m.max_at, (PixelXY{0, 0}));

  double sum_b = 0, rel = 0, smape = 0, peak = 0;
  for (const vec3& p : b.pixels) {
    for (int k = 0; k < 3; ++k) {
      const double vb = p[k];
      sum_b += vb;
      rel += 0.0625 / ((vb + 0.01) * (vb + 0.01));
      smape += 2.0 * 0.25 / (vb + 0.25 + vb);
      peak = std::max(peak, vb);
    }
  }
  const double n = 3.0 * 48;
  // The sums are exact (multiples of 1/16); only the division by n rounds.
  const double mean_b = sum_b / n, mean_a = (sum_b + 0.25 * n) / n;
  EXPECT_EQ(m.mean_b, mean_b);
  EXPECT_EQ(m.mean_a, mean_a);
  EXPECT_EQ(m.mean_diff_percent, 100.0 * (mean_a - mean_b) / mean_b);
  EXPECT_DOUBLE_EQ(m.mean_diff_percent, 100.0 * 0.25 / mean_b);
  EXPECT_NEAR(m.rel_mse, rel / n, 1e-13 * (rel / n));
  EXPECT_NEAR(m.smape, smape / n, 1e-13 * (smape / n));
  EXPECT_EQ(m.psnr_peak, peak);
  EXPECT_DOUBLE_EQ(m.psnr, 10.0 * std::log10(peak * peak / 0.0625));

  // The CLI reports the same numbers.
  const CliResult r = run_cli({"diff", exr("a", a), exr("b", b), "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["metrics"]["mae"], 0.25);
  EXPECT_EQ(j["metrics"]["rmse"], 0.25);
  EXPECT_EQ(j["metrics"]["max_abs"], 0.25);
  EXPECT_EQ(j["mean"]["diff_percent"].get<double>(), m.mean_diff_percent);
  EXPECT_EQ(j["metrics"]["rel_mse"].get<double>(), m.rel_mse);
  EXPECT_EQ(j["compared_pixels"], 48);
}

TEST_F(DiffTest, NonFinitePixelsAreCountedExcludedAndReported) {
  const Image b0 = ramp(8, 6);
  Image a = offset(b0, 0.25f);
  Image b = b0;
  a.at(2, 1).y = kNaNf;                 // one NaN channel in A
  b.at(5, 4).z = -kInfinity;            // one -Inf channel in B
  const ImageMetrics m = compare_images(a, b);
  EXPECT_EQ(m.pixels, 48u);
  EXPECT_EQ(m.compared, 46u);
  EXPECT_EQ(m.nonfinite_a.count, 1u);
  EXPECT_EQ(m.nonfinite_b.count, 1u);
  ASSERT_EQ(m.nonfinite_a.first.size(), 1u);
  EXPECT_EQ(m.nonfinite_a.first[0], (PixelXY{2, 1}));
  EXPECT_EQ(m.nonfinite_b.first[0], (PixelXY{5, 4}));
  // The rest is still an exact offset; the means leave out both pixels.
  EXPECT_EQ(m.mae, 0.25);
  EXPECT_EQ(m.rmse, 0.25);
  EXPECT_EQ(m.max_abs, 0.25);
  double sum_b = 0;
  for (int y = 0; y < 6; ++y)
    for (int x = 0; x < 8; ++x)
      if (!(x == 2 && y == 1) && !(x == 5 && y == 4)) sum_b += b0.at(x, y).x + b0.at(x, y).y + b0.at(x, y).z;
  EXPECT_EQ(m.mean_b, sum_b / (3.0 * 46));

  const std::string fa = exr("a", a), fb = exr("b", b);
  const CliResult text = run_cli({"diff", fa, fb});
  EXPECT_EQ(text.code, 0) << text.err;
  EXPECT_NE(text.err.find("46 of 48 pixels compared"), std::string::npos) << text.err;
  EXPECT_NE(text.err.find("A (" + fa + ") has 1 pixel(s) with NaN or infinite values"), std::string::npos) << text.err;
  EXPECT_NE(text.err.find("first at (2,1)"), std::string::npos) << text.err;
  EXPECT_NE(text.err.find("B (" + fb + ") has 1 pixel(s)"), std::string::npos) << text.err;

  const CliResult js = run_cli({"diff", fa, fb, "--json"});
  ASSERT_EQ(js.code, 0) << js.err;
  EXPECT_NE(js.err.find("NaN or infinite"), std::string::npos) << "the warning also comes with --json";
  const json j = json::parse(js.out);
  EXPECT_EQ(j["nonfinite"]["a"]["count"], 1);
  EXPECT_EQ(j["nonfinite"]["a"]["first"], json::parse("[[2,1]]"));
  EXPECT_EQ(j["nonfinite"]["b"]["count"], 1);
  EXPECT_EQ(j["nonfinite"]["b"]["first"], json::parse("[[5,4]]"));
  EXPECT_EQ(j["compared_pixels"], 46);
  EXPECT_EQ(j["pixels"], 48);
  EXPECT_EQ(j["metrics"]["mae"], 0.25);
}

TEST_F(DiffTest, NoComparablePixelIsBadInput) {
  Image a(2, 2);
  for (vec3& p : a.pixels) p = vec3(kNaNf);
  const CliResult r = run_cli({"diff", exr("a", a), exr("b", Image(2, 2))});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("no pixel is finite in both"), std::string::npos) << r.err;
}

TEST_F(DiffTest, MismatchedSizesExitTwoNamingBothSizes) {
  const std::string fa = exr("a", ramp(4, 3)), fb = exr("b", ramp(5, 3));
  const CliResult r = run_cli({"diff", fa, fb});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("A (" + fa + ") is 4x3, B (" + fb + ") is 5x3"), std::string::npos) << r.err;
  EXPECT_THROW(compare_images(ramp(4, 3), ramp(4, 2)), InputError);
  EXPECT_THROW(pixel_errors(ramp(4, 3), ramp(4, 2)), InputError);
}

TEST_F(DiffTest, MissingFileExitTwoNamingIt) {
  const std::string fa = exr("a", ramp(4, 3));
  const std::string missing = (dir_ / "nope.exr").string();
  for (const auto& args : {std::vector<std::string>{"diff", fa, missing}, std::vector<std::string>{"diff", missing, fa}}) {
    const CliResult r = run_cli(args);
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find(missing + ": cannot read image: no such file"), std::string::npos) << r.err;
  }
}

TEST_F(DiffTest, ChannelMismatchExitTwo) {
  const std::string rgb = exr("rgb", ramp(4, 3));
  const auto write_channels = [&](const std::string& name, int channels) {
    const fs::path file = dir_ / name;
    std::vector<float> data(static_cast<std::size_t>(4 * 3 * channels), 0.5f);
    OIIO::ImageSpec spec(4, 3, channels, OIIO::TypeFloat);
    auto out = OIIO::ImageOutput::create(file.string());
    EXPECT_TRUE(out && out->open(file.string(), spec) && out->write_image(OIIO::TypeFloat, data.data()) && out->close());
    return file.string();
  };
  const std::string grey = write_channels("grey.exr", 1);
  const std::string grey2 = write_channels("grey2.exr", 1);
  const std::string five = write_channels("five.exr", 5);

  CliResult r = run_cli({"diff", rgb, grey});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("A (" + rgb + ") has 3, B (" + grey + ") has 1"), std::string::npos) << r.err;
  r = run_cli({"diff", five, rgb});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find(five + " (A) has 5 channels"), std::string::npos) << r.err;
  // Two grey images compare (read_image replicates the channel).
  r = run_cli({"diff", grey, grey2, "--tolerance", "0"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(image_channels(grey), 1);
  EXPECT_EQ(image_channels(rgb), 3);
}

TEST_F(DiffTest, ToleranceExitCodesForRmseAndPsnr) {
  const Image b = ramp(8, 6);
  const std::string fa = exr("a", offset(b, 0.25f)), fb = exr("b", b);
  const double psnr = compare_images(offset(b, 0.25f), b).psnr;  // about 17.2 dB
  char below[32], above[32];
  std::snprintf(below, sizeof below, "%.17g", psnr - 1.0);
  std::snprintf(above, sizeof above, "%.17g", psnr + 1.0);

  CliResult r = run_cli({"diff", fa, fb, "--tolerance", "0.3"});  // default metric rmse = 0.25
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("pass: rmse = 0.25 <= tolerance 0.3"), std::string::npos) << r.err;
  r = run_cli({"diff", fa, fb, "--tolerance", "0.2"});
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("FAIL: rmse = 0.25 > tolerance 0.2"), std::string::npos) << r.err;
  r = run_cli({"diff", fa, fb, "--tolerance", "0.25", "--metric", "max_abs"});  // equality passes
  EXPECT_EQ(r.code, 0) << r.err;

  // psnr: higher is better.
  r = run_cli({"diff", fa, fb, "--metric", "psnr", "--tolerance", below});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("pass: psnr = "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(" >= tolerance"), std::string::npos) << r.err;
  r = run_cli({"diff", fa, fb, "--metric", "psnr", "--tolerance", above, "--json"});
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find(" < tolerance"), std::string::npos) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["check"]["metric"], "psnr");
  EXPECT_EQ(j["check"]["pass"], false);
  EXPECT_EQ(j["check"]["value"].get<double>(), psnr);

  // Without --tolerance: exit 0 whatever the error; usage errors exit 2.
  EXPECT_EQ(run_cli({"diff", fa, fb}).code, 0);
  EXPECT_EQ(run_cli({"diff", fa, fb, "--tolerance", "0.3", "--metric", "bogus"}).code, 2);
  EXPECT_EQ(run_cli({"diff", fa, fb, "--metric", "mae"}).code, 2);  // --metric needs --tolerance
  EXPECT_EQ(run_cli({"diff", fa, fb, "--tolerance"}).code, 2);
  EXPECT_EQ(run_cli({"diff", fa}).code, 2);
  EXPECT_EQ(run_cli({"diff", fa, fb, "--tolerance", "nan"}).code, 2);
}

TEST_F(DiffTest, MetricLookup) {
  EXPECT_EQ(tolerance_metric_names(),
            (std::vector<std::string>{"mae", "mse", "rmse", "rel_mse", "smape", "max_abs", "psnr"}));
  EXPECT_TRUE(find_metric("psnr").higher_is_better);
  EXPECT_FALSE(find_metric("rmse").higher_is_better);
  EXPECT_THROW(find_metric("PSNR"), InputError);
  const MetricInfo& rmse = find_metric("rmse");
  EXPECT_TRUE(within_tolerance(0.1, rmse, 0.1));
  EXPECT_FALSE(within_tolerance(std::nan(""), rmse, 1e300));
  EXPECT_FALSE(within_tolerance(std::nan(""), find_metric("psnr"), -1e300));
}

TEST_F(DiffTest, JsonIsStable) {
  const Image b = ramp(8, 6);
  const std::string fa = exr("a", offset(b, 0.125f)), fb = exr("b", b);
  const std::vector<std::string> args = {"diff", fa, fb, "--json", "--tolerance", "1", "--metric", "smape"};
  const CliResult r1 = run_cli(args), r2 = run_cli(args);
  ASSERT_EQ(r1.code, 0) << r1.err;
  EXPECT_EQ(r1.out, r2.out);
  EXPECT_TRUE(r1.err.find("MAE") == std::string::npos) << "no table with --json";
  const json j = json::parse(r1.out);
  EXPECT_EQ(j["format"], "pathlab-diff");
  EXPECT_EQ(j["version"], 2);
  EXPECT_EQ(j["files"]["a"], fa);
  EXPECT_EQ(j["files"]["b"], fb);
  EXPECT_EQ(j["width"], 8);
  EXPECT_EQ(j["height"], 6);
  for (const char* key : {"mae", "mse", "rmse", "rel_mse", "smape", "max_abs", "psnr"})
    EXPECT_TRUE(j["metrics"][key].is_number()) << key;
  for (const char* key : {"a", "b", "diff_percent"}) EXPECT_TRUE(j["mean"][key].is_number()) << key;
  EXPECT_EQ(j["max_abs_at"], json::parse(R"({"x": 0, "y": 0, "channel": 0})"));
  EXPECT_TRUE(j["psnr_peak"].is_number());
  EXPECT_EQ(j["check"]["metric"], "smape");
  EXPECT_EQ(j["check"]["tolerance"], 1.0);
  EXPECT_EQ(j["check"]["pass"], true);
  EXPECT_TRUE(j["heatmap"].is_null());
  // The top-level keys, exactly (sorted by the writer).
  std::vector<std::string> keys;
  for (const auto& item : j.items()) keys.push_back(item.key());
  EXPECT_EQ(keys, (std::vector<std::string>{"check", "compared_pixels", "files", "first_over", "format", "heatmap",
                                            "height", "max_abs_at", "mean", "metrics", "nonfinite", "over_threshold",
                                            "pixels", "psnr_peak", "statistical", "threshold", "version", "width",
                                            "worst"}));
  EXPECT_TRUE(j["statistical"].is_null()) << "no variance layers";
}

TEST_F(DiffTest, HeatmapOfIdenticalImagesIsNeutral) {
  const Image b = ramp(7, 5);
  const fs::path png = dir_ / "maps" / "heat.png";  // the folder is created
  const CliResult r = run_cli({"diff", exr("a", b), exr("b", b), "--heatmap", png.string(), "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("wrote heatmap " + png.string()), std::string::npos) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["heatmap"]["file"], png.string());
  EXPECT_EQ(j["heatmap"]["neutral"], 1e-6);
  EXPECT_EQ(j["heatmap"]["quantity"], "abs_diff");

  const Image map = read_image(png);
  ASSERT_EQ(map.width, kLegendMinWidth);
  ASSERT_EQ(map.height, 5 + kLegendHeight);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 7; ++x) {
      const vec3& p = map.at(x, y);
      EXPECT_EQ((std::array<int, 3>{code(p.x), code(p.y), code(p.z)}), (std::array<int, 3>{128, 128, 128}));
    }
}

// 1e-8 of rounding noise is drawn neutral, not as an alarm: errors at or
// below the threshold are grey, the scale starts above them.
TEST_F(DiffTest, HeatmapDrawsRoundingNoiseNeutral) {
  Image a(4, 1), b(4, 1);
  a.at(0, 0) = vec3(1e-8f, 0.0f, 0.0f);
  a.at(1, 0) = vec3(0.0f, 2e-8f, 0.0f);
  a.at(2, 0) = vec3(0.25f, 0.0f, 0.0f);
  a.at(3, 0) = vec3(0.5f, 0.0f, 0.0f);
  const std::vector<double> e = pixel_errors(a, b);
  EXPECT_EQ(e[3], 0.5);
  const HeatmapRange range = default_heatmap_range(e, false, 1e-6);
  EXPECT_EQ(range.lo, 0.0);
  EXPECT_EQ(range.hi, 0.5);  // the 99th percentile of the two values above the threshold
  const Image map = draw_heatmap(e, 4, 1, range, "x");
  const auto codes_at = [&](int x) {
    const vec3& p = map.at(x, 0);
    return std::array<int, 3>{code(linear_to_srgb(p.x) * 1.0f), code(linear_to_srgb(p.y)), code(linear_to_srgb(p.z))};
  };
  EXPECT_EQ(codes_at(0), (std::array<int, 3>{128, 128, 128}));
  EXPECT_EQ(codes_at(1), (std::array<int, 3>{128, 128, 128}));
  EXPECT_EQ(codes_at(2), (std::array<int, 3>{0xbc, 0x37, 0x54}));  // t = 0.5
  EXPECT_EQ(codes_at(3), (std::array<int, 3>{0xfc, 0xff, 0xa4}));  // t = 1
  // With the threshold at 0 the noise is on the scale, and a log scale spans it.
  const HeatmapRange log_range = default_heatmap_range(e, true, 0.0);
  EXPECT_EQ(log_range.lo, static_cast<double>(1e-8f));
  EXPECT_EQ(log_range.hi, 0.5);
}

TEST_F(DiffTest, HeatmapScaleIsThe99thPercentileAndNaNIsMagenta) {
  // Errors (i+1)/64 for i = 0..99 (exact); pixel 100 is NaN in A.
  Image a(101, 1), b(101, 1);
  for (int i = 0; i < 100; ++i) a.at(i, 0) = vec3(static_cast<float>(i + 1) / 64.0f);
  a.at(100, 0) = vec3(kNaNf, 0.0f, 0.0f);
  const HeatmapRange range = default_heatmap_range(pixel_errors(a, b), false, 0.0);
  EXPECT_EQ(range.hi, 99.0 / 64.0);  // nearest rank: the 99th smallest of 100

  const fs::path png = dir_ / "heat.png";
  const CliResult r = run_cli({"diff", exr("a", a), exr("b", b), "--heatmap", png.string(), "--threshold", "0"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("linear scale from 0 (black) to 1.54688 (pale yellow)"), std::string::npos) << r.err;
  const Image back = read_image(png);
  ASSERT_EQ(back.width, kLegendMinWidth);
  ASSERT_EQ(back.height, 1 + kLegendHeight);
  const auto codes = [&](int x) {
    const vec3& p = back.at(x, 0);
    return std::array<int, 3>{code(p.x), code(p.y), code(p.z)};
  };
  EXPECT_EQ(codes(98), (std::array<int, 3>{0xfc, 0xff, 0xa4}));  // t = 1
  EXPECT_EQ(codes(99), (std::array<int, 3>{0xfc, 0xff, 0xa4}));  // above the range: saturated
  EXPECT_EQ(codes(100), (std::array<int, 3>{255, 0, 255}));      // NaN: magenta
  for (int i = 0; i < 100; ++i) {
    const auto want = heatmap_colour(((i + 1) / 64.0) / range.hi);
    EXPECT_EQ(codes(i), (std::array<int, 3>{want[0], want[1], want[2]})) << i;
  }
}

// The legend under the map: the colour bar, and the stated range written
// under it (compared pixel for pixel with draw_text), on a linear and a log scale.
TEST_F(DiffTest, HeatmapLegendShowsTheStatedRange) {
  Image a(20, 10), b(20, 10);
  a.at(3, 2) = vec3(0.01f, 0.0f, 0.0f);
  for (const bool log : {false, true}) {
    const fs::path png = dir_ / (log ? "log.png" : "lin.png");
    std::vector<std::string> args = {"diff", exr("a", a), exr("b", b), "--heatmap", png.string(), "--json"};
    if (log) args.insert(args.end(), {"--log", "--range", "0.0001,1"});
    else args.insert(args.end(), {"--range", "0,0.02"});
    const CliResult r = run_cli(args);
    ASSERT_EQ(r.code, 0) << r.err;
    const json j = json::parse(r.out);
    EXPECT_EQ(j["heatmap"]["log"], log);
    EXPECT_EQ(j["heatmap"]["lo"], log ? 0.0001 : 0.0);
    EXPECT_EQ(j["heatmap"]["hi"], log ? 1.0 : 0.02);
    EXPECT_NE(r.err.find(log ? "log scale from 0.0001 (black) to 1 (pale yellow)" : "linear scale from 0 (black) to 0.02"),
              std::string::npos) << r.err;

    const Image back = read_image(png);
    ASSERT_EQ(back.width, kLegendMinWidth);
    ASSERT_EQ(back.height, 10 + kLegendHeight);
    const auto codes = [&](int x, int y) {
      const vec3& p = back.at(x, y);
      return std::array<int, 3>{code(p.x), code(p.y), code(p.z)};
    };
    // The pixel: t = 0.5 on both scales (0.01 of 0..0.02; 10^-2 of 10^-4..1).
    EXPECT_EQ(codes(3, 2), (std::array<int, 3>{0xbc, 0x37, 0x54}));
    // The colour bar, 6 px in from each side, 10 px under the map + 4.
    const int bar_w = kLegendMinWidth - 12;
    EXPECT_EQ(codes(6, 10 + 4), (std::array<int, 3>{0x00, 0x00, 0x04}));
    EXPECT_EQ(codes(6 + bar_w - 1, 10 + 9), (std::array<int, 3>{0xfc, 0xff, 0xa4}));
    // The numbers: lo at the left, the middle, hi at the right, in white.
    const std::string lo = log ? "0.0001" : "0", mid = log ? "0.01" : "0.01", hi = log ? "1" : "0.02";
    Image want(back.width, back.height);
    const int y = 10 + 4 + 12;
    draw_text(want, 6, y, lo, vec3(1.0f));
    draw_text(want, 6 + bar_w / 2 - text_width(mid) / 2, y, mid, vec3(1.0f));
    draw_text(want, 6 + bar_w - text_width(hi), y, hi, vec3(1.0f));
    int lit = 0;
    for (int yy = y; yy < y + 7; ++yy)
      for (int x = 0; x < back.width; ++x) {
        const bool on = want.at(x, yy).x == 1.0f;
        lit += on;
        EXPECT_EQ(codes(x, yy), on ? (std::array<int, 3>{255, 255, 255}) : (std::array<int, 3>{0, 0, 0}))
            << (log ? "log" : "linear") << " legend numbers at (" << x << "," << yy << ")";
      }
    EXPECT_GT(lit, 20);
  }
  // A bad range is one clear message.
  const CliResult bad = run_cli({"diff", exr("a", a), exr("b", b), "--heatmap", (dir_ / "x.png").string(), "--log",
                                 "--range", "0,1"});
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("--range 0,1: expected LO,HI with 0 <= LO < HI and LO > 0 for --log"), std::string::npos)
      << bad.err;
}

TEST_F(DiffTest, HeatmapColoursSurviveThePngEncoding) {
  // Every 8-bit code, converted to linear and written by write_png, comes back.
  Image image(256, 1);
  for (int c = 0; c < 256; ++c) image.at(c, 0) = vec3(srgb_to_linear(static_cast<float>(c) / 255.0f));
  const fs::path png = dir_ / "codes.png";
  write_png(png, image, 0.0f);
  const Image back = read_image(png);
  for (int c = 0; c < 256; ++c) EXPECT_EQ(code(back.at(c, 0).x), c);
  // The colour scale gets brighter all the way (luminance of the codes).
  double last = -1.0;
  for (int i = 0; i <= 100; ++i) {
    const auto rgb = heatmap_colour(i / 100.0);
    const double y = 0.2126 * srgb_to_linear(rgb[0] / 255.0f) + 0.7152 * srgb_to_linear(rgb[1] / 255.0f) +
                     0.0722 * srgb_to_linear(rgb[2] / 255.0f);
    EXPECT_GE(y, last) << i;
    last = y;
  }
}

TEST_F(DiffTest, HeatmapPathIsCheckedFirst) {
  const Image b = ramp(4, 3);
  const std::string fa = exr("a", b), fb = exr("b", b);
  CliResult r = run_cli({"diff", fa, fb, "--heatmap", (dir_ / "heat.jpg").string()});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("must be a .png"), std::string::npos) << r.err;
  r = run_cli({"diff", fa, (dir_ / "missing.exr").string(), "--heatmap", "/proc/heat.png"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("/proc/heat.png: cannot write output"), std::string::npos) << r.err;
}


TEST_F(DiffTest, FirstAndWorstPixelsAndCountsAreLocatedExactly) {
  const Image b = ramp(9, 7);
  Image a = b;
  a.at(0, 0).x += 1e-7f;  // B is 0 there: rounding-level, below the default threshold 1e-6
  a.at(6, 1).y += 0.5f;   // the first pixel over it, in row order
  a.at(2, 4).z += 1.75f;  // the worst
  a.at(8, 5).x -= 0.25f;
  const ImageMetrics m = compare_images(a, b, 1e-6);
  EXPECT_EQ(m.over, 3u);
  EXPECT_EQ(m.over_fraction, 3.0 / 63.0);
  EXPECT_EQ(m.first_over, (PixelXY{6, 1}));
  EXPECT_EQ(m.first_over_channel, 1);
  EXPECT_EQ(m.first_over_a, static_cast<double>(a.at(6, 1).y));
  EXPECT_EQ(m.first_over_b, static_cast<double>(b.at(6, 1).y));
  EXPECT_EQ(m.max_at, (PixelXY{2, 4}));
  EXPECT_EQ(m.max_channel, 2);
  EXPECT_EQ(m.max_abs, 1.75);
  // Threshold 0: every difference counts, and the first is at (0,0).
  const ImageMetrics all = compare_images(a, b, 0.0);
  EXPECT_EQ(all.over, 4u);
  EXPECT_EQ(all.first_over, (PixelXY{0, 0}));
  EXPECT_EQ(all.first_over_channel, 0);

  const std::string fa = exr("a", a), fb = exr("b", b);
  const CliResult js = run_cli({"diff", fa, fb, "--json"});
  ASSERT_EQ(js.code, 0) << js.err;
  const json j = json::parse(js.out);
  EXPECT_EQ(j["threshold"], 1e-6);
  EXPECT_EQ(j["over_threshold"]["count"], 3);
  EXPECT_EQ(j["over_threshold"]["fraction"], 3.0 / 63.0);
  EXPECT_EQ(j["first_over"]["x"], 6);
  EXPECT_EQ(j["first_over"]["y"], 1);
  EXPECT_EQ(j["first_over"]["channel"], 1);
  EXPECT_EQ(j["first_over"]["abs_diff"], 0.5);
  EXPECT_EQ(j["worst"]["x"], 2);
  EXPECT_EQ(j["worst"]["y"], 4);
  EXPECT_EQ(j["worst"]["channel"], 2);
  EXPECT_EQ(j["worst"]["a"].get<double>(), static_cast<double>(a.at(2, 4).z));
  EXPECT_EQ(j["worst"]["b"].get<double>(), static_cast<double>(b.at(2, 4).z));
  EXPECT_EQ(run_cli({"diff", fa, fb, "--json", "--threshold", "0"}).out.find("\"count\": 4") != std::string::npos, true);

  const CliResult text = run_cli({"diff", fa, fb});
  ASSERT_EQ(text.code, 0) << text.err;
  EXPECT_NE(text.err.find("over threshold     3              of 63 pixels (4.762 %) have max |A - B| > 1e-06"),
            std::string::npos) << text.err;
  EXPECT_NE(text.err.find("first over                        at pixel (6,1) G: A "), std::string::npos) << text.err;
  EXPECT_NE(text.err.find("worst pixel                       at pixel (2,4) B: A "), std::string::npos) << text.err;
  EXPECT_EQ(run_cli({"diff", fa, fb, "--threshold", "-1"}).code, 2);
}

// ---- the statistical mode: images with a known variance of their means.

// Standard normal deviates from a fixed, portable generator (Box-Muller on
// mt19937_64, whose sequence the standard fixes).
class Normal {
 public:
  explicit Normal(std::uint64_t seed) : rng_(seed) {}
  double operator()() {
    const double u1 = (static_cast<double>(rng_() >> 11) + 0.5) * 0x1.0p-53;
    const double u2 = static_cast<double>(rng_() >> 11) * 0x1.0p-53;
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * 3.141592653589793 * u2);
  }

 private:
  std::mt19937_64 rng_;
};

struct NoisyPair {
  Image a, b, var_a, var_b;
  double sigma = 0;  // of a - b
};
// The truth ramp(w, h) plus noise of standard deviation sa (in A) and sb (in
// B), with those variances in the layers.
NoisyPair noisy_pair(int w, int h, double sa, double sb, std::uint64_t seed) {
  NoisyPair p;
  const Image truth = ramp(w, h);
  p.a = p.b = truth;
  p.var_a = p.var_b = Image(w, h);
  Normal n(seed);
  for (std::size_t i = 0; i < truth.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      p.a.pixels[i][c] = static_cast<float>(truth.pixels[i][c] + sa * n());
      p.b.pixels[i][c] = static_cast<float>(truth.pixels[i][c] + sb * n());
      p.var_a.pixels[i][c] = static_cast<float>(sa * sa);
      p.var_b.pixels[i][c] = static_cast<float>(sb * sb);
    }
  p.sigma = std::sqrt(static_cast<double>(static_cast<float>(sa * sa)) + static_cast<double>(static_cast<float>(sb * sb)));
  return p;
}

TEST_F(DiffTest, StatisticalModeFindsATenSigmaShiftInOnePixel) {
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    NoisyPair p = noisy_pair(32, 32, 0.01, 0.02, seed);
    p.a.at(5, 7).y += static_cast<float>(10.0 * p.sigma);
    const StatisticalDiff s = statistical_diff(p.a, p.b, p.var_a, p.var_b, 1e-4, 0.0, false);
    EXPECT_EQ(s.tests, 3u * 32 * 32);
    EXPECT_NEAR(s.z_threshold, 5.53, 0.01);  // Sidak: 1 - (1 - 1e-4)^(1/3072) per test
    EXPECT_FALSE(s.pass) << seed;
    EXPECT_EQ(s.failing, 1u) << seed;
    EXPECT_EQ(s.worst.at, (PixelXY{5, 7})) << seed;
    EXPECT_EQ(s.worst.channel, 1) << seed;
    EXPECT_EQ(s.first_failing.at, (PixelXY{5, 7})) << seed;
    EXPECT_NEAR(s.worst.z, 10.0, 4.0) << seed;  // the shift, plus one unit of noise
    EXPECT_TRUE(s.bias_pass) << seed;           // one pixel barely moves the mean
  }

  // Through the CLI: the layers are read back from the EXRs.
  NoisyPair p = noisy_pair(32, 32, 0.01, 0.02, 1);
  const auto with_variance = [&](const std::string& name, const Image& image, const Image& var) {
    std::vector<ExrChannel> channels;
    const char* names[] = {"R", "G", "B", "variance.R", "variance.G", "variance.B"};
    for (int k = 0; k < 6; ++k) {
      ExrChannel ch{names[k], {}};
      for (const vec3& v : k < 3 ? image.pixels : var.pixels) ch.values.push_back(v[k % 3]);
      channels.push_back(std::move(ch));
    }
    const fs::path file = dir_ / (name + ".exr");
    write_exr_channels(file, image.width, image.height, channels, {});
    return file.string();
  };
  const std::string fb = with_variance("b", p.b, p.var_b);
  const std::string clean = with_variance("clean", p.a, p.var_a);
  p.a.at(5, 7).y += static_cast<float>(10.0 * p.sigma);
  const std::string shifted = with_variance("shifted", p.a, p.var_a);

  CliResult r = run_cli({"diff", clean, fb, "--stat"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("pass: statistical test, 0 failing"), std::string::npos) << r.err;
  r = run_cli({"diff", shifted, fb, "--stat", "--json", "--heatmap", (dir_ / "z.png").string()});
  EXPECT_EQ(r.code, 1) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["statistical"]["failing"], 1);
  EXPECT_EQ(j["statistical"]["first_failing"]["x"], 5);
  EXPECT_EQ(j["statistical"]["first_failing"]["y"], 7);
  EXPECT_EQ(j["statistical"]["first_failing"]["channel"], 1);
  EXPECT_EQ(j["statistical"]["pass"], false);
  EXPECT_EQ(j["heatmap"]["quantity"], "z");
  EXPECT_EQ(j["heatmap"]["hi"].get<double>(), j["statistical"]["z_threshold"].get<double>());
  // Without --stat the report is there but the exit code is the metrics'.
  r = run_cli({"diff", shifted, fb});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("first failing      z "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("at pixel (5,7) G"), std::string::npos) << r.err;
  // --stat without variance layers: one message naming the file.
  const std::string plain = exr("plain", p.b);
  r = run_cli({"diff", shifted, plain, "--stat"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find(plain + ": --stat needs a variance layer"), std::string::npos) << r.err;
}

// Pure noise of the stated variance: the family of per-pixel tests fails in
// a fraction alpha of the seeds (Sidak is exact for independent tests, and
// the constant variance makes the 3x3 maximum the variance itself). Over 400
// fixed seeds at alpha = 0.1 the number of failing seeds is Binomial(400,
// 0.1): 40 +- 6; the bounds are 4.5 standard deviations (a false alarm of
// this test about 1e-5). A test that ignored the multiple comparisons (or
// used the wrong variance) fails far more often; one twice as strict fails
// about half as often.
TEST_F(DiffTest, PureNoisePassesAtTheStatedFalseAlarmRate) {
  const int seeds = 400;
  const double alpha = 0.1;
  int pixel_failures = 0, bias_failures = 0;
  for (int seed = 0; seed < seeds; ++seed) {
    const NoisyPair p = noisy_pair(16, 16, 0.03, 0.01, 1000 + static_cast<std::uint64_t>(seed));
    const StatisticalDiff s = statistical_diff(p.a, p.b, p.var_a, p.var_b, alpha, 0.0, false);
    pixel_failures += !s.pixels_pass;
    bias_failures += !s.bias_pass;
  }
  const double mean = seeds * alpha, sd = std::sqrt(seeds * alpha * (1.0 - alpha));
  EXPECT_NEAR(pixel_failures, mean, 4.5 * sd) << "per-pixel tests";
  EXPECT_NEAR(bias_failures, mean, 4.5 * sd) << "mean-difference test";
}

// A uniform shift of 0.5 sigma in every pixel fails no pixel but the mean
// difference (z = 0.5 sqrt(256) = 8 against a threshold of about 4.0); with
// the bilinear filter's correlation the error is 3x larger (z = 2.7) and it passes.
TEST_F(DiffTest, MeanDifferenceTestFindsAUniformShift) {
  NoisyPair p = noisy_pair(16, 16, 0.01, 0.01, 7);
  for (vec3& v : p.a.pixels) v.x += static_cast<float>(0.5 * p.sigma);
  const StatisticalDiff s = statistical_diff(p.a, p.b, p.var_a, p.var_b, 1e-4, 0.0, false);
  EXPECT_TRUE(s.pixels_pass);
  EXPECT_FALSE(s.bias_pass);
  EXPECT_EQ(s.bias_channel, 0);
  EXPECT_NEAR(s.bias_z, 8.0, 1.5);
  const StatisticalDiff c = statistical_diff(p.a, p.b, p.var_a, p.var_b, 1e-4, 0.0, true);
  EXPECT_TRUE(c.correlated);
  EXPECT_NEAR(c.bias_z, s.bias_z / 3.0, 1e-9);
  EXPECT_TRUE(c.bias_pass);
}

// A pixel whose own variance estimate is 0 (its few samples all missed the
// light) takes its neighbours' largest, as pathlab check does.
TEST_F(DiffTest, ZeroVarianceNextToNoiseUsesTheNeighbourhood) {
  NoisyPair p = noisy_pair(8, 8, 0.01, 0.01, 3);
  p.var_a.at(4, 4) = p.var_b.at(4, 4) = vec3(0.0f);
  p.a.at(4, 4) = p.b.at(4, 4) + vec3(static_cast<float>(p.sigma));
  const StatisticalDiff s = statistical_diff(p.a, p.b, p.var_a, p.var_b, 1e-4, 0.0, false);
  EXPECT_TRUE(s.pixels_pass) << "z " << s.worst.z << " at (" << s.worst.at.x << "," << s.worst.at.y << ")";
  // Noiseless pixels that differ by rounding only pass within the threshold.
  Image var0(8, 8);
  Image a = ramp(8, 8), b = a;
  a.at(1, 1).x += 1e-7f;
  EXPECT_TRUE(statistical_diff(a, b, var0, var0, 1e-4, 1e-6, false).pass);
  EXPECT_FALSE(statistical_diff(a, b, var0, var0, 1e-4, 0.0, false).pass);
}

}  // namespace
}  // namespace pathlab
