// The popping report (splat/popping.h, writePoppingReport): report.html, metrics.csv and
// summary.json in one folder.
//
// metrics.csv columns: renderer, interval, angle_from, angle_to, T, J, flipT, e, flipRef,
// signal, is_event, truth, flipWarp1, flipWarp7. One row per renderer and interval (e and
// flipRef at angle_from; flipWarp1 the interval's StopThePop FLIP_1, flipWarp7 the FLIP_7 of
// views n and n + 7); a value that was not measured (no reference, no FLIP, no valid pixel,
// fewer than 8 views) is an empty cell. truth: the reference
// J, e and flipRef are against, "point" (one ray per pixel centre) or "filtered SIGMA" (the
// pixel-filtered reference, PoppingResult::truthFilter); empty without a reference. When the cross
// jump C was measured, rows with renderer "axis-sheet" follow: C in the J and signal columns,
// is_event 1 when any renderer has an event on that interval, the other columns empty.
//
// The folder: created when missing; refused when it is not a folder, or when it holds
// anything but a previous report's three files (and the hidden temporaries of an
// interrupted atomic write of them). All three files are built in memory first, so a
// failure leaves the folder as it was; then each is written atomically.
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>
#include <tuple>

#include "analysis/html_report.h"
#include "analysis/median.h"
#include "analysis/svg_plot.h"
#include "splat/atomic_file.h"
#include "splat/error.h"
#include "splat/image_io.h"
#include "splat/popping.h"

namespace splat {

namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;
using report::escapeHtml;
using report::formatNumber;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// Events shown with frames, heat maps and a refinement plot; the rest are only listed.
constexpr std::size_t kMaxEventFigures = 16;
constexpr const char* kFiles[] = {"report.html", "metrics.csv", "summary.json"};

// ---- small helpers -----------------------------------------------------------------

double at(const std::vector<double>& v, std::size_t i) { return i < v.size() ? v[i] : kNaN; }

/// A temporal FLIP value (splat/popping.h RendererSeries::flipWarp1): -1 (not measured) as NaN.
double warped(double v) { return v >= 0 ? v : kNaN; }
double warpedAt(const std::vector<double>& v, std::size_t i) { return warped(at(v, i)); }

double median(std::vector<double> v) { return analysis::finiteMedian(std::move(v)); }

json number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

// A float setting as the decimal it was most likely given as (0.35f, not 0.349999994).
double f32(float v) {
    if (!std::isfinite(v)) return v;
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.7g", double(v));
    return std::strtod(buf, nullptr);
}

std::string csvNumber(double v) {
    if (!std::isfinite(v)) return "";
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.9g", v);
    return buf;
}

// The unit of the positions in the report being written: degrees for a sweep, none for a
// camera path (positions are view indices). Set by writePoppingReport for its thread.
thread_local const char* positionUnit = "°";

std::string deg(double v) { return formatNumber(v, 6) + positionUnit; }

const char* angleName(Sweep::Angle a) {
    return a == Sweep::Angle::Azimuth ? "azimuth" : "elevation";
}

/// What the positions are: the swept angle, or the camera path's view index.
std::string positionName(const PoppingResult& r) {
    return r.pathViews > 0 ? "path position (view)" : angleName(r.sweep.angle);
}

std::string sheetName(int axis, int sign) {
    if (axis < 0 || axis > 2) return "–";
    std::string s = sign < 0 ? "−" : sign > 0 ? "+" : "";
    return s + "ijk"[axis];
}

// ", sheet axis +i → +j" of an event, or nothing where no sheet axis was recorded.
std::string sheetChange(const PoppingEvent& e) {
    if (e.sheetAxisBefore < 0 && e.sheetAxisAfter < 0) return "";
    return ", sheet axis " + sheetName(e.sheetAxisBefore, e.sheetSignBefore) + " → " +
           sheetName(e.sheetAxisAfter, e.sheetSignAfter);
}

std::string rendererColor(RendererKind k, std::size_t index) {
    switch (k) {
        case RendererKind::Axis:
            return index < 3 ? "#1f77b4" : "#17becf";
        case RendererKind::Sheet:
            return index < 3 ? "#d95f02" : "#e7298a";
        case RendererKind::Reference:
            return "#222222";
    }
    return "#7f7f7f";
}

// The series whose signal fired event `e`.
const RendererSeries* firedBy(const PoppingResult& r, const PoppingEvent& e) {
    return e.series < r.series.size() ? &r.series[e.series] : nullptr;
}

// The report's name of a renderer: PoppingOptions::names, else its kind's name.
std::string seriesName(const RendererSeries& x) {
    return x.name.empty() ? std::string(toString(x.renderer)) : x.name;
}
std::string nameOf(const PoppingResult& r, std::size_t i) {
    return i < r.series.size() ? seriesName(r.series[i]) : std::string(toString(r.renderers[i]));
}

// What a predicted event is called beside its angle: "switch" (a sheet switch), "order swap".
std::string eventWord(const PoppingResult& r) {
    return r.options.predictedName == "sheet switch" ? "switch" : r.options.predictedName;
}

// "sheet switches", "order swaps".
std::string plural(const std::string& name) {
    return name + (!name.empty() && name.back() == 'h' ? "es" : "s");
}

// Renderer i's colour; a second renderer of the same kind (named renderers) gets the kind's
// other colour.
std::string seriesColor(const PoppingResult& r, std::size_t i) {
    std::size_t index = i;
    for (std::size_t j = 0; j < i; ++j)
        if (r.renderers[j] == r.renderers[i]) index = std::max<std::size_t>(index, 3);
    return rendererColor(r.renderers[i], index);
}

bool sameAngle(double a, double b, double step) {
    return std::abs(a - b) <= 1e-6 * std::max(std::abs(step), 1e-9) + 1e-12;
}

// Whether `series` (nullptr: any) has an event on interval n.
bool isEvent(const PoppingResult& r, const RendererSeries* series, std::size_t n) {
    if (n + 1 >= r.angles.size()) return false;
    for (const PoppingEvent& e : r.events)
        if ((!series || firedBy(r, e) == series) &&
            sameAngle(e.angleFrom, r.angles[n], r.sweep.step))
            return true;
    return false;
}

std::string cpuModel() {
    std::ifstream in("/proc/cpuinfo");
    for (std::string line; std::getline(in, line);) {
        if (line.rfind("model name", 0) != 0) continue;
        const std::size_t colon = line.find(':');
        if (colon == std::string::npos) continue;
        std::string m = line.substr(colon + 1);
        m.erase(0, m.find_first_not_of(" \t"));
        return m;
    }
    return "unknown CPU";
}

std::string nowString() {
    const std::time_t t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
    std::tm tm{};
    localtime_r(&t, &tm);
    char buf[64];
    std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M:%S %Z", &tm);
    return buf;
}

// ---- the folder --------------------------------------------------------------------

bool isReportFile(const std::string& name) {
    for (const char* f : kFiles)
        if (name == f) return true;
    return false;
}

// The hidden temporaries AtomicFile makes for our files: ".report.tmp<tag>.html", ...
bool isReportTemporary(const std::string& name) {
    for (const char* f : kFiles) {
        const std::string file(f);
        const std::size_t dot = file.rfind('.');
        std::string prefix(1, '.');
        prefix.append(file, 0, dot).append(".tmp");
        const std::string ext = file.substr(dot);
        if (name.size() > prefix.size() + ext.size() && name.rfind(prefix, 0) == 0 &&
            name.compare(name.size() - ext.size(), ext.size(), ext) == 0)
            return true;
    }
    return false;
}

void prepareFolder(const fs::path& dir) {
    const std::string d = dir.string();
    std::error_code ec;
    const fs::file_status st = fs::status(dir, ec);
    if (fs::exists(st) && !fs::is_directory(st))
        throw Error(d + ": exists and is not a folder; give a folder for the report");
    if (!fs::exists(st)) {
        fs::create_directories(dir, ec);
        if (ec) throw Error(d + ": cannot create the report folder (" + ec.message() + ")");
        return;
    }
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
        const std::string name = it->path().filename().string();
        std::error_code ec2;
        if ((isReportFile(name) && it->is_regular_file(ec2)) || isReportTemporary(name)) continue;
        if (name == ".frames" && it->is_directory(ec2)) continue;  // `splat popping` journal
        throw Error(d + ": the folder holds '" + name +
                    "', which is not part of a popping report; write the report into a new "
                    "or empty folder (or one holding only a previous report)");
    }
    if (ec) throw Error(d + ": cannot read the report folder (" + ec.message() + ")");
}

