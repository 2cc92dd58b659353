// Image comparison for `pathlab diff`. See image_metrics.h and docs/diff.md.
#include "debugtools/image_metrics.h"

#include "analytic-scenes/check.h"
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

ImageMetrics compare_images(const Image& a, const Image& b, double threshold) {
  check_same_size(a, b);
  if (!(threshold >= 0.0)) throw InputError("--threshold: expected a number >= 0");
  ImageMetrics m;
  m.threshold = threshold;
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
      int worst_c = 0;
      double worst_d = -1.0;
      for (int c = 0; c < 3; ++c) {
        const double dc = std::abs(static_cast<double>(pa[c]) - static_cast<double>(pb[c]));
        if (dc > worst_d) {
          worst_d = dc;
          worst_c = c;
        }
      }
      if (worst_d > threshold) {
        if (m.over++ == 0) {
          m.first_over = {x, y};
          m.first_over_channel = worst_c;
          m.first_over_a = pa[worst_c];
          m.first_over_b = pb[worst_c];
        }
      }
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
          m.max_value_a = va;
          m.max_value_b = vb;
        }
      }
    }
  }

  if (m.compared == 0) {
    m.over_fraction = kNaN;
    m.mae = m.mse = m.rmse = m.rel_mse = m.smape = m.max_abs = kNaN;
    m.mean_a = m.mean_b = m.mean_diff_percent = m.psnr = m.psnr_peak = kNaN;
    return m;
  }
  m.over_fraction = static_cast<double>(m.over) / static_cast<double>(m.compared);
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
  const auto located = [](PixelXY at, int channel, double a, double b) {
    return channel < 0 ? nlohmann::json(nullptr)
                       : nlohmann::json{{"x", at.x}, {"y", at.y}, {"channel", channel}, {"a", a}, {"b", b},
                                        {"abs_diff", std::abs(a - b)}};
  };
  return {
      {"format", "pathlab-diff"},
      {"version", 2},
      {"width", m.width},
      {"height", m.height},
      {"pixels", m.pixels},
      {"compared_pixels", m.compared},
      {"nonfinite", {{"a", nonfinite_json(m.nonfinite_a)}, {"b", nonfinite_json(m.nonfinite_b)}}},
      {"metrics", metrics},
      {"max_abs_at", m.max_channel < 0 ? nlohmann::json(nullptr)
                                       : nlohmann::json{{"x", m.max_at.x}, {"y", m.max_at.y}, {"channel", m.max_channel}}},
      {"worst", located(m.max_at, m.max_channel, m.max_value_a, m.max_value_b)},
      {"threshold", m.threshold},
      {"over_threshold", {{"count", m.over}, {"fraction", number(m.over_fraction)}}},
      {"first_over", located(m.first_over, m.first_over_channel, m.first_over_a, m.first_over_b)},
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
  // The base layer: channels of a named layer ("variance.R", "albedo.G")
  // are not the image's own.
  int channels = 0;
  for (const std::string& name : in->spec().channelnames) channels += name.find('.') == std::string::npos;
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

// ---------------------------------------------------------------- statistics

StatisticalDiff statistical_diff(const Image& a, const Image& b, const Image& var_a, const Image& var_b, double alpha,
                                 double threshold, bool correlated) {
  check_same_size(a, b);
  check_same_size(a, var_a);
  check_same_size(a, var_b);
  if (!(alpha > 0.0 && alpha < 1.0)) throw InputError("--alpha: expected a false-alarm rate in (0, 1)");
  const int w = a.width, h = a.height;
  StatisticalDiff r;
  r.alpha = alpha;
  r.correlated = correlated;
  r.pixel_z.assign(a.pixels.size(), kNaN);
  // The combined variance of d per pixel and channel; NaN where not usable.
  std::vector<dvec3> var(a.pixels.size(), dvec3(kNaN));
  std::vector<std::uint8_t> compared(a.pixels.size(), 0);
  for (std::size_t i = 0; i < a.pixels.size(); ++i) {
    compared[i] = is_finite(a.pixels[i]) && is_finite(b.pixels[i]);
    if (is_finite(var_a.pixels[i]) && is_finite(var_b.pixels[i]))
      var[i] = dvec3(var_a.pixels[i]) + dvec3(var_b.pixels[i]);
  }
  std::size_t n_compared = 0;
  for (std::uint8_t c : compared) n_compared += c;
  r.tests = 3 * n_compared;
  r.z_threshold = normal_two_sided_quantile(-std::expm1(std::log1p(-alpha) / std::max<double>(1.0, r.tests)));
  r.bias_threshold = normal_two_sided_quantile(-std::expm1(std::log1p(-alpha) / 3.0));
  dvec3 sum_d(0.0), sum_var(0.0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      if (!compared[i]) continue;
      bool pixel_fails = false;
      double pixel_max = 0.0;
      for (int c = 0; c < 3; ++c) {
        double v = 0.0;
        for (int ny = std::max(0, y - 1); ny <= std::min(h - 1, y + 1); ++ny)
          for (int nx = std::max(0, x - 1); nx <= std::min(w - 1, x + 1); ++nx) {
            const double vn = var[static_cast<std::size_t>(ny) * w + nx][c];
            if (std::isfinite(vn)) v = std::max(v, vn);
          }
        const double va = a.pixels[i][c], vb = b.pixels[i][c];
        const double d = va - vb;
        const double sigma = std::sqrt(v + threshold * threshold);
        const double z = d == 0.0 ? 0.0 : sigma > 0.0 ? d / sigma : (d > 0 ? kInf : -kInf);
        sum_d[c] += d;
        sum_var[c] += v + threshold * threshold;
        pixel_max = std::max(pixel_max, std::abs(z));
        const PixelZ here{{x, y}, c, z, va, vb, sigma};
        if (r.worst.channel < 0 || std::abs(z) > std::abs(r.worst.z)) r.worst = here;
        if (std::abs(z) > r.z_threshold) {
          if (r.failing++ == 0) r.first_failing = here;
          pixel_fails = true;
        }
      }
      r.pixel_z[i] = pixel_max;
      r.failing_pixels += pixel_fails;
    }
  const double pixels = static_cast<double>(std::max<std::size_t>(n_compared, 1));
  const double inflate = correlated ? 3.0 : 1.0;
  for (int c = 0; c < 3; ++c) {
    const double bias = sum_d[c] / pixels, se = std::sqrt(sum_var[c]) / pixels * inflate;
    const double z = bias == 0.0 ? 0.0 : se > 0.0 ? bias / se : (bias > 0 ? kInf : -kInf);
    if (c == 0 || std::abs(z) > std::abs(r.bias_z)) {
      r.bias_channel = c;
      r.bias = bias;
      r.bias_se = se;
      r.bias_z = z;
    }
  }
  r.pixels_pass = r.failing == 0;
  r.bias_pass = std::abs(r.bias_z) <= r.bias_threshold;
  r.pass = r.pixels_pass && r.bias_pass;
  return r;
}

nlohmann::json to_json(const StatisticalDiff& s) {
  const auto pz = [](const PixelZ& p) {
    return p.channel < 0 ? nlohmann::json(nullptr)
                         : nlohmann::json{{"x", p.at.x}, {"y", p.at.y}, {"channel", p.channel}, {"z", number(p.z)},
                                          {"a", p.a}, {"b", p.b}, {"sigma", p.sigma}};
  };
  return {{"alpha", s.alpha},
          {"tests", s.tests},
          {"z_threshold", s.z_threshold},
          {"failing", s.failing},
          {"failing_pixels", s.failing_pixels},
          {"worst", pz(s.worst)},
          {"first_failing", pz(s.first_failing)},
          {"correlated", s.correlated},
          {"bias", {{"channel", s.bias_channel}, {"value", s.bias}, {"se", s.bias_se}, {"z", number(s.bias_z)},
                    {"threshold", s.bias_threshold}, {"pass", s.bias_pass}}},
          {"pixels_pass", s.pixels_pass},
          {"pass", s.pass}};
}

std::optional<Image> read_variance_layer(const std::filesystem::path& file) {
  std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(file.string());
  if (!in) throw InputError(file.string() + ": cannot read image: " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  int index[3] = {-1, -1, -1};
  const char* names[3] = {"variance.R", "variance.G", "variance.B"};
  int found = 0;
  for (int c = 0; c < spec.nchannels; ++c)
    for (int k = 0; k < 3; ++k)
      if (spec.channelnames[static_cast<std::size_t>(c)] == names[k]) {
        index[k] = c;
        ++found;
      }
  if (found == 0) return std::nullopt;
  if (found != 3)
    throw InputError(file.string() + ": has only part of a variance layer (needs variance.R, variance.G and variance.B)");
  const int w = spec.width, h = spec.height, n = spec.nchannels;
  std::vector<float> all(static_cast<std::size_t>(w) * h * n);
  if (!in->read_image(0, 0, 0, n, OIIO::TypeFloat, all.data()))
    throw InputError(file.string() + ": cannot read the variance layer: " + in->geterror());
  Image out(w, h);
  for (std::size_t i = 0; i < out.pixels.size(); ++i)
    for (int k = 0; k < 3; ++k) out.pixels[i][k] = all[i * static_cast<std::size_t>(n) + static_cast<std::size_t>(index[k])];
  return out;
}

// ---------------------------------------------------------------- heatmap

std::vector<double> pixel_errors(const Image& a, const Image& b) {
  check_same_size(a, b);
  std::vector<double> e(a.pixels.size(), kNaN);
  for (std::size_t i = 0; i < e.size(); ++i) {
    const vec3& pa = a.pixels[i];
    const vec3& pb = b.pixels[i];
    if (!is_finite(pa) || !is_finite(pb)) continue;
    double m = 0.0;
    for (int c = 0; c < 3; ++c) m = std::max(m, std::abs(static_cast<double>(pa[c]) - static_cast<double>(pb[c])));
    e[i] = m;
  }
  return e;
}

HeatmapRange default_heatmap_range(const std::vector<double>& values, bool log, double neutral) {
  HeatmapRange r;
  r.log = log;
  r.neutral = neutral;
  std::vector<double> above;
  double smallest_positive = kInf;
  for (double v : values) {
    if (std::isnan(v) || v <= neutral) continue;
    above.push_back(v);
    if (v > 0.0) smallest_positive = std::min(smallest_positive, v);
  }
  r.lo = log ? (neutral > 0.0 ? neutral : smallest_positive) : 0.0;
  if (above.empty()) {
    if (!std::isfinite(r.lo)) r.lo = 1.0;
    r.hi = log ? 1000.0 * r.lo : r.lo + 1.0;
    return r;
  }
  const std::size_t rank = static_cast<std::size_t>(std::ceil(0.99 * static_cast<double>(above.size())));
  const auto k = above.begin() + static_cast<std::ptrdiff_t>(std::max<std::size_t>(rank, 1) - 1);
  std::nth_element(above.begin(), k, above.end());
  r.hi = *k;
  if (!(r.hi > r.lo)) r.hi = *std::max_element(above.begin(), above.end());
  if (log && !(r.lo < r.hi)) r.lo = r.hi / 1000.0;
  if (!(r.hi > r.lo)) r.hi = r.lo + 1.0;
  return r;
}

namespace {

// 5x7 glyphs, one byte per row, bit 4 = leftmost column.
struct Glyph {
  char c;
  std::uint8_t rows[7];
};
constexpr Glyph kFont[] = {
    {'0', {0x0e, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0e}}, {'1', {0x04, 0x0c, 0x04, 0x04, 0x04, 0x04, 0x0e}},
    {'2', {0x0e, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1f}}, {'3', {0x1f, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0e}},
    {'4', {0x02, 0x06, 0x0a, 0x12, 0x1f, 0x02, 0x02}}, {'5', {0x1f, 0x10, 0x1e, 0x01, 0x01, 0x11, 0x0e}},
    {'6', {0x06, 0x08, 0x10, 0x1e, 0x11, 0x11, 0x0e}}, {'7', {0x1f, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}},
    {'8', {0x0e, 0x11, 0x11, 0x0e, 0x11, 0x11, 0x0e}}, {'9', {0x0e, 0x11, 0x11, 0x0f, 0x01, 0x02, 0x0c}},
    {'.', {0x00, 0x00, 0x00, 0x00, 0x00, 0x0c, 0x0c}}, {'-', {0x00, 0x00, 0x00, 0x1f, 0x00, 0x00, 0x00}},
    {'+', {0x00, 0x04, 0x04, 0x1f, 0x04, 0x04, 0x00}}, {'e', {0x00, 0x00, 0x0e, 0x11, 0x1f, 0x10, 0x0e}},
    {'<', {0x02, 0x04, 0x08, 0x10, 0x08, 0x04, 0x02}}, {'=', {0x00, 0x00, 0x1f, 0x00, 0x1f, 0x00, 0x00}},
    {'|', {0x04, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04}}, {'a', {0x00, 0x00, 0x0e, 0x01, 0x0f, 0x11, 0x0f}},
    {'d', {0x01, 0x01, 0x0d, 0x13, 0x11, 0x11, 0x0f}}, {'g', {0x00, 0x00, 0x0f, 0x11, 0x0f, 0x01, 0x0e}},
    {'i', {0x04, 0x00, 0x0c, 0x04, 0x04, 0x04, 0x0e}}, {'l', {0x0c, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0e}},
    {'m', {0x00, 0x00, 0x1a, 0x15, 0x15, 0x11, 0x11}}, {'n', {0x00, 0x00, 0x16, 0x19, 0x11, 0x11, 0x11}},
    {'o', {0x00, 0x00, 0x0e, 0x11, 0x11, 0x11, 0x0e}}, {'r', {0x00, 0x00, 0x16, 0x19, 0x10, 0x10, 0x10}},
    {'s', {0x00, 0x00, 0x0e, 0x10, 0x0e, 0x01, 0x1e}}, {'t', {0x08, 0x08, 0x1c, 0x08, 0x08, 0x09, 0x06}},
    {'u', {0x00, 0x00, 0x11, 0x11, 0x11, 0x13, 0x0d}}, {'x', {0x00, 0x00, 0x11, 0x0a, 0x04, 0x0a, 0x11}},
    {'z', {0x00, 0x00, 0x1f, 0x02, 0x04, 0x08, 0x1f}}, {'A', {0x0e, 0x11, 0x11, 0x1f, 0x11, 0x11, 0x11}},
    {'B', {0x1e, 0x11, 0x11, 0x1e, 0x11, 0x11, 0x1e}}, {'N', {0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11}},
    {'(', {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02}}, {')', {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08}},
    {',', {0x00, 0x00, 0x00, 0x00, 0x0c, 0x04, 0x08}},
};

const Glyph* glyph(char c) {
  for (const Glyph& g : kFont)
    if (g.c == c) return &g;
  return nullptr;
}

vec3 code_to_linear(const std::array<std::uint8_t, 3>& code) {
  return vec3(srgb_to_linear(code[0] / 255.0f), srgb_to_linear(code[1] / 255.0f), srgb_to_linear(code[2] / 255.0f));
}

void fill(Image& image, int x0, int y0, int w, int h, const vec3& colour) {
  for (int y = std::max(0, y0); y < std::min(image.height, y0 + h); ++y)
    for (int x = std::max(0, x0); x < std::min(image.width, x0 + w); ++x) image.at(x, y) = colour;
}

}  // namespace

int text_width(const std::string& text, int scale) { return static_cast<int>(text.size()) * 6 * scale; }

void draw_text(Image& image, int x, int y, const std::string& text, const vec3& colour, int scale) {
  for (std::size_t k = 0; k < text.size(); ++k) {
    const Glyph* g = glyph(text[k]);
    if (g == nullptr) continue;
    const int gx = x + static_cast<int>(k) * 6 * scale;
    for (int row = 0; row < 7; ++row)
      for (int col = 0; col < 5; ++col)
        if (g->rows[row] & (0x10 >> col)) fill(image, gx + col * scale, y + row * scale, scale, scale, colour);
  }
}

std::string legend_number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", v);
  return text;
}

Image draw_heatmap(const std::vector<double>& values, int width, int height, const HeatmapRange& range,
                   const std::string& caption) {
  const int canvas_w = std::max(width, kLegendMinWidth);
  Image out(canvas_w, height + kLegendHeight);  // black
  const double span = range.log ? std::log(range.hi / range.lo) : range.hi - range.lo;
  const auto t_of = [&](double v) {
    const double t = range.log ? (v > 0.0 ? std::log(v / range.lo) : -kInf) / span : (v - range.lo) / span;
    return std::isnan(t) ? 0.0 : std::clamp(t, 0.0, 1.0);
  };
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const double v = values[static_cast<std::size_t>(y) * width + x];
      out.at(x, y) = std::isnan(v)              ? code_to_linear(kHeatmapNonFinite)
                     : v <= range.neutral       ? code_to_linear(kHeatmapNeutral)
                                                : code_to_linear(heatmap_colour(t_of(v)));
    }
  // The legend: a colour bar 6 px from the left and right, 10 px high; the
  // numbers under its ends and middle; the caption and the swatches below.
  const vec3 white(1.0f);
  const int bar_x = 6, bar_w = canvas_w - 12, bar_y = height + 4;
  for (int x = 0; x < bar_w; ++x)
    fill(out, bar_x + x, bar_y, 1, 10, code_to_linear(heatmap_colour(bar_w > 1 ? x / double(bar_w - 1) : 0.0)));
  const double mid = range.log ? std::sqrt(range.lo * range.hi) : 0.5 * (range.lo + range.hi);
  const std::string lo = legend_number(range.lo), mi = legend_number(mid), hi = legend_number(range.hi);
  const int numbers_y = bar_y + 12;
  draw_text(out, bar_x, numbers_y, lo, white);
  draw_text(out, bar_x + bar_w / 2 - text_width(mi) / 2, numbers_y, mi, white);
  draw_text(out, bar_x + bar_w - text_width(hi), numbers_y, hi, white);
  const int caption_y = numbers_y + 10;
  std::string line = caption + (range.log ? " log" : " lin");
  int x = bar_x;
  draw_text(out, x, caption_y, line, white);
  x += text_width(line) + 6;
  if (range.neutral >= 0.0) {
    fill(out, x, caption_y, 7, 7, code_to_linear(kHeatmapNeutral));
    const std::string label = "<=" + legend_number(range.neutral);
    draw_text(out, x + 9, caption_y, label, white);
    x += 9 + text_width(label) + 6;
  }
  fill(out, x, caption_y, 7, 7, code_to_linear(kHeatmapNonFinite));
  draw_text(out, x + 9, caption_y, "NaN", white);
  return out;
}

}  // namespace pathlab
