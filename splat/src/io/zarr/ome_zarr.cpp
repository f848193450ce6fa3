// OME-Zarr images as volumes (ome_zarr.h): the `multiscales` metadata of OME-NGFF 0.4
// (https://ngff.openmicroscopy.org/0.4/#multiscale-md), the selection of one 3D block, and
// its chunks read through zarr_array.h.
#include "io/zarr/ome_zarr.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "io/volume_detail.h"
#include "splat/error.h"
#include "splat/sparse_files.h"
#include "io/zarr/zarr_array.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace splat::detail {
namespace {

struct Level {
    std::string path;
    zarr::Array array;
    std::vector<double> scale, translation;  ///< per array axis (global transform applied)
};

/// An image: its axes and levels, checked to agree.
struct Image {
    std::string name;
    std::string axes;  ///< one letter per array axis: t, c, z, y, x (or '?')
    int time = -1, channel = -1;
    int space[3] = {-1, -1, -1};  ///< the array axes of x, y, z (z: -1 for a 2D image)
    std::vector<Level> levels;
    int times() const { return time < 0 ? 1 : int(levels[0].array.shape[std::size_t(time)]); }
    int channels() const {
        return channel < 0 ? 1 : int(levels[0].array.shape[std::size_t(channel)]);
    }
};

json readJson(const fs::path& p) {
    const std::vector<unsigned char> text = readFileBytes(p);
    json j = json::parse(text.begin(), text.end(), nullptr, false);
    if (j.is_discarded() || !j.is_object()) throw Error(displayName(p) + ": not valid JSON");
    return j;
}

bool hasMultiscales(const fs::path& dir) {
    std::error_code ec;
    if (!fs::is_regular_file(dir / ".zattrs", ec)) return false;
    const json j = readJson(dir / ".zattrs");
    return j.contains("multiscales");
}

/// The folder holding the image: `dir`, or its `0` (bioformats2raw's layout).
fs::path imageFolder(const fs::path& dir) {
    std::error_code ec;
    if (hasMultiscales(dir) || fs::is_regular_file(dir / ".zarray", ec)) return dir;
    if (hasMultiscales(dir / "0")) return dir / "0";
    throw Error(displayName(dir) +
                ": not an OME-Zarr image (no 'multiscales' in .zattrs and no .zarray)");
}

std::vector<double> numbers(const json& j, const std::string& what, std::size_t count) {
    if (!j.is_array() || j.size() != count)
        throw Error(what + " does not hold " + std::to_string(count) + " numbers");
    std::vector<double> out;
    for (const json& x : j) {
        if (!x.is_number() || !std::isfinite(x.get<double>()))
            throw Error(what + " holds " + x.dump() + ", not a finite number");
        out.push_back(x.get<double>());
    }
    return out;
}

/// Applies a list of NGFF coordinateTransformations (scale, translation) to scale/translation.
void applyTransforms(const json& list, const std::string& what, std::vector<double>& scale,
                     std::vector<double>& translation) {
    if (list.is_null()) return;
    if (!list.is_array()) throw Error(what + ": coordinateTransformations is not a list");
    for (const json& t : list) {
        const std::string type = t.value("type", std::string());
        if (type == "identity") continue;
        if ((type == "scale" || type == "translation") && t.contains("path"))
            throw Error(what + ": coordinateTransformations stored in a file are not supported");
        if (type == "scale") {
            const auto s = numbers(t.value("scale", json()), what + ": scale", scale.size());
            for (std::size_t d = 0; d < s.size(); ++d) {
                scale[d] *= s[d];
                translation[d] *= s[d];
            }
        } else if (type == "translation") {
            const auto s =
                numbers(t.value("translation", json()), what + ": translation", translation.size());
            for (std::size_t d = 0; d < s.size(); ++d) translation[d] += s[d];
        } else {
            throw Error(what + ": coordinate transformation '" + type +
                        "' is not supported (scale and translation are)");
        }
    }
}

/// Axis letters from NGFF 0.4 objects ({"name", "type"}) or 0.3 strings.
std::string axisLetters(const json& axes, const std::string& what) {
    if (!axes.is_array()) throw Error(what + ": 'axes' is not a list");
    std::string letters;
    for (const json& a : axes) {
        std::string name, type;
        if (a.is_string()) {
            name = a.get<std::string>();
        } else if (a.is_object()) {
            name = a.value("name", std::string());
            type = a.value("type", std::string());
        } else {
            throw Error(what + ": axis " + a.dump() + " is neither a name nor an object");
        }
        name = toLower(name);
        if (type == "time" || name == "t")
            letters += 't';
        else if (type == "channel" || name == "c")
            letters += 'c';
        else if (name == "x" || name == "y" || name == "z")
            letters += name[0];
        else if (type == "space")
            throw Error(what + ": space axis '" + name + "' is not x, y or z");
        else
            letters += 'c';  // a custom axis: selected like a channel
    }
    return letters;
}

void assignAxes(Image& im, const std::string& what) {
    for (std::size_t d = 0; d < im.axes.size(); ++d) {
        const char a = im.axes[d];
        int* slot = a == 't'   ? &im.time
                    : a == 'c' ? &im.channel
                    : a == 'x' ? &im.space[0]
                    : a == 'y' ? &im.space[1]
                               : &im.space[2];
        if (*slot >= 0)
            throw Error(what + ": axes '" + im.axes + "' name an axis twice (splat reads one " +
                        "time and one channel axis)");
        *slot = int(d);
    }
    if (im.space[0] < 0 || im.space[1] < 0)
        throw Error(what + ": axes '" + im.axes + "' have no x and y");
}

Image bareArray(const fs::path& dir, const std::string& name) {
    Image im;
    im.name = name;
    Level L;
    L.path = ".";
    L.array = zarr::readArray(dir, name);
    const std::size_t n = L.array.dims();
    if (n != 2 && n != 3)
        throw Error(name + ": a Zarr array of " + std::to_string(n) +
                    " dimensions without OME-NGFF multiscales metadata (splat reads 2D and 3D "
                    "arrays, or OME-Zarr images)");
    im.axes = n == 3 ? "zyx" : "yx";
    assignAxes(im, name);
    L.scale.assign(n, 1.0);
    L.translation.assign(n, 0.0);
    im.levels.push_back(std::move(L));
    return im;
}

/// Levels that disagree with level 0 (axes, the non-space sizes, the physical extent).
void checkLevels(const Image& im) {
    const Level& base = im.levels[0];
    for (std::size_t l = 1; l < im.levels.size(); ++l) {
        const Level& L = im.levels[l];
        const std::string what = im.name + ": level " + std::to_string(l) + " ('" + L.path + "')";
        if (L.array.dims() != base.array.dims())
            throw Error(what + " has " + std::to_string(L.array.dims()) + " axes, level 0 has " +
                        std::to_string(base.array.dims()));
        for (std::size_t d = 0; d < im.axes.size(); ++d) {
            if (im.axes[d] == 't' || im.axes[d] == 'c') {
                if (L.array.shape[d] != base.array.shape[d])
                    throw Error(what + " has " + std::to_string(L.array.shape[d]) + " along '" +
                                im.axes[d] + "', level 0 has " +
                                std::to_string(base.array.shape[d]));
                continue;
            }
            const double extent = double(L.array.shape[d]) * L.scale[d];
            const double extent0 = double(base.array.shape[d]) * base.scale[d];
            if (std::abs(extent - extent0) > L.scale[d] * 1.0001 + 1e-9 * std::abs(extent0))
                throw Error(what + " spans " + std::to_string(extent) + " along '" + im.axes[d] +
                            "', level 0 spans " + std::to_string(extent0) +
                            " (the levels disagree)");
        }
    }
}

Image readImage(const fs::path& given) {
    const std::string name = displayName(given);
    const fs::path dir = imageFolder(given);
    if (!hasMultiscales(dir)) return bareArray(dir, name);
    const json attrs = readJson(dir / ".zattrs");
    const json& ms = attrs["multiscales"];
    if (!ms.is_array() || ms.empty() || !ms[0].is_object())
        throw Error(name + ": 'multiscales' is not a list of images");
    const json& m = ms[0];
    Image im;
    im.name = name;
    const json datasets = m.value("datasets", json());
    if (!datasets.is_array() || datasets.empty())
        throw Error(name + ": multiscales holds no datasets");
    for (const json& ds : datasets) {
        if (!ds.is_object() || !ds.contains("path") || !ds["path"].is_string())
            throw Error(name + ": a dataset has no path");
        Level L;
        L.path = ds["path"].get<std::string>();
        const fs::path rel = fs::path(L.path).lexically_normal();
        if (rel.empty() || rel.is_absolute() || *rel.begin() == "..")
            throw Error(name + ": dataset path '" + L.path + "' leaves the image's folder");
        L.array = zarr::readArray(dir / rel, name + "/" + L.path);
        im.levels.push_back(std::move(L));
    }
    const std::size_t n = im.levels[0].array.dims();
    if (m.contains("axes"))
        im.axes = axisLetters(m["axes"], name);
    else if (n <= 5)
        im.axes = std::string("tczyx").substr(5 - n);  // NGFF 0.1/0.2: always 5D, tczyx
    else
        throw Error(name + ": " + std::to_string(n) + " axes and no 'axes' to name them");
    if (im.axes.size() != n)
        throw Error(name + ": 'axes' names " + std::to_string(im.axes.size()) +
                    " axes, the arrays have " + std::to_string(n));
    assignAxes(im, name);
    for (Level& L : im.levels) {
        if (L.array.dims() != n)
            throw Error(name + ": level '" + L.path + "' has " + std::to_string(L.array.dims()) +
                        " axes, level 0 has " + std::to_string(n));
        L.scale.assign(n, 1.0);
        L.translation.assign(n, 0.0);
        for (const json& ds : datasets)
            if (ds["path"] == L.path)
                applyTransforms(ds.value("coordinateTransformations", json()),
                                name + ": level '" + L.path + "'", L.scale, L.translation);
        applyTransforms(m.value("coordinateTransformations", json()), name, L.scale, L.translation);
        for (std::size_t d = 0; d < n; ++d)
            if (!(L.scale[d] > 0))
                throw Error(name + ": level '" + L.path + "' has scale " +
                            std::to_string(L.scale[d]) + " along '" + im.axes[d] +
                            "' (must be > 0)");
    }
    checkLevels(im);
    return im;
}

/// The chosen level, time point and channel, with the notes a default choice needs.
struct Selection {
    int level = 0, time = 0, channel = 0;
    std::vector<std::string> notes;
};

int pick(const std::optional<int>& given, int count, const std::string& what,
         const std::string& knob, std::vector<std::string>* notes) {
    if (given) {
        if (*given < 0 || *given >= count)
            throw Error(what + ": " + knob + " " + std::to_string(*given) + " is out of range (" +
                        std::to_string(count) + (count == 1 ? " " + knob : " " + knob + "s") +
                        ": 0.." + std::to_string(count - 1) + ")");
        return *given;
    }
    if (count > 1 && notes)
        notes->push_back("OME-Zarr image of " + std::to_string(count) + " " + knob + "s: loaded " +
                         knob + " 0");
    return 0;
}

Selection select(const Image& im, const LoadOptions& o) {
    Selection s;
    s.level = pick(o.level, int(im.levels.size()), im.name, "level", nullptr);
    s.time = pick(o.time, im.times(), im.name, "time point", &s.notes);
    s.channel = pick(o.channel, im.channels(), im.name, "channel", &s.notes);
    return s;
}

glm::ivec3 dimsOf(const Image& im, const Level& L) {
    glm::ivec3 d(1);
    for (int a = 0; a < 3; ++a)
        if (im.space[a] >= 0) {
            const std::int64_t n = L.array.shape[std::size_t(im.space[a])];
            if (n < 1 || n > 2147483647)
                throw Error(im.name + ": level '" + L.path + "' has " + std::to_string(n) +
                            " samples along " + "xyz"[a]);
            d[a] = int(n);
        }
    return d;
}

Volume geometryOf(const Image& im, const Selection& s) {
    const Level& L = im.levels[std::size_t(s.level)];
    Volume g;
    g.dims = dimsOf(im, L);
    checkedVoxelCount(g.dims, im.name);
    for (int a = 0; a < 3; ++a)
        if (im.space[a] >= 0) {
            g.spacing[a] = L.scale[std::size_t(im.space[a])];
            g.origin[a] = L.translation[std::size_t(im.space[a])];
        }
    g.source = "OME-Zarr " + L.array.dtype + " level " + std::to_string(s.level) + " of " +
               std::to_string(im.levels.size()) + " (" + im.name + ")";
    for (const std::string& n : s.notes) addNote(g, n);
    return g;
}

/// The array box of the volume box [lo, hi) and the strides that lay it out x fastest.
void arrayBox(const Image& im, const Selection& s, const glm::ivec3& lo, const glm::ivec3& hi,
              std::vector<std::int64_t>& alo, std::vector<std::int64_t>& ahi,
              std::vector<std::int64_t>& stride) {
    const std::size_t n = im.axes.size();
    alo.assign(n, 0);
    ahi.assign(n, 1);
    stride.assign(n, 0);
    if (im.time >= 0) {
        alo[std::size_t(im.time)] = s.time;
        ahi[std::size_t(im.time)] = s.time + 1;
    }
    if (im.channel >= 0) {
        alo[std::size_t(im.channel)] = s.channel;
        ahi[std::size_t(im.channel)] = s.channel + 1;
    }
    const glm::ivec3 d = hi - lo;
    const std::int64_t strides[3] = {1, d.x, std::int64_t(d.x) * d.y};
    for (int a = 0; a < 3; ++a)
        if (im.space[a] >= 0) {
            alo[std::size_t(im.space[a])] = lo[a];
            ahi[std::size_t(im.space[a])] = hi[a];
            stride[std::size_t(im.space[a])] = strides[a];
        }
}

Volume readVolumeBox(const Image& im, const Selection& s, const Volume& g, const glm::ivec3& lo,
                     const glm::ivec3& hi) {
    Volume v = makeVolume(hi - lo, g.spacing, im.name);
    v.origin = g.world(glm::dvec3(lo));
    v.source = g.source;
    v.note = g.note;
    v.background = g.background;
    v.backgroundSource = g.backgroundSource;
    std::vector<std::int64_t> alo, ahi, stride;
    arrayBox(im, s, lo, hi, alo, ahi, stride);
    zarr::readBox(im.levels[std::size_t(s.level)].array, alo, ahi, stride, v.data.data());
    return v;
}

/// b = fill_value when a chunk of the selected block is not stored (what is not stored is
/// the background); false otherwise.
bool fillBackground(const Image& im, const Selection& s, Volume& g) {
    const zarr::Array& a = im.levels[std::size_t(s.level)].array;
    std::vector<std::int64_t> alo, ahi, stride;
    arrayBox(im, s, glm::ivec3(0), g.dims, alo, ahi, stride);
    if (zarr::allChunksStored(a, alo, ahi)) return false;
    g.background = float(a.fill);
    g.backgroundSource = "Zarr fill_value (chunks not stored)";
    return true;
}

/// loadVolume's rule over the outer faces of the volume, read alone: the same samples as
/// backgroundFromFaces visits (each once), so the same median.
float facesBackground(const Image& im, const Selection& s, const Volume& g,
                      NonFinitePolicy policy) {
    const glm::ivec3 d = g.dims;
    std::vector<float> face;
    auto take = [&](glm::ivec3 lo, glm::ivec3 hi) {
        if (lo.x >= hi.x || lo.y >= hi.y || lo.z >= hi.z) return;
        const Volume b = readVolumeBox(im, s, g, lo, hi);
        for (float x : b.data)
            if (std::isfinite(x))
                face.push_back(x);
            else if (policy == NonFinitePolicy::Zero)
                face.push_back(0.0f);
    };
    take({0, 0, 0}, {d.x, d.y, 1});
    if (d.z > 1) take({0, 0, d.z - 1}, {d.x, d.y, d.z});
    take({0, 0, 1}, {d.x, 1, d.z - 1});
    if (d.y > 1) take({0, d.y - 1, 1}, {d.x, d.y, d.z - 1});
    take({0, 1, 1}, {1, d.y - 1, d.z - 1});
    if (d.x > 1) take({d.x - 1, 1, 1}, {d.x, d.y - 1, d.z - 1});
    if (face.empty()) return 0.0f;
    auto mid = face.begin() + std::ptrdiff_t(face.size() / 2);
    std::nth_element(face.begin(), mid, face.end());
    return *mid;
}

}  // namespace