// ---- settings ------------------------------------------------------------------------

json cameraJson(const CameraParams& c) {
    json j;
    j["width"] = c.width;
    j["height"] = c.height;
    j["azimuth"] = c.azimuthDeg;
    j["elevation"] = c.elevationDeg;
    j["projection"] = toString(c.projection);
    j["pixel_size"] = c.pixelSize;
    j["fov"] = c.fovDeg;
    return j;
}

json settingsJson(const RenderSettings& s) {
    json j;
    j["renderer"] = toString(s.renderer);
    j["mode"] = toString(s.mode);
    j["order"] = toString(s.order);
    j["classification"] = toString(s.classification);
    json tf;
    tf["name"] = s.transfer.name;
    tf["unit_distance"] = s.transfer.unitDistance;
    tf["normalized"] = s.transfer.normalized;
    tf["points"] = json::array();
    for (const TransferPoint& p : s.transfer.points)
        tf["points"].push_back(
            {f32(p.value), f32(p.rgba.r), f32(p.rgba.g), f32(p.rgba.b), f32(p.rgba.a)});
    j["transfer"] = tf;
    j["camera"] = cameraJson(s.camera);
    j["kernel"] = s.kernel;
    j["kernel_sigma"] = s.kernelSigma;
    j["kernel_radius"] = s.kernelRadius;
    j["background"] = {f32(s.background.r), f32(s.background.g), f32(s.background.b),
                       f32(s.background.a)};
    j["iso_level"] = s.isoLevel;
    j["shading"] = {{"enabled", s.shading.enabled},
                    {"ambient", f32(s.shading.ambient)},
                    {"diffuse", f32(s.shading.diffuse)},
                    {"specular", f32(s.shading.specular)},
                    {"shininess", f32(s.shading.shininess)}};
    j["threads"] = s.threads;
    const Quality& q = s.quality;
    j["quality"] = {{"slab", q.slab},
                    {"early_termination", q.earlyTermination},
                    {"footprint_resolution", q.footprintResolution},
                    {"slab_radial_resolution", q.slabRadialResolution},
                    {"slab_depth_resolution", q.slabDepthResolution},
                    {"polynomial_tolerance", q.polynomialTolerance},
                    {"reference_step", q.referenceStep},
                    {"reference_tolerance", q.referenceTolerance},
                    {"tile_size", q.tileSize},
                    {"lod", q.lod.pixels},
                    {"pixel_filter", q.pixelFilter},
                    {"ewa", toString(q.ewa)}};
    return j;
}

json optionsJson(const PoppingOptions& o) {
    json j;
    j["mad_k"] = o.madK;
    j["floor_ratio"] = o.floorRatio;
    j["precision_floor"] = o.precisionFloor;
    j["refine"] = o.refine;
    j["pixels_per_degree"] = o.pixelsPerDegree;
    j["flip"] = o.flip;
    j["warp_flip"] = o.warpFlip;
    j["warp_border"] = o.warp.border;
    j["warp_depth_tolerance"] = o.warp.depthTolerance;
    j["thumbnail"] = o.thumbnail;
    j["truth"] = toString(o.truth);
    return j;
}

