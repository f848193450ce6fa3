// How to read VOLUME, from option values (see splat/options.h).
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <sstream>

#include "splat/options.h"

namespace splat {

namespace {

// "256x256x128" (also "256,256,128") -> dims; every entry a positive integer.
glm::ivec3 parseDims(const std::string& s) {
    std::string t = s;
    for (char& c : t)
        if (c == 'x' || c == 'X' || c == ',') c = ' ';
    std::istringstream in(t);
    long long v[3];
    std::string rest;
    if (!(in >> v[0] >> v[1] >> v[2]) || (in >> rest))
        throw OptionError("--dims '" + s + "': expected XxYxZ, e.g. 256x256x128");
    for (long long d : v)
        if (d < 1 || d > 2147483647LL)
            throw OptionError("--dims '" + s + "': every dimension must be between 1 and 2^31-1");
    return {int(v[0]), int(v[1]), int(v[2])};
}

glm::dvec3 parseSpacing(const std::string& s) {
    std::string t = s;
    for (char& c : t)
        if (c == ',' || c == 'x') c = ' ';
    std::istringstream in(t);
    double v[3];
    std::string rest;
    if (!(in >> v[0])) throw OptionError("--spacing '" + s + "': expected X,Y,Z, e.g. 1,1,2.5");
    if (!(in >> v[1])) {
        v[1] = v[2] = v[0];  // one number: isotropic
    } else if (!(in >> v[2]) || (in >> rest)) {
        throw OptionError("--spacing '" + s + "': expected X,Y,Z, e.g. 1,1,2.5");
    }
    for (double d : v)
        if (!std::isfinite(d) || d <= 0)
            throw OptionError("--spacing '" + s + "': spacings must be finite and > 0");
    return {v[0], v[1], v[2]};
}

// A level or channel number: an integer 0 .. 2^31-1.
int parseIndex(const std::string& s, const std::string& flag) {
    char* end = nullptr;
    const long long v = std::strtoll(s.c_str(), &end, 10);
    if (s.empty() || *end || v < 0 || v > 2147483647LL)
        throw OptionError(flag + " '" + s + "': expected an integer >= 0");
    return int(v);
}

// --background-value: a number, "auto" or "" (the loader's).
std::optional<float> backgroundValueOf(const std::string& text) {
    if (text.empty() || text == "auto") return std::nullopt;
    const std::vector<double> b = parseNumbers(text, "--background-value");
    if (b.size() != 1 || !(std::abs(b[0]) <= 3.0e38))
        throw OptionError("--background-value '" + text +
                          "': expected one finite number or 'auto'");
    return float(b[0]);
}

}  // namespace

int parseTimeStep(const std::string& text, const std::string& what) {
    char* end = nullptr;
    errno = 0;
    const long long t = std::strtoll(text.c_str(), &end, 10);
    if (text.empty() || *end || errno || t < 0 || t > 2147483647LL)
        throw OptionError(what + " '" + text + "': expected a time step, an integer from 0");
    return int(t);
}

LoadOptions loadOptionsFrom(const OptionValues& v) {
    LoadOptions options;
    if (!v.text("dims").empty()) options.raw.dims = parseDims(v.text("dims"));
    options.raw.type = v.text("type");
    if (!v.text("spacing").empty()) options.raw.spacing = parseSpacing(v.text("spacing"));
    options.raw.bigEndian = v.flag("big-endian");
    options.raw.headerBytes = std::size_t(v.integer("header-bytes"));
    options.allowOutsideDataFiles = v.flag("allow-outside-data");
    options.dicomSeries = v.text("series");
    options.grid = v.text("grid");
    if (!v.text("zarr-level").empty()) options.level = parseIndex(v.text("zarr-level"), "--zarr-level");
    if (!v.text("channel").empty()) options.channel = parseIndex(v.text("channel"), "--channel");
    if (!v.text("time").empty()) options.time = parseTimeStep(v.text("time"), "--time");
    const std::string& nan = v.text("nan-policy");
    if (nan == "error")
        options.nonFinite = NonFinitePolicy::Error;
    else if (nan == "zero")
        options.nonFinite = NonFinitePolicy::Zero;
    else
        throw OptionError("--nan-policy '" + nan + "': expected 'error' or 'zero'");
    return options;
}

Volume loadVolumeFrom(const std::string& spec, const OptionValues& v) {
    const LoadOptions options = loadOptionsFrom(v);
    const std::string& backgroundText = v.text("background-value");
    const std::optional<float> background = backgroundValueOf(backgroundText);
    Volume volume = loadVolume(spec, options);
    if (background) {
        volume.background = *background;
        volume.backgroundSource = "--background-value";
    } else if (backgroundText == "auto") {
        volume.background = backgroundFromFaces(volume);
        volume.backgroundSource = "median of the outer faces (--background-value auto)";
    }
    return volume;
}

}  // namespace splat
