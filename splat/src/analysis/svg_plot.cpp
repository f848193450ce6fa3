// Inline SVG line plots (see svg_plot.h).
#include "analysis/svg_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "analysis/html_report.h"

namespace splat::report {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Plot area margins, pixels.
constexpr double kLeft = 68, kRight = 150, kTop = 30, kBottom = 44;

std::string num(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.2f", v);
    return buf;
}

struct Axis {
    bool log = false;
    double lo = 0, hi = 1;  ///< data range (log axes: positive)
    double p0 = 0, p1 = 1;  ///< pixel positions of lo and hi

    double t(double v) const { return log ? std::log10(v) : v; }
    double map(double v) const {
        const double a = t(lo), b = t(hi);
        return p0 + (t(v) - a) / (b - a) * (p1 - p0);
    }
    bool drawable(double v) const { return std::isfinite(v) && (!log || v > 0); }

    std::vector<double> ticks() const {
        if (!log) return niceTicks(lo, hi);
        std::vector<double> out;
        const int e0 = int(std::floor(std::log10(lo) + 1e-9)),
                  e1 = int(std::ceil(std::log10(hi) - 1e-9));
        const double eps = 1e-9 * (std::log10(hi) - std::log10(lo));
        auto inside = [&](double v) {
            return std::log10(v) >= std::log10(lo) - eps && std::log10(v) <= std::log10(hi) + eps;
        };
        for (int e = e0; e <= e1; ++e)
            if (inside(std::pow(10.0, e))) out.push_back(std::pow(10.0, e));
        if (out.size() < 2) {
            out.clear();
            for (int e = e0 - 1; e <= e1; ++e)
                for (double m : {1.0, 2.0, 5.0})
                    if (inside(m * std::pow(10.0, e))) out.push_back(m * std::pow(10.0, e));
        }
        if (out.size() < 2) {
            // Less than a factor 2.5: linear ticks in the log domain.
            for (double v : niceTicks(lo, hi, 4))
                if (v > 0 && inside(v)) out.push_back(v);
            std::sort(out.begin(), out.end());
            out.erase(std::unique(out.begin(), out.end()), out.end());
        }
        return out;
    }
};

// Sets lo/hi of an axis from values (only drawable ones count); false if none.
bool fitRange(Axis& axis, const std::vector<double>& values, bool includeZero) {
    double lo = kInf, hi = -kInf;
    for (double v : values)
        if (axis.drawable(v)) {
            lo = std::min(lo, v);
            hi = std::max(hi, v);
        }
    if (!(lo <= hi)) return false;
    if (axis.log) {
        if (hi / lo < 1.0001) {
            lo /= 2;
            hi *= 2;
        } else {
            const double pad = 0.04 * (std::log10(hi) - std::log10(lo));
            lo = std::pow(10.0, std::log10(lo) - pad);
            hi = std::pow(10.0, std::log10(hi) + pad);
        }
    } else {
        if (includeZero) {
            lo = std::min(lo, 0.0);
            hi = std::max(hi, 0.0);
        }
        if (hi - lo <= 1e-300 * std::max(1.0, std::abs(hi))) {
            const double d = std::abs(hi) > 0 ? 0.5 * std::abs(hi) : 1.0;
            lo -= includeZero && lo == 0 ? 0 : d;
            hi += d;
        } else if (includeZero) {
            hi += 0.05 * (hi - lo);
        }
    }
    axis.lo = lo;
    axis.hi = hi;
    return true;
}

}  // namespace

std::string formatNumber(double v, int digits) {
    if (!std::isfinite(v)) return std::isnan(v) ? "–" : (v > 0 ? "∞" : "−∞");
    if (v == 0) return "0";
    char buf[48];
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
    return buf;
}