// Key paths and values of a JSON object, for the settings table.
void flatten(const json& j, const std::string& prefix,
             std::vector<std::pair<std::string, std::string>>& out) {
    if (j.is_object() && !j.empty()) {
        for (const auto& [k, v] : j.items()) flatten(v, prefix.empty() ? k : prefix + "." + k, out);
        return;
    }
    if (j.is_string()) {
        out.emplace_back(prefix, j.get<std::string>());
    } else if (j.is_number_float()) {
        out.emplace_back(prefix, formatNumber(j.get<double>(), 9));
    } else if (j.is_array()) {
        std::string s = "[";
        for (std::size_t i = 0; i < j.size(); ++i) {
            if (i) s += ", ";
            if (j[i].is_array()) {
                std::vector<std::pair<std::string, std::string>> inner;
                flatten(j[i], "", inner);
                s += inner.empty() ? "[]" : inner[0].second;
            } else if (j[i].is_number_float()) {
                s += formatNumber(j[i].get<double>(), 6);
            } else {
                s += j[i].dump();
            }
        }
        out.emplace_back(prefix, s + "]");
    } else {
        out.emplace_back(prefix, j.dump());
    }
}

// ---- summary.json ----------------------------------------------------------------------

json summaryJson(const PoppingResult& r) {
    json j;
    j["version"] = 1;
    j["settings"] = settingsJson(r.settings);
    if (r.pathViews > 0)
        j["sweep"] = {{"angle", "path"},
                      {"from", 0},
                      {"to", r.pathViews - 1},
                      {"step", 1},
                      {"views", r.angles.size()}};
    else
        j["sweep"] = {{"angle", angleName(r.sweep.angle)},
                      {"from", r.sweep.from},
                      {"to", r.sweep.to},
                      {"step", r.sweep.step},
                      {"views", r.angles.size()}};
    j["options"] = optionsJson(r.options);
    // The reference J, e and flipRef are measured against (null without one).
    if (r.find(RendererKind::Reference))
        j["truth"] = {{"reference", r.truthFilter > 0 ? "filtered" : "point"},
                      {"pixel_filter", r.truthFilter}};
    else
        j["truth"] = nullptr;
    json renderers = json::object();
    for (const RendererSeries& s : r.series) {
        json o;
        o["spike_ratio"] = number(s.spikeRatio);
        o["median_T"] = number(s.medianT);
        o["flicker_ratio"] = number(s.flickerRatio);
        // StopThePop's temporal FLIP_1 and FLIP_7 (null when not measured).
        o["flip_warp_1"] = number(warped(s.flipWarp1Mean));
        o["flip_warp_7"] = number(warped(s.flipWarp7Mean));
        o["threshold"] = number(s.threshold);
        o["median_error"] = number(median(s.e));
        o["ms_per_frame"] = number(s.msPerFrame);
        o["total_ms"] = number(s.totalMs);
        // Views whose pixels the splatter handed to the reference: listed, so
        // that a flat signal there is not read as "no popping".
        o["exact_views"] = json::array();
        for (std::size_t n = 0; n < s.exactPixels.size(); ++n)
            if (s.exactPixels[n] > 0) o["exact_views"].push_back(r.angles[n]);
        if (!s.exactReason.empty()) o["exact_reason"] = s.exactReason;
        o["events"] = json::array();
        for (const PoppingEvent& e : r.events) {
            if (firedBy(r, e) != &s) continue;
            o["events"].push_back({{"angle_from", e.angleFrom},
                                   {"angle_to", e.angleTo},
                                   {"J", number(e.signal)},
                                   {"refined_jump", number(e.refinedJump)},
                                   {"refined_width", number(e.refinedWidth)},
                                   {"refined_slope", number(e.refinedSlope)},
                                   {"refined_angle", number(e.refinedAngle)},
                                   {"sheet_axis_before", e.sheetAxisBefore},
                                   {"sheet_axis_after", e.sheetAxisAfter},
                                   {"sheet_sign_before", e.sheetSignBefore},
                                   {"sheet_sign_after", e.sheetSignAfter},
                                   {"predicted", e.predicted}});
        }
        renderers[seriesName(s)] = o;
    }
    j["renderers"] = renderers;
    j["predicted_switches"] = json::array();
    for (double a : r.predictedSwitches) j["predicted_switches"].push_back(a);
    j["timings"] = {{"total_ms", number(r.totalMs)}};
    return j;
}

// ---- metrics.csv -----------------------------------------------------------------------

std::string metricsCsv(const PoppingResult& r) {
    std::ostringstream s;
    s << "renderer,interval,angle_from,angle_to,T,J,flipT,e,flipRef,signal,is_event,truth,"
         "flipWarp1,flipWarp7\n";
    const std::string truth = !r.find(RendererKind::Reference) ? ""
                              : r.truthFilter > 0 ? "filtered " + csvNumber(r.truthFilter)
                                                  : "point";
    const std::size_t intervals = r.angles.size() > 1 ? r.angles.size() - 1 : 0;
    for (const RendererSeries& x : r.series)
        for (std::size_t n = 0; n < intervals; ++n)
            s << seriesName(x) << ',' << n << ',' << csvNumber(r.angles[n]) << ','
              << csvNumber(r.angles[n + 1]) << ',' << csvNumber(at(x.T, n)) << ','
              << csvNumber(at(x.J, n)) << ',' << csvNumber(at(x.flipT, n)) << ','
              << csvNumber(at(x.e, n)) << ',' << csvNumber(at(x.flipRef, n)) << ','
              << csvNumber(at(x.signal, n)) << ',' << (isEvent(r, &x, n) ? 1 : 0) << ','
              << truth << ',' << csvNumber(warpedAt(x.flipWarp1, n)) << ','
              << csvNumber(warpedAt(x.flipWarp7, n)) << '\n';
    if (!r.crossJump.empty())
        for (std::size_t n = 0; n < intervals; ++n)
            s << "axis-sheet," << n << ',' << csvNumber(r.angles[n]) << ','
              << csvNumber(r.angles[n + 1]) << ",," << csvNumber(at(r.crossJump, n)) << ",,,,"
              << csvNumber(at(r.crossJump, n)) << ',' << (isEvent(r, nullptr, n) ? 1 : 0)
              << ",,,\n";
    return s.str();
}

