// pathlab diff A B [--heatmap out.png [--log] [--range LO,HI]] [--json] [--tolerance X [--metric M]]
//                  [--threshold T] [--stat [--alpha P]]
// Compares image A against the reference B (docs/diff.md). Exit 0 within the
// tolerance (or no tolerance given), 1 outside it, 2 bad input.
#include "apps/cli/commands.h"

#include "core/error.h"
#include "core/image_io.h"
#include "debugtools/image_metrics.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <ostream>
#include <sstream>

namespace pathlab::cli {

namespace {

namespace fs = std::filesystem;

std::string size_text(const Image& image) {
  return std::to_string(image.width) + "x" + std::to_string(image.height);
}

// %.6g, with inf / nan spelled out.
std::string num(double v) {
  if (std::isnan(v)) return "undefined";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char text[64];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

// 1-channel (grey), RGB and RGBA images can be compared; a file with any
// other layout is refused rather than guessed at.
void check_channels(const std::string& which, const std::string& file, int channels) {
  if (channels != 1 && channels != 3 && channels != 4)
    throw InputError(file + " (" + which + ") has " + std::to_string(channels) +
                     " channels; diff compares 1-channel, RGB or RGBA images");
}

void print_nonfinite(std::ostream& err, const char* which, const std::string& file, const NonFinite& nf) {
  if (nf.count == 0) return;
  err << "pathlab: warning: " << which << " (" << file << ") has " << nf.count
      << " pixel(s) with NaN or infinite values, left out of every metric; first at";
  for (std::size_t i = 0; i < nf.first.size(); ++i)
    err << (i ? ", " : " ") << "(" << nf.first[i].x << "," << nf.first[i].y << ")";
  if (nf.count > nf.first.size()) err << ", ...";
  err << "\n";
}

void print_table(std::ostream& err, const std::string& a, const std::string& b, const ImageMetrics& m) {
  err << "pathlab diff: A = " << a << ", B = " << b << " (reference), " << m.width << "x" << m.height << ", "
      << m.compared << " of " << m.pixels << " pixels compared\n";
  const auto row = [&](const char* name, const std::string& value, const std::string& note = "") {
    char line[160];
    std::snprintf(line, sizeof line, "  %-18s %-14s", name, value.c_str());
    std::string text = line;
    if (!note.empty()) text += " " + note;
    while (!text.empty() && text.back() == ' ') text.pop_back();
    err << text << "\n";
  };
  row("MAE", num(m.mae));
  row("MSE", num(m.mse));
  row("RMSE", num(m.rmse));
  row("relative MSE", num(m.rel_mse), "(d^2 / (B + 0.01)^2)");
  row("SMAPE", num(m.smape), "(fraction, 0..2)");
  row("max abs error", num(m.max_abs),
      m.max_channel < 0 ? ""
                        : "at pixel (" + std::to_string(m.max_at.x) + "," + std::to_string(m.max_at.y) + ") " +
                              "RGB"[m.max_channel]);
  row("mean A", num(m.mean_a));
  row("mean B", num(m.mean_b));
  row("mean difference", (m.mean_diff_percent > 0 ? "+" : "") + num(m.mean_diff_percent) + " %", "(100 (mean A - mean B) / mean B)");
  row("PSNR", num(m.psnr) + " dB", "(peak " + num(m.psnr_peak) + " = max of B)");
  const auto at = [](PixelXY p, int c, double value_a, double value_b) {
    return "at pixel (" + std::to_string(p.x) + "," + std::to_string(p.y) + ") " + "RGB"[c] + ": A " + num(value_a) +
           ", B " + num(value_b);
  };
  char fraction[32];
  std::snprintf(fraction, sizeof fraction, "%.4g %%", 100.0 * m.over_fraction);
  row("over threshold", std::to_string(m.over), "of " + std::to_string(m.compared) + " pixels (" + fraction +
                                                    ") have max |A - B| > " + num(m.threshold));
  row("first over", m.first_over_channel < 0 ? "none" : "",
      m.first_over_channel < 0 ? "" : at(m.first_over, m.first_over_channel, m.first_over_a, m.first_over_b));
  row("worst pixel", m.max_channel < 0 ? "none" : "",
      m.max_channel < 0 ? "" : at(m.max_at, m.max_channel, m.max_value_a, m.max_value_b));
}

void print_statistics(std::ostream& err, const StatisticalDiff& s) {
  const auto at = [](const PixelZ& p) {
    return "z " + num(p.z) + " at pixel (" + std::to_string(p.at.x) + "," + std::to_string(p.at.y) + ") " +
           "RGB"[p.channel] + ": A " + num(p.a) + ", B " + num(p.b) + ", sigma " + num(p.sigma);
  };
  err << "statistical (both images carry variance layers): z = (A - B) / sigma, Sidak over " << s.tests
      << " tests at alpha " << num(s.alpha) << ": |z| <= " << num(s.z_threshold)
      << (s.correlated ? "; bilinear filter: bias error x3" : "") << "\n";
  err << "  failing            " << s.failing << " test(s) in " << s.failing_pixels << " pixel(s)"
      << (s.pixels_pass ? "" : " -- FAIL") << "\n";
  if (s.first_failing.channel >= 0) err << "  first failing      " << at(s.first_failing) << "\n";
  if (s.worst.channel >= 0) err << "  largest |z|        " << at(s.worst) << "\n";
  err << "  mean difference    " << num(s.bias) << " in " << "RGB"[s.bias_channel] << " (z " << num(s.bias_z)
      << ", |z| <= " << num(s.bias_threshold) << ")" << (s.bias_pass ? "" : " -- FAIL") << "\n";
}

// "LO,HI" with 0 <= LO < HI (LO > 0 for a log scale).
HeatmapRange parse_range(const std::string& text, bool log) {
  double lo = 0, hi = 0;
  char comma = 0, extra = 0;
  std::istringstream in(text);
  if (!(in >> lo >> comma >> hi) || comma != ',' || (in >> extra) || !std::isfinite(lo) || !std::isfinite(hi) ||
      !(lo >= 0.0) || !(hi > lo) || (log && !(lo > 0.0)))
    throw InputError("--range " + text + ": expected LO,HI with 0 <= LO < HI" +
                     (log ? std::string(" and LO > 0 for --log") : std::string()) + ", e.g. --range 0,0.5");
  HeatmapRange r;
  r.lo = lo;
  r.hi = hi;
  r.log = log;
  return r;
}

}  // namespace

void DiffCommand::add_to(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand("diff", "Compare image A against the reference B (docs/diff.md)");
  cmd->add_option("a", a, "Image under test (EXR, or anything OpenImageIO reads)")->required();
  cmd->add_option("b", b, "Reference image, same size and channels")->required();
  cmd->add_option("--heatmap", heatmap, "Write a false-colour PNG of the per-pixel error, with a legend");
  cmd->add_flag("--log", log_scale, "Heatmap on a log scale")->needs("--heatmap");
  cmd->add_option("--range", range, "Heatmap range LO,HI (default: 0 or the threshold, to the 99th percentile)")
      ->needs("--heatmap");
  cmd->add_option("--threshold", threshold,
                  "A pixel differs when max |A - B| over its channels exceeds T (default 1e-6); at or below it the "
                  "heatmap is neutral grey");
  cmd->add_flag("--stat", stat,
                "Exit 1 unless the statistical test passes (needs variance layers in both: render --aov variance)");
  cmd->add_option("--alpha", alpha, "False-alarm rate of the statistical test over all pixels (default 1e-4)");
  cmd->add_flag("--json", json, "Print the metrics as JSON on stdout (docs/diff.md)");
  CLI::Option* tol = cmd->add_option("--tolerance", tolerance,
                                     "Exit 1 unless the metric is <= X (for psnr: >= X)");
  cmd->add_option("--metric", metric, "Metric checked by --tolerance (default rmse)")
      ->check(CLI::IsMember(tolerance_metric_names()))
      ->needs(tol);
  cmd->callback([this] { selected = true; });
}

int DiffCommand::run(std::ostream& out, std::ostream& err) const {
  const MetricInfo& checked = find_metric(metric);
  if (tolerance && std::isnan(*tolerance)) throw InputError("--tolerance: expected a number, not NaN");

  fs::path heatmap_file;
  if (!heatmap.empty()) {
    heatmap_file = heatmap;
    if (lower_extension(heatmap_file) != ".png") throw InputError(heatmap + ": --heatmap must be a .png file");
    std::error_code ec_heatmap, ec_input;
    const fs::path canonical_heatmap = fs::weakly_canonical(heatmap_file, ec_heatmap);
    for (const std::string& input : {a, b}) {
      if (!ec_heatmap && fs::weakly_canonical(input, ec_input) == canonical_heatmap && !ec_input)
        throw InputError(heatmap + ": --heatmap would overwrite the input " + input);
    }
    ensure_writable(heatmap_file);  // fail now, not after the comparison
  }

  const Image image_a = read_image(a);
  const Image image_b = read_image(b);
  const int channels_a = image_channels(a);
  const int channels_b = image_channels(b);
  check_channels("A", a, channels_a);
  check_channels("B", b, channels_b);
  if (channels_a != channels_b)
    throw InputError("the images differ in channels: A (" + a + ") has " + std::to_string(channels_a) +
                     ", B (" + b + ") has " + std::to_string(channels_b));
  if (image_a.width != image_b.width || image_a.height != image_b.height)
    throw InputError("the images differ in size: A (" + a + ") is " + size_text(image_a) + ", B (" + b + ") is " +
                     size_text(image_b));

  if (!(threshold >= 0.0) || !std::isfinite(threshold)) throw InputError("--threshold: expected a number >= 0");
  if (!(alpha > 0.0 && alpha < 1.0)) throw InputError("--alpha: expected a false-alarm rate in (0, 1)");
  std::optional<HeatmapRange> stated_range;
  if (range) stated_range = parse_range(*range, log_scale);

  const ImageMetrics m = compare_images(image_a, image_b, threshold);
  if (m.compared == 0)
    throw InputError("no pixel is finite in both " + a + " and " + b + ": nothing to compare");

  // The statistical mode, when both images carry the variance of their means.
  const std::optional<Image> var_a = read_variance_layer(a), var_b = read_variance_layer(b);
  if (stat && (!var_a || !var_b))
    throw InputError(std::string(!var_a ? a : b) + ": --stat needs a variance layer (variance.R/G/B) in both "
                     "images; render them with --aov variance");
  std::optional<StatisticalDiff> sd;
  if (var_a && var_b) {
    ImageMetadata meta_a, meta_b;
    read_image(a, &meta_a);
    read_image(b, &meta_b);
    const auto bilinear = [](const ImageMetadata& meta) {
      for (const auto& [key, value] : meta)
        if (key == "filter" && value == "bilinear") return true;
      return false;
    };
    sd = statistical_diff(image_a, image_b, *var_a, *var_b, alpha, threshold, bilinear(meta_a) || bilinear(meta_b));
  }

  HeatmapRange hrange;
  const char* quantity = sd ? "|z|" : "|A-B|";
  if (!heatmap.empty()) {
    const std::vector<double> values = sd ? sd->pixel_z : pixel_errors(image_a, image_b);
    const double neutral = sd ? -1.0 : threshold;
    if (stated_range) {
      hrange = *stated_range;
    } else if (sd) {
      hrange.lo = log_scale ? 1.0 : 0.0;
      hrange.hi = std::max(sd->z_threshold, hrange.lo + 1.0);
      hrange.log = log_scale;
    } else {
      hrange = default_heatmap_range(values, log_scale, neutral);
    }
    hrange.neutral = neutral;
    write_png(heatmap_file, draw_heatmap(values, image_a.width, image_a.height, hrange, quantity), 0.0f);
  }

  bool pass = true;
  if (tolerance) pass = within_tolerance(m.*checked.field, checked, *tolerance);
  if (stat && sd && !sd->pass) pass = false;

  if (json) {
    nlohmann::json j = to_json(m);
    j["files"] = {{"a", a}, {"b", b}};
    j["check"] = tolerance ? nlohmann::json{{"metric", checked.name},
                                            {"tolerance", *tolerance},
                                            {"value", std::isfinite(m.*checked.field) ? nlohmann::json(m.*checked.field)
                                                                                       : nlohmann::json(nullptr)},
                                            {"pass", within_tolerance(m.*checked.field, checked, *tolerance)}}
                           : nlohmann::json(nullptr);
    j["statistical"] = sd ? to_json(*sd) : nlohmann::json(nullptr);
    j["heatmap"] = heatmap.empty() ? nlohmann::json(nullptr)
                                   : nlohmann::json{{"file", heatmap},
                                                    {"quantity", sd ? "z" : "abs_diff"},
                                                    {"lo", hrange.lo},
                                                    {"hi", hrange.hi},
                                                    {"log", hrange.log},
                                                    {"neutral", hrange.neutral >= 0.0 ? nlohmann::json(hrange.neutral)
                                                                                      : nlohmann::json(nullptr)}};
    out << j.dump(2) << "\n";
  } else {
    print_table(err, a, b, m);
    if (sd) print_statistics(err, *sd);
  }
  print_nonfinite(err, "A", a, m.nonfinite_a);
  print_nonfinite(err, "B", b, m.nonfinite_b);
  if (!heatmap.empty()) {
    err << "pathlab: wrote heatmap " << heatmap << " (per pixel " << (sd ? "max |z| over channels" : "max |A - B| over channels")
        << ", " << (hrange.log ? "log" : "linear") << " scale from " << num(hrange.lo) << " (black) to "
        << num(hrange.hi) << " (pale yellow)";
    if (hrange.neutral >= 0.0) err << "; grey <= " << num(hrange.neutral);
    err << "; magenta = NaN/Inf; legend below the map)\n";
  }
  if (stat && sd)
    err << "pathlab: " << (sd->pass ? "pass" : "FAIL") << ": statistical test, " << sd->failing
        << " failing test(s), mean-difference z " << num(sd->bias_z) << "\n";
  if (tolerance) {
    const double value = m.*checked.field;
    const bool ok = within_tolerance(value, checked, *tolerance);
    const char* relation = checked.higher_is_better ? (ok ? " >= " : " < ") : (ok ? " <= " : " > ");
    err << "pathlab: " << (ok ? "pass" : "FAIL") << ": " << checked.name << " = " << num(value)
        << (std::isnan(value) ? ", which no tolerance accepts; " : relation) << "tolerance " << num(*tolerance)
        << "\n";
  }
  return pass ? 0 : 1;
}

}  // namespace pathlab::cli
