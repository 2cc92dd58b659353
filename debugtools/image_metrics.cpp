// Image comparison for `pathlab diff`. See image_metrics.h and docs/diff.md.
#include "debugtools/image_metrics.h"

#include "core/error.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

namespace pathlab {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

std::string size_text(const Image& image) {
  return std::to_string(image.width) + "x" + std::to_string(image.height);
}

void check_same_size(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height)
    throw InputError("the images differ in size: A is " + size_text(a) + ", B is " + size_text(b));
}

// Neumaier's compensated sum: the metrics of a 4K image (25 million terms)
// keep all the digits JSON prints.
class Sum {
 public:
  void add(double v) {
    const double t = sum_ + v;
    comp_ += std::abs(sum_) >= std::abs(v) ? (sum_ - t) + v : (v - t) + sum_;
    sum_ = t;
  }
  double value() const { return sum_ + comp_; }

 private:
  double sum_ = 0.0, comp_ = 0.0;
};

void note_nonfinite(NonFinite& nf, int x, int y) {
  if (nf.first.size() < NonFinite::kMaxListed) nf.first.push_back({x, y});
  ++nf.count;
}

nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json nonfinite_json(const NonFinite& nf) {
  nlohmann::json first = nlohmann::json::array();
  for (const PixelXY& p : nf.first) first.push_back({p.x, p.y});
  return {{"count", nf.count}, {"first", first}};
}

// matplotlib's inferno (CC0) at t = 0, .2, .4, .5, .6, .7, .8, 1: lightness
// L* = 0, 17, 35, 44, 54, 64, 75, 98, so equal steps of error look like
// roughly equal steps of brightness, and the map survives greyscale printing.
struct ControlPoint {
  double t;
  double rgb[3];  // sRGB codes, 0..255
};
constexpr ControlPoint kInferno[] = {
    {0.0, {0x00, 0x00, 0x04}}, {0.2, {0x42, 0x0a, 0x68}}, {0.4, {0x93, 0x26, 0x67}},
    {0.5, {0xbc, 0x37, 0x54}}, {0.6, {0xdd, 0x51, 0x3a}}, {0.7, {0xf3, 0x78, 0x19}},
    {0.8, {0xfc, 0xa5, 0x0a}}, {1.0, {0xfc, 0xff, 0xa4}},
};

}  // namespace

ImageMetrics compare_images(const Image& a, const Image& b) {
  check_same_size(a, b);
  ImageMetrics m;
  m.width = a.width;
  m.height = a.height;
  m.pixels = a.pixels.size();

  Sum abs_sum, sq_sum, rel_sum, smape_sum, a_sum, b_sum;
  double peak = -kInf;
  for (int y = 0; y < a.height; ++y) {
    for (int x = 0; x < a.width; ++x) {
      const vec3& pa = a.at(x, y);
      const vec3& pb = b.at(x, y);
      const bool fa = is_finite(pa), fb = is_finite(pb);
      if (!fa) note_nonfinite(m.nonfinite_a, x, y);
      if (!fb) note_nonfinite(m.nonfinite_b, x, y);
      if (!fa || !fb) continue;
      ++m.compared;
      for (int c = 0; c < 3; ++c) {
        const double va = pa[c], vb = pb[c];
        const double d = va - vb;
        const double ad = std::abs(d);
        abs_sum.add(ad);
        sq_sum.add(d * d);
        rel_sum.add(d * d / ((vb + 0.01) * (vb + 0.01)));
        const double denom = std::abs(va) + std::abs(vb);
        smape_sum.add(denom > 0.0 ? 2.0 * ad / denom : 0.0);
        a_sum.add(va);
        b_sum.add(vb);
        peak = std::max(peak, vb);
        if (ad > m.max_abs || m.max_channel < 0) {
          m.max_abs = ad;
          m.max_at = {x, y};
          m.max_channel = c;
        }
      }
    }
  }

  if (m.compared == 0) {
    m.mae = m.mse = m.rmse = m.rel_mse = m.smape = m.max_abs = kNaN;
    m.mean_a = m.mean_b = m.mean_diff_percent = m.psnr = m.psnr_peak = kNaN;
    return m;
  }
  const double n = 3.0 * static_cast<double>(m.compared);
  m.mae = abs_sum.value() / n;
  m.mse = sq_sum.value() / n;
  m.rmse = std::sqrt(m.mse);
  m.rel_mse = rel_sum.value() / n;
  m.smape = smape_sum.value() / n;
  m.mean_a = a_sum.value() / n;
  m.mean_b = b_sum.value() / n;
  m.mean_diff_percent = m.mean_a == m.mean_b ? 0.0 : 100.0 * (m.mean_a - m.mean_b) / m.mean_b;
  m.psnr_peak = peak;
  if (m.mse == 0.0) m.psnr = kInf;
  else if (peak <= 0.0) m.psnr = kNaN;
  else m.psnr = 10.0 * std::log10(peak * peak / m.mse);
  return m;
}