// ---- images ------------------------------------------------------------------------------

bool windowed(RenderMode m) { return m == RenderMode::Mip || m == RenderMode::Xray; }

// How images of the run are shown: dvr and iso as sRGB of the linear values, mip and xray
// windowed to defaultWindow(images) (the data's range, 0 included).
WriteOptions displayFor(const RenderSettings& s, const std::vector<const Image*>& images) {
    WriteOptions o;
    if (!windowed(s.mode)) return o;
    o.mapping = DisplayMapping::Window;
    std::tie(o.windowLow, o.windowHigh) = defaultWindow(images);
    return o;
}

std::string pngImg(const Image& im, const WriteOptions& o, const std::string& cls,
                   const std::string& alt) {
    return report::imgTag(encodeImage(im, ".png", o), "image/png", cls, alt, alt);
}

// |a - b|, max over RGB, per pixel.
std::vector<float> absDiff(const Image& a, const Image& b) {
    std::vector<float> d(a.pixels.size());
    for (std::size_t n = 0; n < d.size(); ++n) {
        const glm::vec4 v = glm::abs(a.pixels[n] - b.pixels[n]);
        const float m = std::max(v.r, std::max(v.g, v.b));
        d[n] = std::isfinite(m) ? m : std::numeric_limits<float>::max();
    }
    return d;
}

