// pathlab diff A B [--heatmap out.png] [--json] [--tolerance X [--metric M]]
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
#include <ostream>

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
}

}  // namespace

void DiffCommand::add_to(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand("diff", "Compare image A against the reference B (docs/diff.md)");
  cmd->add_option("a", a, "Image under test (EXR, or anything OpenImageIO reads)")->required();
  cmd->add_option("b", b, "Reference image, same size and channels")->required();
  cmd->add_option("--heatmap", heatmap, "Write a false-colour PNG of the per-pixel error");
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

  const ImageMetrics m = compare_images(image_a, image_b);
  if (m.compared == 0)
    throw InputError("no pixel is finite in both " + a + " and " + b + ": nothing to compare");

  double scale = 0.0;
  if (!heatmap.empty()) write_png(heatmap_file, error_heatmap(image_a, image_b, &scale), 0.0f);

  bool pass = true;
  if (tolerance) pass = within_tolerance(m.*checked.field, checked, *tolerance);

  if (json) {
    nlohmann::json j = to_json(m);
    j["files"] = {{"a", a}, {"b", b}};
    j["check"] = tolerance ? nlohmann::json{{"metric", checked.name},
                                            {"tolerance", *tolerance},
                                            {"value", std::isfinite(m.*checked.field) ? nlohmann::json(m.*checked.field)
                                                                                       : nlohmann::json(nullptr)},
                                            {"pass", pass}}
                           : nlohmann::json(nullptr);
    j["heatmap"] = heatmap.empty() ? nlohmann::json(nullptr) : nlohmann::json{{"file", heatmap}, {"scale", scale}};
    out << j.dump(2) << "\n";
  } else {
    print_table(err, a, b, m);
  }
  print_nonfinite(err, "A", a, m.nonfinite_a);
  print_nonfinite(err, "B", b, m.nonfinite_b);
  if (!heatmap.empty())
    err << "pathlab: wrote heatmap " << heatmap << " (per-pixel mean |A - B|; black = 0, pale yellow >= " << num(scale)
        << ", the 99th percentile; magenta = NaN/Inf)\n";
  if (tolerance) {
    const double value = m.*checked.field;
    const char* relation = checked.higher_is_better ? (pass ? " >= " : " < ") : (pass ? " <= " : " > ");
    err << "pathlab: " << (pass ? "pass" : "FAIL") << ": " << checked.name << " = " << num(value)
        << (std::isnan(value) ? ", which no tolerance accepts; " : relation) << "tolerance " << num(*tolerance)
        << "\n";
  }
  return pass ? 0 : 1;
}

}  // namespace pathlab::cli
