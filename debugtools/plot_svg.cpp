#include "debugtools/plot_svg.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace pathlab {

namespace {

// Colour-blind-friendly categorical colours (Okabe-Ito, then grey shades).
constexpr const char* kColours[] = {"#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00",
                                    "#56B4E9", "#000000", "#F0E442", "#666666", "#999999"};

std::string escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

// "0.01", "1", "1000" for |k| <= 3; "1e-5", "1e6" beyond.
std::string decade_label(int k) {
  if (k >= 0 && k <= 3) return std::to_string(static_cast<int>(std::pow(10, k)));
  if (k < 0 && k >= -3) return "0." + std::string(static_cast<std::size_t>(-k - 1), '0') + "1";
  return "1e" + std::to_string(k);
}

}  // namespace

const char* const kNothingToPlot =
    "No point to draw on logarithmic axes: every value is 0 or not finite (an exact estimator has RMSE 0).";

std::string loglog_svg(const LogLogPlot& plot) {
  double xmin = std::numeric_limits<double>::infinity(), xmax = 0, ymin = xmin, ymax = 0;
  for (const PlotSeries& s : plot.series)
    for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i)
      if (s.x[i] > 0 && s.y[i] > 0 && std::isfinite(s.x[i]) && std::isfinite(s.y[i])) {
        xmin = std::min(xmin, s.x[i]), xmax = std::max(xmax, s.x[i]);
        ymin = std::min(ymin, s.y[i]), ymax = std::max(ymax, s.y[i]);
      }
  if (!(xmax > 0)) {
    // Nothing has a logarithm (an exact estimator's RMSE is 0): say so
    // rather than draw empty axes or fail the report.
    std::ostringstream o;
    o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"640\" height=\"120\" viewBox=\"0 0 640 120\" "
      << "font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
      << "<text x=\"20\" y=\"30\" font-size=\"14\">" << escape(plot.title) << "</text>\n"
      << "<text x=\"20\" y=\"70\">" << kNothingToPlot << "</text>\n</svg>\n";
    return o.str();
  }
  const int x0 = static_cast<int>(std::floor(std::log10(xmin))), x1 = std::max(x0 + 1, static_cast<int>(std::ceil(std::log10(xmax))));
  const int y0 = static_cast<int>(std::floor(std::log10(ymin))), y1 = std::max(y0 + 1, static_cast<int>(std::ceil(std::log10(ymax))));

  // Equal length per decade on both axes, chosen to fit a 560 x 420 frame.
  const double decade = std::min(560.0 / (x1 - x0), 420.0 / (y1 - y0));
  const double left = 80, top = 40, w = decade * (x1 - x0), h = decade * (y1 - y0);
  const double legend_w = 260, legend_row = 20;
  const double width = left + w + 30 + legend_w, height = std::max(top + h + 60, top + 20 + legend_row * (plot.series.size() + 1));
  const auto px = [&](double x) { return left + (std::log10(x) - x0) * decade; };
  const auto py = [&](double y) { return top + h - (std::log10(y) - y0) * decade; };

  std::ostringstream o;
  o.precision(5);
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height
    << "\" viewBox=\"0 0 " << width << " " << height << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
    << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    << "<text x=\"" << left << "\" y=\"22\" font-size=\"14\">" << escape(plot.title)
    << "</text>\n";
  // Grid and ticks: a line and label at each decade, short ticks at 2..9.
  for (int k = x0; k <= x1; ++k) {
    const double x = px(std::pow(10.0, k));
    o << "<line x1=\"" << x << "\" y1=\"" << top << "\" x2=\"" << x << "\" y2=\"" << top + h
      << "\" stroke=\"#dddddd\"/>\n<text x=\"" << x << "\" y=\"" << top + h + 18 << "\" text-anchor=\"middle\">"
      << decade_label(k) << "</text>\n";
    for (int m = 2; m <= 9 && k < x1; ++m) {
      const double xm = px(m * std::pow(10.0, k));
      o << "<line x1=\"" << xm << "\" y1=\"" << top + h << "\" x2=\"" << xm << "\" y2=\"" << top + h - 5
        << "\" stroke=\"black\"/>\n";
    }
  }
  for (int k = y0; k <= y1; ++k) {
    const double y = py(std::pow(10.0, k));
    o << "<line x1=\"" << left << "\" y1=\"" << y << "\" x2=\"" << left + w << "\" y2=\"" << y
      << "\" stroke=\"#dddddd\"/>\n<text x=\"" << left - 6 << "\" y=\"" << y + 4 << "\" text-anchor=\"end\">"
      << decade_label(k) << "</text>\n";
    for (int m = 2; m <= 9 && k < y1; ++m) {
      const double ym = py(m * std::pow(10.0, k));
      o << "<line x1=\"" << left << "\" y1=\"" << ym << "\" x2=\"" << left + 5 << "\" y2=\"" << ym
        << "\" stroke=\"black\"/>\n";
    }
  }
  o << "<rect x=\"" << left << "\" y=\"" << top << "\" width=\"" << w << "\" height=\"" << h
    << "\" fill=\"none\" stroke=\"black\"/>\n"
    << "<text x=\"" << left + w / 2 << "\" y=\"" << top + h + 40 << "\" text-anchor=\"middle\">" << escape(plot.x_label)
    << " (log scale)</text>\n"
    << "<text transform=\"translate(20," << top + h / 2 << ") rotate(-90)\" text-anchor=\"middle\">"
    << escape(plot.y_label) << " (log scale)</text>\n";
  // Series and legend.
  for (std::size_t i = 0; i < plot.series.size(); ++i) {
    const PlotSeries& s = plot.series[i];
    const char* colour = kColours[i % std::size(kColours)];
    std::ostringstream pts;
    pts.precision(6);
    std::vector<std::pair<double, double>> xy;
    for (std::size_t j = 0; j < std::min(s.x.size(), s.y.size()); ++j)
      if (s.x[j] > 0 && s.y[j] > 0 && std::isfinite(s.x[j]) && std::isfinite(s.y[j])) xy.emplace_back(px(s.x[j]), py(s.y[j]));
    for (const auto& [x, y] : xy) pts << x << "," << y << " ";
    const char* dash = i % 2 ? " stroke-dasharray=\"7,4\"" : "";
    o << "<polyline fill=\"none\" stroke=\"" << colour << "\" stroke-width=\"1.5\"" << dash << " points=\"" << pts.str()
      << "\"/>\n";
    for (const auto& [x, y] : xy)
      o << "<circle cx=\"" << x << "\" cy=\"" << y << "\" r=\"3\" fill=\"" << colour << "\"/>\n";
    const double ly = top + 10 + legend_row * static_cast<double>(i), lx = left + w + 30;
    o << "<line x1=\"" << lx << "\" y1=\"" << ly << "\" x2=\"" << lx + 24 << "\" y2=\"" << ly << "\" stroke=\"" << colour
      << "\" stroke-width=\"1.5\"" << dash << "/><circle cx=\"" << lx + 12 << "\" cy=\"" << ly << "\" r=\"3\" fill=\"" << colour
      << "\"/><text x=\"" << lx + 30 << "\" y=\"" << ly + 4 << "\">" << escape(s.label) << "</text>\n";
  }
  if (plot.guide_slope != 0.0 && !plot.series.empty() && !plot.series.front().x.empty()) {
    // y = y0 (x / x0)^slope across the whole x range, clipped to the frame.
    const double gx = plot.series.front().x.front(), gy = plot.series.front().y.front();
    if (gx > 0 && gy > 0) {
      const auto at = [&](double x) { return gy * std::pow(x / gx, plot.guide_slope); };
      const double xa = std::pow(10.0, x0), xb = std::pow(10.0, x1);
      o << "<clipPath id=\"frame\"><rect x=\"" << left << "\" y=\"" << top << "\" width=\"" << w << "\" height=\"" << h
        << "\"/></clipPath>\n<line clip-path=\"url(#frame)\" x1=\"" << px(xa) << "\" y1=\"" << py(at(xa)) << "\" x2=\""
        << px(xb) << "\" y2=\"" << py(at(xb)) << "\" stroke=\"#888888\" stroke-dasharray=\"2,3\"/>\n";
      const double ly = top + 10 + legend_row * static_cast<double>(plot.series.size()), lx = left + w + 30;
      o << "<line x1=\"" << lx << "\" y1=\"" << ly << "\" x2=\"" << lx + 24 << "\" y2=\"" << ly
        << "\" stroke=\"#888888\" stroke-dasharray=\"2,3\"/><text x=\"" << lx + 30 << "\" y=\"" << ly + 4 << "\">"
        << escape(plot.guide_label) << "</text>\n";
    }
  }
  o << "</svg>\n";
  return o.str();
}

}  // namespace pathlab