// A heat map of `diff` scaled to [0, scale] with OpenImageIO's "inferno" map (as
// writeHeatmap does: the map's values are treated as linear and sRGB-encoded).
std::string heatmapImg(const std::vector<float>& diff, int w, int h, double scale,
                       const std::string& alt) {
    std::vector<float> v(diff.size());
    for (std::size_t n = 0; n < v.size(); ++n)
        v[n] = float(std::clamp(double(diff[n]) / scale, 0.0, 1.0));
    OIIO::ImageBuf grey(OIIO::ImageSpec(w, h, 1, OIIO::TypeDesc::FLOAT), v.data());
    OIIO::ImageBuf mapped = OIIO::ImageBufAlgo::color_map(grey, 0, "inferno");
    std::vector<float> rgb(std::size_t(w) * h * 3);
    if (mapped.has_error() ||
        !mapped.get_pixels(OIIO::ROI(0, w, 0, h, 0, 1, 0, 3), OIIO::TypeDesc::FLOAT, rgb.data()))
        throw Error("popping report: heat map colour map failed: " + mapped.geterror());
    Image heat(w, h, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
    for (std::size_t n = 0; n < heat.pixels.size(); ++n)
        heat.pixels[n] = glm::vec4(rgb[3 * n], rgb[3 * n + 1], rgb[3 * n + 2], 1.0f);
    return pngImg(heat, {}, "heatmap", alt);
}

bool sameSize(const Image& a, const Image& b) {
    return a.width == b.width && a.height == b.height && a.width > 0 && a.height > 0 &&
           a.pixels.size() == std::size_t(a.width) * a.height && b.pixels.size() == a.pixels.size();
}

// ---- page sections -------------------------------------------------------------------------

std::string th(const std::string& s, bool left = false) {
    return std::string(left ? "<th class=\"l\">" : "<th>") + s + "</th>";
}
std::string td(const std::string& s, bool left = false) {
    return std::string(left ? "<td class=\"l\">" : "<td>") + s + "</td>";
}

std::vector<double> midpoints(const std::vector<double>& angles) {
    std::vector<double> m;
    for (std::size_t i = 0; i + 1 < angles.size(); ++i)
        m.push_back(0.5 * (angles[i] + angles[i + 1]));
    return m;
}

std::string headerSection(const PoppingResult& r, const std::string& commandLine) {
    const RenderSettings& s = r.settings;
    std::ostringstream h;
    h << "<h1>Popping report</h1>\n<table class=\"kv\">\n";
    auto row = [&](const std::string& k, const std::string& v) {
        h << "<tr><td>" << escapeHtml(k) << "</td><td>" << v << "</td></tr>\n";
    };
    const std::string scene = !r.options.scene.empty()
                                  ? r.options.scene
                                  : std::string(toString(s.mode)) + ", transfer function " +
                                        s.transfer.name + ", " + toString(s.classification) +
                                        "-classified, kernel " + s.kernel;
    row("scene",
        escapeHtml(scene + ", " + std::to_string(s.camera.width) + "×" +
                   std::to_string(s.camera.height) + " pixels, " + toString(s.camera.projection)));
    if (r.pathViews > 0)
        row("camera path",
            escapeHtml(std::to_string(r.pathViews) +
                       " views; positions are view indices, refinement renders the camera "
                       "interpolated between two views"));
    else
        row("sweep",
            escapeHtml(std::string(angleName(r.sweep.angle)) + " from " + deg(r.sweep.from) +
                       " to " + deg(r.sweep.to) + " in steps of " + deg(r.sweep.step) + " (" +
                       std::to_string(r.angles.size()) + " views)"));
    std::string names;
    for (std::size_t i = 0; i < r.renderers.size(); ++i) names += (i ? ", " : "") + nameOf(r, i);
    row("renderers", escapeHtml(names));
    if (r.find(RendererKind::Reference))
        row("truth",
            escapeHtml(r.truthFilter > 0
                           ? "the pixel-filtered reference (Gaussian pixel filter, sigma " +
                                 formatNumber(r.truthFilter, 4) +
                                 " pixels): the splatters' frames are filtered (EWA)"
                           : std::string("the point-sampled reference (one ray per pixel "
                                         "centre)")));
    row("events", std::to_string(r.events.size()) + " detected, " +
                      std::to_string(r.predictedSwitches.size()) + " predicted " +
                      plural(r.options.predictedName));
    for (const RendererSeries& x : r.series) {
        std::size_t exact = 0;
        for (std::size_t p : x.exactPixels) exact += p > 0;
        if (exact > 0)
            row("warning", escapeHtml(seriesName(x) + ": " + std::to_string(exact) + " of " +
                                      std::to_string(x.exactPixels.size()) +
                                      " views are the reference's pixels, not the splatter's (" +
                                      x.exactReason + "); its measures there say nothing"));
    }
    row("machine", escapeHtml(cpuModel() + ", " +
                              std::to_string(std::thread::hardware_concurrency()) + " cores"));
    row("date", escapeHtml(nowString()));
    std::string timing = "total " + formatNumber(r.totalMs / 1000.0, 4) + " s";
    for (const RendererSeries& x : r.series)
        timing += "; " + seriesName(x) + " " + formatNumber(x.msPerFrame, 4) + " ms/frame, " +
                  formatNumber(x.totalMs / 1000.0, 4) + " s";
    row("timings", escapeHtml(timing));
    h << "</table>\n<p>Reproduce this report with:</p>\n<pre class=\"command\">"
      << escapeHtml(commandLine) << "</pre>\n";
    return h.str();
}

std::string summarySection(const PoppingResult& r) {
    std::ostringstream h;
    h << "<h2>Summary</h2>\n<table>\n<tr>" << th("renderer", true) << th("spike ratio")
      << th("median T") << th("flicker ratio") << th("events") << th("median error")
      << th("threshold") << th("ꟻLIP₁ warped") << th("ꟻLIP₇ warped") << th("ms / frame")
      << th("total s") << "</tr>\n";
    for (const RendererSeries& x : r.series) {
        const auto n = std::count_if(r.events.begin(), r.events.end(),
                                     [&](const PoppingEvent& e) { return firedBy(r, e) == &x; });
        h << "<tr>" << td(seriesName(x), true) << td(formatNumber(x.spikeRatio, 4))
          << td(formatNumber(x.medianT, 4)) << td(formatNumber(x.flickerRatio, 4))
          << td(n ? "<span class=\"event-yes\">" + std::to_string(n) + "</span>" : "0")
          << td(formatNumber(median(x.e), 4)) << td(formatNumber(x.threshold, 4))
          << td(formatNumber(warped(x.flipWarp1Mean), 4))
          << td(formatNumber(warped(x.flipWarp7Mean), 4)) << td(formatNumber(x.msPerFrame, 4))
          << td(formatNumber(x.totalMs / 1000.0, 4)) << "</tr>\n";
    }
    h << "</table>\n<p class=\"note\">Spike ratio: the largest detection signal over its median. "
         "Flicker ratio: median T over the reference's. Median error: median e (RMS against "
         "the reference) over the views. An event is an interval whose signal exceeds the "
         "threshold. ꟻLIP<sub>k</sub> warped: StopThePop's temporal measure, the mean LDR-ꟻLIP "
         "between frame t + k and frame t warped to view t + k with the exact flow of the "
         "cameras and the reference's depth, occluded pixels and a border masked "
         "(docs/popping.md); ꟻLIP₇ needs at least 8 views.</p>\n";
    return h.str();
}

std::string eventsTable(const PoppingResult& r) {
    if (r.events.empty()) return "<p>No events were detected.</p>\n";
    std::ostringstream h;
    h << "<table>\n<tr>" << th("#") << th("renderer", true) << th("interval", true) << th("signal")
      << th("refined jump") << th("width") << th("slope") << th("angle") << th("sheet axis", true)
      << th("predicted", true) << "</tr>\n";
    for (std::size_t i = 0; i < r.events.size(); ++i) {
        const PoppingEvent& e = r.events[i];
        h << "<tr>" << td(std::to_string(i + 1)) << td(nameOf(r, e.series), true)
          << td(std::string("[").append(deg(e.angleFrom)).append(", ").append(deg(e.angleTo)) + "]",
                true)
          << td(formatNumber(e.signal, 4)) << td(formatNumber(e.refinedJump, 4))
          << td(formatNumber(e.refinedWidth, 3) + "°") << td(formatNumber(e.refinedSlope, 3))
          << td(deg(e.refinedAngle))
          << td(sheetName(e.sheetAxisBefore, e.sheetSignBefore) + " → " +
                    sheetName(e.sheetAxisAfter, e.sheetSignAfter),
                true)
          << td(e.predicted ? "yes" : "no", true) << "</tr>\n";
    }
    h << "</table>\n";
    return h.str();
}

std::string plotsSection(const PoppingResult& r) {
    std::vector<report::PlotBand> bands;
    for (const PoppingEvent& e : r.events)
        bands.push_back({e.angleFrom, e.angleTo,
                         std::string("event: ") + nameOf(r, e.series) + " [" + deg(e.angleFrom) +
                             ", " + deg(e.angleTo) + "]"});
    std::vector<report::PlotMarker> markers;
    for (double a : r.predictedSwitches)
        markers.push_back({a, "predicted " + eventWord(r) + " " + deg(a)});
    const std::vector<double> mid = midpoints(r.angles);
    const std::string xLabel =
        r.pathViews > 0 ? positionName(r) : std::string(angleName(r.sweep.angle)) + " (degrees)";

    auto makePlot = [&](const std::string& title, const std::string& yLabel) {
        report::LinePlot p;
        p.title = title;
        p.xLabel = xLabel;
        p.yLabel = yLabel;
        p.bands = bands;
        p.markers = markers;
        if (!r.angles.empty()) {
            p.xFrom = std::min(r.angles.front(), r.angles.back());
            p.xTo = std::max(r.angles.front(), r.angles.back());
        }
        return p;
    };
    auto add = [&](report::LinePlot& p, const RendererSeries& x, std::size_t i,
                   const std::vector<double>& xs, const std::vector<double>& ys) {
        if (ys.empty()) return;
        p.series.push_back({seriesName(x), seriesColor(r, i), xs, ys, xs.size() < 40, false});
    };
    auto figure = [](const report::LinePlot& p, const std::string& caption) {
        return "<figure>\n" + p.svg() + "<figcaption>" + caption + "</figcaption>\n</figure>\n";
    };

    report::LinePlot pT = makePlot("Temporal change T", "T (RMS)");
    report::LinePlot pJ = makePlot("Error jump J", "J (RMS)");
    report::LinePlot pE = makePlot("Error e against the reference", "e (RMS)");
    report::LinePlot pF = makePlot("ꟻLIP between consecutive frames", "mean ꟻLIP");
    report::LinePlot pR = makePlot("ꟻLIP against the reference", "mean ꟻLIP");
    report::LinePlot pW = makePlot("ꟻLIP₁ of frames warped with the exact flow", "mean ꟻLIP₁");
    for (std::size_t i = 0; i < r.series.size(); ++i) {
        const RendererSeries& x = r.series[i];
        add(pT, x, i, mid, x.T);
        if (x.renderer != RendererKind::Reference) {
            add(pJ, x, i, mid, x.J);
            add(pE, x, i, r.angles, x.e);
            add(pR, x, i, r.angles, x.flipRef);
        }
        add(pF, x, i, mid, x.flipT);
        std::vector<double> w1;
        for (double v : x.flipWarp1) w1.push_back(warped(v));
        add(pW, x, i, mid, w1);
    }
    if (!r.crossJump.empty())
        pJ.series.push_back({"C axis−sheet", "#9467bd", mid, r.crossJump, mid.size() < 40, true});
    // J spans decades when a renderer pops: log scale when the positive values do.
    double lo = std::numeric_limits<double>::infinity(), hi = 0;
    for (const report::PlotSeries& s : pJ.series)
        for (double v : s.y)
            if (std::isfinite(v) && v > 0) {
                lo = std::min(lo, v);
                hi = std::max(hi, v);
            }
    pJ.logY = hi > 0 && hi / lo > 30;

    std::ostringstream h;
    h << "<h2>Measures along the sweep</h2>\n"
         "<p class=\"note\">Per-interval measures are drawn at the interval's middle, per-view "
         "ones at the view. Shaded bands: detected events; dashed lines: predicted "
      << escapeHtml(plural(r.options.predictedName))
      << (r.options.predictedName == "sheet switch" ? " of the axis-aligned splatter" : "")
      << ".</p>\n";
    h << figure(pT,
                "T<sub>X</sub>(n) = RMS(I<sub>X</sub>(θ<sub>n+1</sub>) − "
                "I<sub>X</sub>(θ<sub>n</sub>)): how much each renderer's image changes per "
                "step.");
    h << figure(
        pJ,
        std::string("J<sub>X</sub>(n) = RMS(D<sub>X</sub>(θ<sub>n+1</sub>) − "
                    "D<sub>X</sub>(θ<sub>n</sub>)), D<sub>X</sub> = I<sub>X</sub> − "
                    "I<sub>ref</sub>: the jump of the error") +
            (r.crossJump.empty() ? "" : "; C: the jump of I<sub>axis</sub> − I<sub>sheet</sub>") +
            (pJ.logY ? " (logarithmic scale)." : "."));
    h << figure(pE, "e<sub>X</sub>(θ) = RMS(I<sub>X</sub>(θ) − I<sub>ref</sub>(θ)) per view.");
    h << figure(pF, "Mean LDR-ꟻLIP between consecutive frames (perceived change per step).");
    h << figure(pR, "Mean LDR-ꟻLIP against the reference per view.");
    if (!pW.series.empty())
        h << figure(pW,
                    "StopThePop's ꟻLIP₁: mean LDR-ꟻLIP between frame n + 1 and frame n warped to "
                    "view n + 1 (exact flow, reference depth), over the pixels the warp holds.");
    return h.str();
}

std::string refinementFigure(const PoppingResult& r, const PoppingEvent& e, bool withJump) {
    report::LinePlot p;
    p.title = "Refinement: change against interval width";
    p.xLabel = "interval width (degrees)";
    p.yLabel = "change (RMS)";
    p.logX = p.logY = true;
    p.height = 260;
    for (std::size_t i = 0; i < r.renderers.size(); ++i) {
        report::PlotSeries c{
            std::string("T ") + nameOf(r, i), seriesColor(r, i), {}, {}, true, false};
        report::PlotSeries j{
            std::string("J ") + nameOf(r, i), seriesColor(r, i), {}, {}, true, true};
        for (const RefinementStep& st : e.refinement) {
            c.x.push_back(st.width);
            c.y.push_back(at(st.change, i));
            j.x.push_back(st.width);
            j.y.push_back(at(st.jump, i));
        }
        // Sort by width so that the polyline runs left to right.
        auto sortByX = [](report::PlotSeries& s) {
            std::vector<std::size_t> idx(s.x.size());
            for (std::size_t k = 0; k < idx.size(); ++k) idx[k] = k;
            std::sort(idx.begin(), idx.end(), [&](auto a, auto b) { return s.x[a] < s.x[b]; });
            std::vector<double> x, y;
            for (auto k : idx) {
                x.push_back(s.x[k]);
                y.push_back(s.y[k]);
            }
            s.x = x;
            s.y = y;
        };
        sortByX(c);
        sortByX(j);
        p.series.push_back(c);
        if (withJump && r.renderers[i] != RendererKind::Reference) p.series.push_back(j);
    }
    std::string caption =
        "Change over the refined interval against its width, per renderer "
        "(T solid";
    caption += withJump ? ", J dashed" : "";
    caption += "). " + escapeHtml(nameOf(r, e.series)) + ": fitted log–log slope " +
               formatNumber(e.refinedSlope, 3) + ", jump " + formatNumber(e.refinedJump, 4) +
               " at width " + formatNumber(e.refinedWidth, 3) + "° (near " + deg(e.refinedAngle) +
               "). A slope near 0 is a discontinuity (popping); near 1, "
               "continuous change.";
    return "<figure>\n" + p.svg() + "<figcaption>" + caption + "</figcaption>\n</figure>\n";
}

std::string eventSection(const PoppingResult& r, const PoppingEvent& e, std::size_t index) {
    std::ostringstream h;
    const std::size_t R = r.renderers.size();
    const auto refIt = std::find(r.renderers.begin(), r.renderers.end(), RendererKind::Reference);
    const std::size_t ref =
        refIt == r.renderers.end() ? R : std::size_t(refIt - r.renderers.begin());
    const RendererSeries* fired = nullptr;
    for (const RendererSeries& x : r.series)
        if (firedBy(r, e) == &x) fired = &x;

    std::string predicted = "not predicted";
    for (double a : r.predictedSwitches)
        if (a >= std::min(e.angleFrom, e.angleTo) && a <= std::max(e.angleFrom, e.angleTo))
            predicted = "predicted " + eventWord(r) + " at " + deg(a);
    if (e.predicted && predicted == "not predicted") predicted = "predicted";
    const std::string caption =
        "Event " + std::to_string(index + 1) + ": " + escapeHtml(nameOf(r, e.series)) + " over [" +
        deg(e.angleFrom) + ", " + deg(e.angleTo) + "], signal " + formatNumber(e.signal, 4) +
        (fired ? " (threshold " + formatNumber(fired->threshold, 4) + ")" : "") + sheetChange(e) +
        ", " + predicted + ".";
    h << "<h3>" << caption << "</h3>\n";

    const EventFrames& f = e.frames;
    bool framesOk = f.before.size() == R && f.after.size() == R && R > 0;
    for (std::size_t i = 0; framesOk && i < R; ++i)
        framesOk = sameSize(f.before[i], f.after[i]) && sameSize(f.before[i], f.before[0]);
    if (!framesOk) {
        h << "<p class=\"note\">No frames were kept for this event.</p>\n";
    } else {
        std::vector<const Image*> all;
        for (std::size_t i = 0; i < R; ++i) {
            all.push_back(&f.before[i]);
            all.push_back(&f.after[i]);
        }
        const WriteOptions display = displayFor(r.settings, all);
        const int w = f.before[0].width, hgt = f.before[0].height;
        // Difference images and their shared scales (change rows, error rows).
        std::vector<std::vector<float>> change(R), errBefore(R), errAfter(R);
        double changeMax = 0, errMax = 0;
        for (std::size_t i = 0; i < R; ++i) {
            change[i] = absDiff(f.after[i], f.before[i]);
            for (float v : change[i]) changeMax = std::max(changeMax, double(v));
            if (ref < R && i != ref) {
                errBefore[i] = absDiff(f.before[i], f.before[ref]);
                errAfter[i] = absDiff(f.after[i], f.after[ref]);
                for (float v : errBefore[i]) errMax = std::max(errMax, double(v));
                for (float v : errAfter[i]) errMax = std::max(errMax, double(v));
            }
        }
        const double changeScale = changeMax > 0 ? changeMax : 1,
                     errScale = errMax > 0 ? errMax : 1;
        h << "<figure>\n<div class=\"grid\" style=\"grid-template-columns: 7em repeat(" << R
          << ", 1fr)\">\n<div></div>";
        for (std::size_t i = 0; i < R; ++i)
            h << "<div class=\"cell\"><b>" << escapeHtml(nameOf(r, i)) << "</b></div>";
        h << '\n';
        auto label = [](const std::string& s) { return "<div class=\"cell\">" + s + "</div>"; };
        const std::string name = "event " + std::to_string(index + 1) + " ";
        h << label("before<br>" + deg(e.angleFrom));
        for (std::size_t i = 0; i < R; ++i)
            h << "<div>" << pngImg(f.before[i], display, "frame", name + nameOf(r, i) + " before")
              << "</div>";
        h << '\n' << label("after<br>" + deg(e.angleTo));
        for (std::size_t i = 0; i < R; ++i)
            h << "<div>" << pngImg(f.after[i], display, "frame", name + nameOf(r, i) + " after")
              << "</div>";
        h << '\n' << label("|after − before|");
        for (std::size_t i = 0; i < R; ++i)
            h << "<div>"
              << heatmapImg(change[i], w, hgt, changeScale,
                            name + nameOf(r, i) + " |after − before|")
              << "</div>";
        h << '\n';
        if (ref < R) {
            for (int side = 0; side < 2; ++side) {
                h << label(side ? "|X − ref| after" : "|X − ref| before");
                for (std::size_t i = 0; i < R; ++i) {
                    if (i == ref) {
                        h << "<div class=\"cell\">—</div>";
                        continue;
                    }
                    h << "<div>"
                      << heatmapImg(side ? errAfter[i] : errBefore[i], w, hgt, errScale,
                                    name + nameOf(r, i) +
                                        (side ? " |X − ref| after" : " |X − ref| before"))
                      << "</div>";
                }
                h << '\n';
            }
        }
        h << "</div>\n<figcaption>Frames at both ends of the interval, "
          << (windowed(r.settings.mode) ? "windowed to [" + formatNumber(display.windowLow, 4) +
                                              ", " + formatNumber(display.windowHigh, 4) + "]"
                                        : std::string("sRGB"))
          << "; heat maps (inferno) of the largest RGB difference, |after − before| scaled to [0, "
          << formatNumber(changeScale, 4) << "]"
          << (ref < R ? ", |X − ref| to [0, " + formatNumber(errScale, 4) + "]" : std::string())
          << ".</figcaption>\n</figure>\n";
    }
    if (!e.refinement.empty())
        h << refinementFigure(r, e, ref < R);
    else
        h << "<p class=\"note\">This event was not refined.</p>\n";
    return h.str();
}

std::string animationSection(const PoppingResult& r) {
    std::ostringstream h;
    h << "<h2>The sweep side by side</h2>\n";
    std::size_t frames = std::numeric_limits<std::size_t>::max();
    int w = 0, hgt = 0;
    for (const RendererSeries& x : r.series) {
        frames = std::min(frames, x.thumbnails.size());
        for (const Image& t : x.thumbnails) {
            w = std::max(w, t.width);
            hgt = std::max(hgt, t.height);
        }
    }
    if (r.series.empty() || frames == 0 || w == 0 || hgt == 0) {
        h << "<p class=\"note\">No thumbnails were kept, so there is no animation.</p>\n";
        return h.str();
    }
    const int gap = 4, n = int(r.series.size());
    std::vector<const Image*> all;
    for (const RendererSeries& x : r.series)
        for (std::size_t f = 0; f < frames; ++f) all.push_back(&x.thumbnails[f]);
    const WriteOptions display = displayFor(r.settings, all);
    const glm::vec4 fill = windowed(r.settings.mode) ? glm::vec4(0.0f) : r.settings.background;
    std::vector<Image> movie;
    for (std::size_t f = 0; f < frames; ++f) {
        Image m(n * w + (n - 1) * gap, hgt, fill);
        for (int k = 0; k < n; ++k) {
            const Image& t = r.series[k].thumbnails[f];
            if (t.pixels.size() != std::size_t(t.width) * t.height) continue;
            const int x0 = k * (w + gap) + (w - t.width) / 2, y0 = (hgt - t.height) / 2;
            for (int y = 0; y < t.height; ++y)
                for (int x = 0; x < t.width; ++x) m.at(x0 + x, y0 + y) = t.at(x, y);
        }
        movie.push_back(std::move(m));
    }
    std::string order;
    for (int k = 0; k < n; ++k) order += (k ? " | " : "") + seriesName(r.series[k]);
    const int fps = std::clamp(int(frames) / 3, 4, 12);
    // Small thumbnails are shown enlarged (whole pixels) to about 480 CSS pixels wide.
    const int scale = std::max(1, 480 / movie[0].width);
    const double first = r.angles.empty() ? r.sweep.from : r.angles.front();
    const double last = frames - 1 < r.angles.size() ? r.angles[frames - 1] : r.sweep.to;
    h << "<figure>\n"
      << report::imgTag(encodeAnimatedGif(movie, display, fps), "image/gif", "animation",
                        "the sweep: " + order, "the sweep: " + order, scale * movie[0].width)
      << "\n<figcaption>Left to right: " << escapeHtml(order) << "; " << frames << " views, "
      << positionName(r) << " " << deg(first) << " to " << deg(last) << ", " << fps
      << " frames per second, looping.</figcaption>\n</figure>\n";
    return h.str();
}

std::string settingsSection(const json& summary) {
    std::vector<std::pair<std::string, std::string>> rows;
    flatten(summary["settings"], "", rows);
    std::vector<std::pair<std::string, std::string>> opts;
    flatten(summary["options"], "", opts);
    std::ostringstream h;
    h << "<h2>Settings</h2>\n<table class=\"kv\">\n";
    for (const auto& [k, v] : rows)
        h << "<tr><td>" << escapeHtml(k) << "</td><td>" << escapeHtml(v) << "</td></tr>\n";
    h << "</table>\n<h3>Analysis options</h3>\n<table class=\"kv\">\n";
    for (const auto& [k, v] : opts)
        h << "<tr><td>" << escapeHtml(k) << "</td><td>" << escapeHtml(v) << "</td></tr>\n";
    h << "</table>\n";
    return h.str();
}

std::string reportHtml(const PoppingResult& r, const std::string& commandLine,
                       const json& summary) {
    std::string body = headerSection(r, commandLine);
    body += summarySection(r);
    body += plotsSection(r);
    body += "<h2>Events</h2>\n" + eventsTable(r);
    for (std::size_t i = 0; i < r.events.size() && i < kMaxEventFigures; ++i)
        body += eventSection(r, r.events[i], i);
    if (r.events.size() > kMaxEventFigures)
        body += "<p class=\"note\">Frames are shown for the first " +
                std::to_string(kMaxEventFigures) + " events only.</p>\n";
    body += animationSection(r);
    body += settingsSection(summary);
    body +=
        "<p class=\"note\">Written by splat. The measures per interval are in "
        "metrics.csv, the summary in summary.json.</p>\n";
    return report::htmlPage("Popping report", body);
}

}  // namespace

void writePoppingReport(const PoppingResult& result, const std::string& dir,
                        const std::string& commandLine) {
    if (dir.empty()) throw Error("popping report: no folder given");
    positionUnit = result.pathViews > 0 ? "" : "°";
    const fs::path folder(dir);
    prepareFolder(folder);
    removeStaleTemporaries(folder);  // left by a killed run
    // Everything is built before anything is written.
    const json summary = summaryJson(result);
    const std::string csv = metricsCsv(result);
    std::string html;
    try {
        html = reportHtml(result, commandLine, summary);
    } catch (const Error& e) {
        throw Error((folder / "report.html").string() + ": " + e.what());
    }
    // All three are written in full before any replaces a previous one: a failure leaves
    // the previous report whole, never a mix of two runs.
    const std::string json = summary.dump(2) + "\n";
    AtomicFile files[] = {AtomicFile(folder / "metrics.csv"), AtomicFile(folder / "summary.json"),
                          AtomicFile(folder / "report.html")};
    files[0].write(csv.data(), csv.size());
    files[1].write(json.data(), json.size());
    files[2].write(html.data(), html.size());
    for (AtomicFile& f : files) f.sync();
    for (AtomicFile& f : files) f.commit();
}

}  // namespace splat
