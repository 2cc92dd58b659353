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
  EXPECT_THROW(error_heatmap(ramp(4, 3), ramp(4, 2), nullptr), InputError);
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
  EXPECT_EQ(j["version"], 1);
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
  EXPECT_EQ(keys, (std::vector<std::string>{"check", "compared_pixels", "files", "format", "heatmap", "height",
                                            "max_abs_at", "mean", "metrics", "nonfinite", "pixels", "psnr_peak",
                                            "version", "width"}));
}

TEST_F(DiffTest, HeatmapOfIdenticalImagesIsTheColourOfZero) {
  const Image b = ramp(7, 5);
  const fs::path png = dir_ / "maps" / "heat.png";  // the folder is created
  const CliResult r = run_cli({"diff", exr("a", b), exr("b", b), "--heatmap", png.string(), "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("wrote heatmap " + png.string()), std::string::npos) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["heatmap"]["file"], png.string());
  EXPECT_EQ(j["heatmap"]["scale"], 0.0);

  const Image map = read_image(png);
  ASSERT_EQ(map.width, 7);
  ASSERT_EQ(map.height, 5);
  const auto zero = heatmap_colour(0.0);
  EXPECT_EQ(zero, (std::array<std::uint8_t, 3>{0, 0, 4}));
  for (const vec3& p : map.pixels) {
    EXPECT_EQ(code(p.x), zero[0]);
    EXPECT_EQ(code(p.y), zero[1]);
    EXPECT_EQ(code(p.z), zero[2]);
  }
}

TEST_F(DiffTest, HeatmapScaleIsThe99thPercentileAndNaNIsMagenta) {
  // Errors i/64 for i = 0..99 (exact); pixel 100 is NaN in A.
  Image a(101, 1), b(101, 1);
  for (int i = 0; i < 100; ++i) a.at(i, 0) = vec3(static_cast<float>(i) / 64.0f);
  a.at(100, 0) = vec3(kNaNf, 0.0f, 0.0f);
  double scale = -1.0;
  const Image map = error_heatmap(a, b, &scale);
  EXPECT_EQ(scale, 98.0 / 64.0);  // nearest rank: the 99th smallest of 100

  const fs::path png = dir_ / "heat.png";
  const CliResult r = run_cli({"diff", exr("a", a), exr("b", b), "--heatmap", png.string()});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find(">= 1.53125, the 99th percentile"), std::string::npos) << r.err;
  const Image back = read_image(png);
  ASSERT_EQ(back.width, 101);
  ASSERT_EQ(back.height, 1);
  const auto codes = [&](int x) {
    const vec3& p = back.at(x, 0);
    return std::array<int, 3>{code(p.x), code(p.y), code(p.z)};
  };
  EXPECT_EQ(codes(0), (std::array<int, 3>{0x00, 0x00, 0x04}));
  EXPECT_EQ(codes(49), (std::array<int, 3>{0xbc, 0x37, 0x54}));  // t = 0.5, a control point
  EXPECT_EQ(codes(98), (std::array<int, 3>{0xfc, 0xff, 0xa4}));  // t = 1
  EXPECT_EQ(codes(99), (std::array<int, 3>{0xfc, 0xff, 0xa4}));  // above the scale: saturated
  EXPECT_EQ(codes(100), (std::array<int, 3>{255, 0, 255}));      // NaN: magenta
  for (int i = 0; i < 100; ++i) {
    const auto want = heatmap_colour((i / 64.0) / scale);
    EXPECT_EQ(codes(i), (std::array<int, 3>{want[0], want[1], want[2]})) << i;
  }
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

}  // namespace
}  // namespace pathlab
