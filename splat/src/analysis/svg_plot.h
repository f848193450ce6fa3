#pragma once
// Inline SVG line plots for the HTML reports: polylines with a legend, axes with ticks and
// labels, linear or logarithmic axes, shaded vertical bands and dashed vertical markers.
// The SVG is meant to be embedded in an HTML5 page (no xmlns, no external references);
// the <svg> element carries class="plot".
#include <limits>
#include <string>
#include <vector>

namespace splat::report {

struct PlotSeries {
    std::string name;
    std::string color;  ///< any CSS colour
    std::vector<double> x, y;
    bool markers = false;  ///< a dot at every point
    bool dashed = false;
};

struct PlotBand {
    double from = 0, to = 0;  ///< x range
    std::string label;        ///< shown as a tooltip
};

struct PlotMarker {
    double x = 0;
    std::string label;  ///< shown as a tooltip
};

struct LinePlot {
    std::string title, xLabel, yLabel;
    int width = 800, height = 260;
    bool logX = false, logY = false;
    /// The x range when both are finite (else fitted to the data, bands and markers).
    double xFrom = std::numeric_limits<double>::quiet_NaN(), xTo = xFrom;
    std::vector<PlotSeries> series;
    std::vector<PlotBand> bands;      ///< shaded (events)
    std::vector<PlotMarker> markers;  ///< dashed vertical lines (predicted switches)
    std::string bandLegend = "event", markerLegend = "predicted switch";
    /// Renders the plot. Points that are not finite (or not positive on a log axis) break
    /// the polyline. A plot with no drawable point says so instead of drawing axes.
    std::string svg() const;
};

/// "Nice" tick positions covering [lo, hi] (about `target` of them), for a linear axis.
std::vector<double> niceTicks(double lo, double hi, int target = 6);
/// A number formatted compactly for a tick label or a table (up to `digits` significant).
std::string formatNumber(double v, int digits = 4);

}  // namespace splat::report