bool isZarrFolder(const fs::path& dir) {
    std::error_code ec;
    fs::path named = dir;
    if (!named.has_filename()) named = named.parent_path();  // "image.zarr/"
    if (toLower(named.filename().string()).ends_with(".zarr")) return true;
    return fs::is_regular_file(dir / ".zarray", ec) || fs::is_regular_file(dir / ".zattrs", ec) ||
           fs::is_regular_file(dir / ".zgroup", ec);
}

Volume loadZarr(const fs::path& dir, const LoadOptions& options) {
    const Image im = readImage(dir);
    const Selection s = select(im, options);
    Volume g = geometryOf(im, s);
    fillBackground(im, s, g);
    return readVolumeBox(im, s, g, glm::ivec3(0), g.dims);
}

Volume zarrGeometry(const fs::path& dir, const LoadOptions& options, bool background) {
    const Image im = readImage(dir);
    const Selection s = select(im, options);
    Volume g = geometryOf(im, s);
    if (background && !fillBackground(im, s, g)) {
        g.background = facesBackground(im, s, g, options.nonFinite);
        g.backgroundSource = "median of the outer faces";
    }
    return g;
}

Volume loadZarrBrick(const fs::path& dir, const LoadOptions& options, const glm::ivec3& lo,
                     const glm::ivec3& hi) {
    const Image im = readImage(dir);
    const Selection s = select(im, options);
    const Volume g = geometryOf(im, s);
    if (glm::any(glm::lessThan(lo, glm::ivec3(0))) || glm::any(glm::greaterThan(hi, g.dims)) ||
        glm::any(glm::lessThanEqual(hi, lo)))
        throw Error(im.name + ": brick outside the volume");
    return readVolumeBox(im, s, g, lo, hi);
}

}  // namespace splat::detail

namespace splat {

bool isZarrFolder(const std::string& path) {
    std::error_code ec;
    return !path.empty() && fs::is_directory(path, ec) && detail::isZarrFolder(path);
}

ZarrImageInfo describeZarr(const std::string& folder) {
    const detail::Image im = detail::readImage(folder);
    ZarrImageInfo info;
    info.axes = im.axes;
    info.times = im.times();
    info.channels = im.channels();
    for (std::size_t l = 0; l < im.levels.size(); ++l) {
        const detail::Level& L = im.levels[l];
        ZarrLevelInfo z;
        z.path = L.path;
        z.dims = detail::dimsOf(im, L);
        for (int a = 0; a < 3; ++a)
            if (im.space[a] >= 0) {
                z.spacing[a] = L.scale[std::size_t(im.space[a])];
                z.origin[a] = L.translation[std::size_t(im.space[a])];
            }
        z.chunks = L.array.chunks;
        z.dtype = L.array.dtype;
        z.compressor = L.array.compressor;
        info.levels.push_back(std::move(z));
    }
    return info;
}

}  // namespace splat
