// A small, honest log-log line plot as SVG (plain text, no plotting
// dependency): both axes logarithmic with a tick and a label at every
// decade (and unlabelled ticks at 2..9 times it), axis titles, a legend, and
// one polyline with round markers per series (every other one dashed, so
// series that coincide stay visible), and optionally a dashed grey guide
// line of a given slope. The axes span whole decades
// around the data, so slopes read true: one decade is the same length on
// both axes, and a line of slope -1/2 falls one decade in y over two in x.
#pragma once

#include <string>
#include <vector>

namespace pathlab {

struct PlotSeries {
  std::string label;
  std::vector<double> x, y;  // points with x <= 0 or y <= 0 are left out
};

struct LogLogPlot {
  std::string title, x_label, y_label;
  std::vector<PlotSeries> series;
  // A guide of this slope through the first series' first point (0: none),
  // e.g. -0.5, the Monte Carlo rate of RMSE; labelled in the legend.
  double guide_slope = 0.0;
  std::string guide_label;
};

// The SVG document. With no point of positive x and y in any series (every
// RMSE 0: an exact estimator) it is the title and kNothingToPlot, not axes.
std::string loglog_svg(const LogLogPlot& plot);
extern const char* const kNothingToPlot;

}  // namespace pathlab