std::span<const MetricInfo> tolerance_metrics() {
  static constexpr MetricInfo kMetrics[] = {
      {"mae", false, &ImageMetrics::mae},         {"mse", false, &ImageMetrics::mse},
      {"rmse", false, &ImageMetrics::rmse},       {"rel_mse", false, &ImageMetrics::rel_mse},
      {"smape", false, &ImageMetrics::smape},     {"max_abs", false, &ImageMetrics::max_abs},
      {"psnr", true, &ImageMetrics::psnr},
  };
  return kMetrics;
}

std::vector<std::string> tolerance_metric_names() {
  std::vector<std::string> names;
  for (const MetricInfo& m : tolerance_metrics()) names.emplace_back(m.name);
  return names;
}

const MetricInfo& find_metric(std::string_view name) {
  for (const MetricInfo& m : tolerance_metrics()) {
    if (m.name == name) return m;
  }
  std::string known;
  for (const MetricInfo& m : tolerance_metrics()) known += (known.empty() ? "" : ", ") + std::string(m.name);
  throw InputError("unknown metric '" + std::string(name) + "' (known: " + known + ")");
}

bool within_tolerance(double value, const MetricInfo& metric, double tolerance) {
  if (std::isnan(value)) return false;
  return metric.higher_is_better ? value >= tolerance : value <= tolerance;
}

nlohmann::json to_json(const ImageMetrics& m) {
  nlohmann::json metrics = nlohmann::json::object();
  for (const MetricInfo& info : tolerance_metrics()) metrics[std::string(info.name)] = number(m.*info.field);
  return {
      {"format", "pathlab-diff"},
      {"version", 1},
      {"width", m.width},
      {"height", m.height},
      {"pixels", m.pixels},
      {"compared_pixels", m.compared},
      {"nonfinite", {{"a", nonfinite_json(m.nonfinite_a)}, {"b", nonfinite_json(m.nonfinite_b)}}},
      {"metrics", metrics},
      {"max_abs_at", m.max_channel < 0 ? nlohmann::json(nullptr)
                                       : nlohmann::json{{"x", m.max_at.x}, {"y", m.max_at.y}, {"channel", m.max_channel}}},
      {"psnr_peak", number(m.psnr_peak)},
      {"mean", {{"a", number(m.mean_a)}, {"b", number(m.mean_b)}, {"diff_percent", number(m.mean_diff_percent)}}},
  };
}

int image_channels(const std::filesystem::path& file) {
  std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(file.string());
  if (!in) {
    std::string reason = OIIO::geterror();
    for (char& c : reason) {
      if (c == '\n' || c == '\r') c = ' ';
    }
    throw InputError(file.string() + ": cannot read image: " + (reason.empty() ? "unknown error" : reason));
  }
  const int channels = in->spec().nchannels;
  in->close();
  return channels;
}

std::array<std::uint8_t, 3> heatmap_colour(double t) {
  t = std::isnan(t) ? 0.0 : std::clamp(t, 0.0, 1.0);
  std::size_t i = 1;
  while (i + 1 < std::size(kInferno) && t > kInferno[i].t) ++i;
  const ControlPoint& lo = kInferno[i - 1];
  const ControlPoint& hi = kInferno[i];
  const double f = (t - lo.t) / (hi.t - lo.t);
  std::array<std::uint8_t, 3> out{};
  for (int c = 0; c < 3; ++c)
    out[c] = static_cast<std::uint8_t>(std::lround(lo.rgb[c] + f * (hi.rgb[c] - lo.rgb[c])));
  return out;
}

Image error_heatmap(const Image& a, const Image& b, double* scale) {
  check_same_size(a, b);
  const std::size_t n = a.pixels.size();
  std::vector<double> error(n, kNaN);
  std::vector<double> finite;
  finite.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const vec3& pa = a.pixels[i];
    const vec3& pb = b.pixels[i];
    if (!is_finite(pa) || !is_finite(pb)) continue;
    double e = 0.0;
    for (int c = 0; c < 3; ++c) e += std::abs(static_cast<double>(pa[c]) - static_cast<double>(pb[c]));
    error[i] = e / 3.0;
    finite.push_back(error[i]);
  }

  // Nearest-rank 99th percentile: the ceil(0.99 n)-th smallest error.
  double s = 0.0;
  if (!finite.empty()) {
    const std::size_t rank = static_cast<std::size_t>(std::ceil(0.99 * static_cast<double>(finite.size())));
    const auto k = finite.begin() + static_cast<std::ptrdiff_t>(std::max<std::size_t>(rank, 1) - 1);
    std::nth_element(finite.begin(), k, finite.end());
    s = *k;
    if (s <= 0.0) s = *std::max_element(finite.begin(), finite.end());
  }
  if (scale != nullptr) *scale = s;

  // Codes -> linear floats that write_png encodes back into the same codes.
  const auto to_linear = [](const std::array<std::uint8_t, 3>& code) {
    return vec3(srgb_to_linear(code[0] / 255.0f), srgb_to_linear(code[1] / 255.0f), srgb_to_linear(code[2] / 255.0f));
  };
  Image out(a.width, a.height);
  for (std::size_t i = 0; i < n; ++i) {
    if (std::isnan(error[i])) out.pixels[i] = to_linear(kHeatmapNonFinite);
    else out.pixels[i] = to_linear(heatmap_colour(s > 0.0 ? error[i] / s : 0.0));
  }
  return out;
}

}  // namespace pathlab
