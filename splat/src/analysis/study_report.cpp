// Study reports: study.csv, study.json, pareto.svg and pareto.png (see splat/study.h).
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "splat/atomic_file.h"
#include "splat/error.h"
#include "splat/image_io.h"
#include "splat/study.h"

namespace splat {

namespace {

std::string num(double v) {
    if (!std::isfinite(v)) return "";
    std::ostringstream o;
    o.precision(6);
    o << v;
    return o.str();
}

std::string csvField(const std::string& s) {
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string out = "\"";
    for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
    return out + "\"";
}

std::string xmlEscape(const std::string& s) {
    std::string out;
    for (char c : s) {
        if (c == '<')
            out += "&lt;";
        else if (c == '>')
            out += "&gt;";
        else if (c == '&')
            out += "&amp;";
        else
            out += c;
    }
    return out;
}

/// Log-log plot frame: maps (ms, rmse) to plot coordinates.
struct Axes {
    double x0, x1, y0, y1;  ///< log10 ranges
    double left = 80, right = 170, top = 40, bottom = 60, width = 900, height = 560;
    static Axes of(const std::vector<StudyPoint>& pts) {
        double lx0 = 1e300, lx1 = -1e300, ly0 = 1e300, ly1 = -1e300;
        for (const auto& p : pts) {
            if (!(p.msMedian > 0)) continue;
            lx0 = std::min(lx0, std::log10(p.msMedian));
            lx1 = std::max(lx1, std::log10(p.msMedian));
            const double e = std::log10(std::max(p.rmse, 1e-12));
            ly0 = std::min(ly0, e);
            ly1 = std::max(ly1, e);
        }
        if (lx0 > lx1) lx0 = 0, lx1 = 1;
        if (ly0 > ly1) ly0 = -3, ly1 = 0;
        lx0 = std::floor(lx0 - 0.05), lx1 = std::ceil(lx1 + 0.05);
        ly0 = std::floor(ly0 - 0.05), ly1 = std::ceil(ly1 + 0.05);
        return {lx0, lx1, ly0, ly1};
    }
    double px(double ms) const {
        return left + (std::log10(ms) - x0) / (x1 - x0) * (width - left - right);
    }
    double py(double e) const {
        return height - bottom -
               (std::log10(std::max(e, 1e-12)) - y0) / (y1 - y0) * (height - top - bottom);
    }
};

std::vector<const StudyPoint*> frontOf(const std::vector<StudyPoint>& pts) {
    std::vector<const StudyPoint*> f;
    for (const auto& p : pts)
        if (p.pareto && p.msMedian > 0) f.push_back(&p);
    std::sort(f.begin(), f.end(), [](auto a, auto b) { return a->msMedian < b->msMedian; });
    return f;
}

/// A point of a quality preset (`--quality`), marked on the plot and always named.
bool isPresetPoint(const StudyPoint& p) {
    for (const auto& [knob, value] : p.knobs)
        if (knob == "quality") return true;
    return false;
}

/// The SVG mark of a point: a green diamond for a preset, else a dot (red on the front).
std::string svgMark(const StudyPoint& p, double x, double y) {
    std::ostringstream s;
    if (isPresetPoint(p))
        s << "<polygon points='" << x << ',' << y - 7 << ' ' << x + 7 << ',' << y << ' ' << x << ','
          << y + 7 << ' ' << x - 7 << ',' << y << "' fill='#2ca02c' stroke='black'>";
    else
        s << "<circle cx='" << x << "' cy='" << y << "' r='" << (p.pareto ? 5 : 3.5) << "' fill='"
          << (p.pareto ? "#d62728" : "#1f77b4") << "'>";
    s << "<title>" << xmlEscape(p.label()) << ": " << num(p.msMedian) << " ms, rmse " << num(p.rmse)
      << "</title>" << (isPresetPoint(p) ? "</polygon>" : "</circle>") << '\n';
    return s.str();
}

std::string svgPlot(const StudyResult& r) {
    const Axes ax = Axes::of(r.points);
    std::ostringstream s;
    s << "<svg xmlns='http://www.w3.org/2000/svg' width='" << ax.width << "' height='" << ax.height
      << "' font-family='sans-serif' font-size='12'>\n"
      << "<rect width='100%' height='100%' fill='white'/>\n";
    s << "<text x='" << ax.width / 2 << "' y='20' text-anchor='middle' font-size='14'>"
      << xmlEscape("error (RMSE vs reference) against time: " + r.volume) << "</text>\n";
    for (int d = int(ax.x0); d <= int(ax.x1); ++d) {
        const double x = ax.px(std::pow(10.0, d));
        s << "<line x1='" << x << "' y1='" << ax.top << "' x2='" << x << "' y2='"
          << ax.height - ax.bottom << "' stroke='#ddd'/>\n<text x='" << x << "' y='"
          << ax.height - ax.bottom + 16 << "' text-anchor='middle'>" << num(std::pow(10.0, d))
          << "</text>\n";
    }
    for (int d = int(ax.y0); d <= int(ax.y1); ++d) {
        const double y = ax.py(std::pow(10.0, d));
        s << "<line x1='" << ax.left << "' y1='" << y << "' x2='" << ax.width - ax.right << "' y2='"
          << y << "' stroke='#ddd'/>\n<text x='" << ax.left - 6 << "' y='" << y + 4
          << "' text-anchor='end'>1e" << d << "</text>\n";
    }
    s << "<text x='" << ax.width / 2 << "' y='" << ax.height - 20
      << "' text-anchor='middle'>median ms per frame (log)</text>\n"
      << "<text x='20' y='" << ax.height / 2 << "' transform='rotate(-90 20 " << ax.height / 2
      << ")' text-anchor='middle'>RMSE (log)</text>\n";
    const auto front = frontOf(r.points);
    if (front.size() > 1) {
        s << "<polyline fill='none' stroke='#d62728' stroke-width='1.5' points='";
        for (auto p : front) s << ax.px(p->msMedian) << ',' << ax.py(p->rmse) << ' ';
        s << "'/>\n";
    }
    for (const auto& p : r.points) {
        if (!(p.msMedian > 0)) continue;
        const double x = ax.px(p.msMedian), y = ax.py(p.rmse);
        s << svgMark(p, x, y);
        if (p.pareto || isPresetPoint(p))  // the others: named by tooltips and in study.csv
            s << "<text x='" << x + 7 << "' y='" << y - 5 << "' font-size='10' fill='#444'>"
              << xmlEscape(p.label()) << "</text>\n";
    }
    s << "</svg>\n";
    return s.str();
}

std::vector<unsigned char> plotPng(const StudyResult& r, const std::filesystem::path& path) {
    namespace IBA = OIIO::ImageBufAlgo;
    const Axes ax = Axes::of(r.points);
    OIIO::ImageBuf buf(OIIO::ImageSpec(int(ax.width), int(ax.height), 3, OIIO::TypeDesc::UINT8));
    const float white[] = {1, 1, 1}, grid[] = {0.87f, 0.87f, 0.87f}, black[] = {0, 0, 0};
    const float red[] = {0.84f, 0.15f, 0.16f}, blue[] = {0.12f, 0.47f, 0.71f},
                green[] = {0.17f, 0.63f, 0.17f};
    IBA::fill(buf, white);
    const std::string font = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
    const bool text = std::filesystem::exists(font);
    auto label = [&](int x, int y, const std::string& t, int size) {
        if (text) IBA::render_text(buf, x, y, t, size, font, black);
    };
    for (int d = int(ax.x0); d <= int(ax.x1); ++d) {
        const int x = int(ax.px(std::pow(10.0, d)));
        IBA::render_line(buf, x, int(ax.top), x, int(ax.height - ax.bottom), grid);
        label(x - 10, int(ax.height - ax.bottom + 18), num(std::pow(10.0, d)), 12);
    }
    for (int d = int(ax.y0); d <= int(ax.y1); ++d) {
        const int y = int(ax.py(std::pow(10.0, d)));
        IBA::render_line(buf, int(ax.left), y, int(ax.width - ax.right), y, grid);
        label(int(ax.left) - 40, y + 4, "1e" + std::to_string(d), 12);
    }
    IBA::render_box(buf, int(ax.left), int(ax.top), int(ax.width - ax.right),
                    int(ax.height - ax.bottom), black);
    label(int(ax.width / 2) - 90, int(ax.height) - 18, "median ms per frame (log)", 13);
    label(10, 24, "RMSE against the reference (log) vs time: " + r.volume, 13);
    const auto front = frontOf(r.points);
    for (std::size_t i = 0; i + 1 < front.size(); ++i)
        IBA::render_line(buf, int(ax.px(front[i]->msMedian)), int(ax.py(front[i]->rmse)),
                         int(ax.px(front[i + 1]->msMedian)), int(ax.py(front[i + 1]->rmse)), red);
    for (const auto& p : r.points) {
        if (!(p.msMedian > 0)) continue;
        const bool preset = isPresetPoint(p);
        const int x = int(ax.px(p.msMedian)), y = int(ax.py(p.rmse)),
                  h = preset     ? 5
                      : p.pareto ? 4
                                 : 3;
        IBA::render_box(buf, x - h, y - h, x + h, y + h,
                        preset     ? green
                        : p.pareto ? red
                                   : blue,
                        true);
        if (preset) IBA::render_box(buf, x - h, y - h, x + h, y + h, black);
        if (p.pareto || preset) label(x + 7, y - 5, p.label(), 10);  // others: see study.csv
    }
    // Encoded in memory; written with the other report files by the checked atomic writer.
    std::vector<float> px(std::size_t(ax.width) * std::size_t(ax.height) * 3);
    if (!buf.get_pixels(buf.roi(), OIIO::TypeDesc::FLOAT, px.data()))
        throw Error(path.string() + ": cannot draw the plot (" + buf.geterror() + ")");
    Image image(int(ax.width), int(ax.height));
    for (std::size_t n = 0; n < image.pixels.size(); ++n)
        image.pixels[n] = glm::vec4(px[3 * n], px[3 * n + 1], px[3 * n + 2], 1.0f);
    WriteOptions display;
    display.mapping = DisplayMapping::Display;
    try {
        return encodeImage(image, ".png", display);
    } catch (const Error& e) {
        throw Error(path.string() + ": " + e.what());
    }
}

}  // namespace

void writeStudyReport(const StudyResult& r, const std::string& dir,
                      const std::string& commandLine) {
    namespace fs = std::filesystem;
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (!fs::is_directory(dir)) throw Error(dir + ": cannot create the report folder");
    removeStaleTemporaries(dir);  // left by a killed run
    // CSV: one row per setting.
    std::vector<std::string> knobNames;
    for (const auto& k : r.options.sweeps) knobNames.push_back(k.name);
    // The quality presets measured beside the sweep (StudyOptions::presets): their own column.
    const bool presets = std::any_of(r.points.begin(), r.points.end(), isPresetPoint);
    if (presets && std::find(knobNames.begin(), knobNames.end(), "quality") == knobNames.end())
        knobNames.push_back("quality");
    std::ostringstream csv;
    for (const auto& k : knobNames) csv << k << ',';
    csv << "ms_median,ms_min,ms_max,ms_mad,peak_mib,splats,footprint_pixels,"
           "footprint_pixels_per_s,rmse,psnr,max_abs,flip,pareto,exact_frames,truth\n";
    for (const auto& p : r.points) {
        for (const auto& k : knobNames) {
            std::string v;
            for (const auto& [n, val] : p.knobs)
                if (n == k) v = val;
            csv << csvField(v) << ',';
        }
        csv << num(p.msMedian) << ',' << num(p.msMin) << ',' << num(p.msMax) << ',' << num(p.msMad)
            << ',' << num(p.peakMiB) << ',' << p.splats << ',' << p.footprintPixels << ','
            << num(p.footprintPixelRate) << ',' << num(p.rmse) << ',' << num(p.psnr) << ','
            << num(p.maxAbs) << ',' << num(p.flip) << ',' << (p.pareto ? 1 : 0) << ','
            << p.exactFrames << ','
            << (p.truthFilter > 0 ? "filtered " + num(p.truthFilter) : std::string("point"))
            << '\n';
    }
    const std::string csvText = csv.str();

    nlohmann::json j;
    j["command"] = commandLine;
    j["volume"] = r.volume;
    j["visible_voxels"] = r.visibleVoxels;
    j["mode"] = toString(r.base.mode);
    j["classification"] = toString(r.base.classification);
    j["size"] = std::to_string(r.base.camera.width) + "x" + std::to_string(r.base.camera.height);
    j["repeats"] = r.options.repeats;
    j["warmup"] = r.options.warmup;
    j["reference_step"] = r.options.referenceStep;
    j["reference_tolerance"] = r.options.referenceTolerance;
    j["flip_available"] = r.flipAvailable;
    j["total_seconds"] = r.totalMs / 1000.0;
    auto orNull = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
    for (const auto& p : r.points) {
        nlohmann::json o;
        for (const auto& [n, v] : p.knobs) o["knobs"][n] = v;
        o["label"] = p.label();
        o["ms_median"] = p.msMedian;
        o["ms_min"] = p.msMin;
        o["ms_max"] = p.msMax;
        o["ms_mad"] = p.msMad;
        o["peak_mib"] = p.peakMiB;
        o["splats"] = p.splats;
        o["footprint_pixels"] = p.footprintPixels;
        o["footprint_pixels_per_s"] = p.footprintPixelRate;
        o["rmse"] = orNull(p.rmse);
        o["psnr"] = orNull(p.psnr);
        o["max_abs"] = orNull(p.maxAbs);
        o["flip"] = orNull(p.flip);
        o["pareto"] = p.pareto;
        // Frames the splatter handed to the reference: their error says nothing.
        o["exact_frames"] = p.exactFrames;
        // The reference it was judged against: point-sampled, or pixel-filtered (sigma).
        o["truth"] = p.truthFilter > 0 ? "filtered" : "point";
        o["truth_filter"] = p.truthFilter;
        j["points"].push_back(o);
    }
    for (const auto& c : r.convergence) {
        nlohmann::json o;
        o["parameter"] = c.parameter;
        o["renderer"] = toString(c.renderer);
        o["h"] = c.h;
        o["error"] = c.error;
        o["order"] = c.order;
        j["convergence"].push_back(o);
    }
    const std::string json = j.dump(2) + "\n", svg = svgPlot(r);
    const std::vector<unsigned char> png = plotPng(r, fs::path(dir) / "pareto.png");
    // All four are written in full before any replaces a previous one: a failure leaves
    // the previous report whole, never a mix of two runs.
    AtomicFile files[] = {
        AtomicFile(fs::path(dir) / "study.csv"), AtomicFile(fs::path(dir) / "study.json"),
        AtomicFile(fs::path(dir) / "pareto.svg"), AtomicFile(fs::path(dir) / "pareto.png")};
    files[0].write(csvText.data(), csvText.size());
    files[1].write(json.data(), json.size());
    files[2].write(svg.data(), svg.size());
    files[3].write(png.data(), png.size());
    for (AtomicFile& f : files) f.sync();
    for (AtomicFile& f : files) f.commit();
}

}  // namespace splat