std::vector<double> niceTicks(double lo, double hi, int target) {
    std::vector<double> out;
    if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi)) {
        if (std::isfinite(lo)) out.push_back(lo);
        return out;
    }
    const double raw = (hi - lo) / std::max(target, 1);
    const double mag = std::pow(10.0, std::floor(std::log10(raw)));
    double step = mag;
    for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
        if (m * mag >= raw) {
            step = m * mag;
            break;
        }
    const double first = std::ceil(lo / step - 1e-9) * step;
    for (double v = first; v <= hi + 1e-9 * step; v += step)
        out.push_back(std::abs(v) < 1e-12 * step ? 0.0 : v);
    return out;
}

namespace {

/// The axes of `plot`, fitted to its drawable points, bands, markers and fixed x range; false
/// when no point can be drawn.
bool fitAxes(const LinePlot& plot, Axis& xa, Axis& ya) {
    xa.log = plot.logX;
    ya.log = plot.logY;
    xa.p0 = kLeft;
    xa.p1 = plot.width - kRight;
    ya.p0 = plot.height - kBottom;
    ya.p1 = kTop;
    std::vector<double> xs, ys;
    for (const PlotSeries& ps : plot.series)
        for (std::size_t i = 0; i < std::min(ps.x.size(), ps.y.size()); ++i)
            if (xa.drawable(ps.x[i]) && ya.drawable(ps.y[i])) {
                xs.push_back(ps.x[i]);
                ys.push_back(ps.y[i]);
            }
    const bool any = !xs.empty();
    for (const PlotBand& b : plot.bands) {
        xs.push_back(b.from);
        xs.push_back(b.to);
    }
    for (const PlotMarker& m : plot.markers) xs.push_back(m.x);
    const bool fixedRange = std::isfinite(plot.xFrom) && std::isfinite(plot.xTo) &&
                            plot.xFrom < plot.xTo && (!plot.logX || plot.xFrom > 0);
    if (fixedRange) {
        xs.push_back(plot.xFrom);
        xs.push_back(plot.xTo);
    }
    if (!any || !fitRange(xa, xs, false) || !fitRange(ya, ys, !plot.logY)) return false;
    if (fixedRange) {
        xa.lo = plot.xFrom;
        xa.hi = plot.xTo;
    }
    return true;
}

/// The svg element, its white background and the title.
void writeHeader(std::ostringstream& s, const LinePlot& plot) {
    s << "<svg class=\"plot\" role=\"img\" width=\"" << plot.width << "\" height=\"" << plot.height
      << "\" viewBox=\"0 0 " << plot.width << ' ' << plot.height << "\" aria-label=\""
      << escapeHtml(plot.title) << "\">\n";
    s << "<rect x=\"0\" y=\"0\" width=\"" << plot.width << "\" height=\"" << plot.height
      << "\" fill=\"#fff\"/>\n";
    s << "<text x=\"" << num(kLeft) << "\" y=\"18\" class=\"plot-title\">" << escapeHtml(plot.title)
      << "</text>\n";
}

/// Bands (events), clipped to the plot area, at least 2 pixels wide.
void writeBands(std::ostringstream& s, const LinePlot& plot, const Axis& xa, const Axis& ya) {
    const double top = ya.p1, bottom = ya.p0;
    for (const PlotBand& b : plot.bands) {
        if (!xa.drawable(b.from) || !xa.drawable(b.to)) continue;
        double x0 = std::clamp(xa.map(std::min(b.from, b.to)), xa.p0, xa.p1);
        double x1 = std::clamp(xa.map(std::max(b.from, b.to)), xa.p0, xa.p1);
        if (x1 - x0 < 2) {
            const double c = 0.5 * (x0 + x1);
            x0 = c - 1;
            x1 = c + 1;
        }
        s << "<rect class=\"band\" x=\"" << num(x0) << "\" y=\"" << num(top) << "\" width=\""
          << num(x1 - x0) << "\" height=\"" << num(bottom - top)
          << "\" fill=\"#f4a261\" fill-opacity=\"0.28\"><title>" << escapeHtml(b.label)
          << "</title></rect>\n";
    }
}

/// Grid lines, ticks and their labels, the frame and the axis labels.
void writeAxes(std::ostringstream& s, const LinePlot& plot, const Axis& xa, const Axis& ya) {
    const double top = ya.p1, bottom = ya.p0;
    s << "<g class=\"axes\" font-size=\"11\" fill=\"#333\">\n";
    for (double v : xa.ticks()) {
        const double x = xa.map(v);
        if (x < xa.p0 - 0.5 || x > xa.p1 + 0.5) continue;
        s << "<line x1=\"" << num(x) << "\" y1=\"" << num(top) << "\" x2=\"" << num(x) << "\" y2=\""
          << num(bottom) << "\" stroke=\"#e6e6e6\"/>"
          << "<line x1=\"" << num(x) << "\" y1=\"" << num(bottom) << "\" x2=\"" << num(x)
          << "\" y2=\"" << num(bottom + 4) << "\" stroke=\"#333\"/>"
          << "<text x=\"" << num(x) << "\" y=\"" << num(bottom + 16) << "\" text-anchor=\"middle\">"
          << formatNumber(v) << "</text>\n";
    }
    for (double v : ya.ticks()) {
        const double y = ya.map(v);
        if (y < top - 0.5 || y > bottom + 0.5) continue;
        s << "<line x1=\"" << num(xa.p0) << "\" y1=\"" << num(y) << "\" x2=\"" << num(xa.p1)
          << "\" y2=\"" << num(y) << "\" stroke=\"#e6e6e6\"/>"
          << "<line x1=\"" << num(xa.p0 - 4) << "\" y1=\"" << num(y) << "\" x2=\"" << num(xa.p0)
          << "\" y2=\"" << num(y) << "\" stroke=\"#333\"/>"
          << "<text x=\"" << num(xa.p0 - 7) << "\" y=\"" << num(y + 4) << "\" text-anchor=\"end\">"
          << formatNumber(v, 3) << "</text>\n";
    }
    s << "<rect x=\"" << num(xa.p0) << "\" y=\"" << num(top) << "\" width=\"" << num(xa.p1 - xa.p0)
      << "\" height=\"" << num(bottom - top) << "\" fill=\"none\" stroke=\"#333\"/>\n";
    s << "<text x=\"" << num(0.5 * (xa.p0 + xa.p1)) << "\" y=\"" << num(plot.height - 8)
      << "\" text-anchor=\"middle\" font-size=\"12\">" << escapeHtml(plot.xLabel)
      << (plot.logX ? " (log)" : "") << "</text>\n";
    s << "<text transform=\"translate(14," << num(0.5 * (top + bottom))
      << ") rotate(-90)\" text-anchor=\"middle\" font-size=\"12\">" << escapeHtml(plot.yLabel)
      << (plot.logY ? " (log)" : "") << "</text>\n";
    s << "</g>\n";
}

/// Markers (predicted switches): dashed vertical lines inside the plot area.
void writeMarkers(std::ostringstream& s, const LinePlot& plot, const Axis& xa, const Axis& ya) {
    for (const PlotMarker& m : plot.markers) {
        if (!xa.drawable(m.x)) continue;
        const double x = xa.map(m.x);
        if (x < xa.p0 - 0.5 || x > xa.p1 + 0.5) continue;
        s << "<line class=\"marker\" x1=\"" << num(x) << "\" y1=\"" << num(ya.p1) << "\" x2=\""
          << num(x) << "\" y2=\"" << num(ya.p0)
          << "\" stroke=\"#555\" stroke-width=\"1.2\" stroke-dasharray=\"5 4\"><title>"
          << escapeHtml(m.label) << "</title></line>\n";
    }
}

/// One series: polylines broken at points that cannot be drawn, and its dots.
void writeSeries(std::ostringstream& s, const PlotSeries& ps, const Axis& xa, const Axis& ya) {
    s << "<g class=\"series\" stroke=\"" << escapeHtml(ps.color) << "\" fill=\"none\""
      << (ps.dashed ? " stroke-dasharray=\"6 3\"" : "") << ">"
      << "<title>" << escapeHtml(ps.name) << "</title>\n";
    std::string points;
    std::vector<std::pair<double, double>> dots;
    auto flush = [&] {
        if (!points.empty())
            s << "<polyline stroke-width=\"1.6\" stroke-linejoin=\"round\" points=\"" << points
              << "\"/>\n";
        points.clear();
    };
    for (std::size_t i = 0; i < std::min(ps.x.size(), ps.y.size()); ++i) {
        if (!xa.drawable(ps.x[i]) || !ya.drawable(ps.y[i])) {
            flush();
            continue;
        }
        const double x = xa.map(ps.x[i]), y = ya.map(ps.y[i]);
        if (!points.empty()) points += ' ';
        points += num(x) + ',' + num(y);
        dots.emplace_back(x, y);
    }
    flush();
    if (ps.markers || dots.size() == 1)
        for (auto [x, y] : dots)
            s << "<circle cx=\"" << num(x) << "\" cy=\"" << num(y) << "\" r=\"2.6\" fill=\""
              << escapeHtml(ps.color) << "\"/>";
    s << "</g>\n";
}

/// The legend right of the plot area: the series, then the bands and markers if any.
void writeLegend(std::ostringstream& s, const LinePlot& plot, const Axis& xa, const Axis& ya) {
    s << "<g class=\"legend\" font-size=\"12\" fill=\"#222\">\n";
    double ly = ya.p1 + 6;
    const double lx = xa.p1 + 14;
    for (const PlotSeries& ps : plot.series) {
        s << "<line x1=\"" << num(lx) << "\" y1=\"" << num(ly) << "\" x2=\"" << num(lx + 22)
          << "\" y2=\"" << num(ly) << "\" stroke=\"" << escapeHtml(ps.color)
          << "\" stroke-width=\"2.5\"" << (ps.dashed ? " stroke-dasharray=\"6 3\"" : "")
          << "/><text x=\"" << num(lx + 28) << "\" y=\"" << num(ly + 4) << "\">"
          << escapeHtml(ps.name) << "</text>\n";
        ly += 18;
    }
    if (!plot.bands.empty()) {
        s << "<rect x=\"" << num(lx) << "\" y=\"" << num(ly - 6) << "\" width=\"22\" height=\"12\""
          << " fill=\"#f4a261\" fill-opacity=\"0.35\"/><text x=\"" << num(lx + 28) << "\" y=\""
          << num(ly + 4) << "\">" << escapeHtml(plot.bandLegend) << "</text>\n";
        ly += 18;
    }
    if (!plot.markers.empty()) {
        s << "<line x1=\"" << num(lx) << "\" y1=\"" << num(ly) << "\" x2=\"" << num(lx + 22)
          << "\" y2=\"" << num(ly) << "\" stroke=\"#555\" stroke-dasharray=\"5 4\"/><text x=\""
          << num(lx + 28) << "\" y=\"" << num(ly + 4) << "\">" << escapeHtml(plot.markerLegend)
          << "</text>\n";
    }
    s << "</g>\n";
}

}  // namespace

std::string LinePlot::svg() const {
    std::ostringstream s;
    writeHeader(s, *this);
    Axis xa, ya;
    if (!fitAxes(*this, xa, ya)) {
        s << "<text x=\"" << num(width / 2.0) << "\" y=\"" << num(height / 2.0)
          << "\" text-anchor=\"middle\" class=\"plot-empty\">no data</text>\n</svg>\n";
        return s.str();
    }
    writeBands(s, *this, xa, ya);
    writeAxes(s, *this, xa, ya);
    writeMarkers(s, *this, xa, ya);
    for (const PlotSeries& ps : series) writeSeries(s, ps, xa, ya);
    writeLegend(s, *this, xa, ya);
    s << "</svg>\n";
    return s.str();
}

}  // namespace splat::report
