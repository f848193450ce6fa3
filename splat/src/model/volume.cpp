// The Volume type: validated allocation, statistics and the `splat info` description.
#include "splat/volume.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "splat/error.h"

namespace splat {

std::uint64_t checkedVoxelCount(const glm::ivec3& dims, const std::string& what) {
    const char* axis = "xyz";
    for (int a = 0; a < 3; ++a)
        if (dims[a] < 1)
            throw Error(what + ": invalid dimensions " + std::to_string(dims.x) + " x " +
                        std::to_string(dims.y) + " x " + std::to_string(dims.z) + " (" + axis[a] +
                        " must be at least 1)");
    // Overflow-safe product: each factor is < 2^31, check before every multiplication.
    std::uint64_t count = 1;
    for (int a = 0; a < 3; ++a) {
        if (count > kMaxVoxels / std::uint64_t(dims[a]))
            throw Error(what + ": dimensions " + std::to_string(dims.x) + " x " +
                        std::to_string(dims.y) + " x " + std::to_string(dims.z) +
                        " are too large (more than 2^32 voxels)");
        count *= std::uint64_t(dims[a]);
    }
    return count;
}

std::size_t sampleTypeBytes(SampleType type) {
    switch (type) {
        case SampleType::Float32:
            return 4;
        case SampleType::UInt8:
            return 1;
        case SampleType::Int16:
        case SampleType::UInt16:
            return 2;
    }
    return 4;
}

const char* sampleTypeName(SampleType type) {
    switch (type) {
        case SampleType::Float32:
            return "float32";
        case SampleType::UInt8:
            return "uint8";
        case SampleType::Int16:
            return "int16";
        case SampleType::UInt16:
            return "uint16";
    }
    return "?";
}

namespace {
void checkSpacing(const glm::dvec3& spacing, const std::string& what) {
    const char* axis = "xyz";
    for (int a = 0; a < 3; ++a)
        if (!std::isfinite(spacing[a]) || spacing[a] <= 0) {
            std::ostringstream s;
            s << what << ": invalid spacing " << spacing.x << ", " << spacing.y << ", " << spacing.z
              << " (" << axis[a] << " must be finite and > 0)";
            throw Error(s.str());
        }
}
}  // namespace

Volume Volume::borrow(const void* samples, SampleType type, const glm::ivec3& dims,
                      const glm::dvec3& spacing, const glm::dvec3& origin,
                      std::shared_ptr<const void> keepAlive, double scale, double offset) {
    Volume v = typed(std::move(keepAlive), samples, type, dims, spacing, origin, scale, offset);
    v.borrowed_ = true;
    v.source = std::string("borrowed ") + sampleTypeName(type) + " samples";
    return v;
}

Volume Volume::typed(std::shared_ptr<const void> storage, const void* samples, SampleType type,
                     const glm::ivec3& dims, const glm::dvec3& spacing, const glm::dvec3& origin,
                     double scale, double offset) {
    const std::string what = "volume";
    if (!samples) throw Error(what + ": no sample data (null pointer)");
    if (type != SampleType::Float32 && type != SampleType::UInt8 && type != SampleType::Int16 &&
        type != SampleType::UInt16)
        throw Error(what + ": unknown sample type " + std::to_string(int(type)));
    checkedVoxelCount(dims, what);
    checkSpacing(spacing, what);
    if (!std::isfinite(origin.x) || !std::isfinite(origin.y) || !std::isfinite(origin.z))
        throw Error(what + ": origin is NaN or Inf");
    if (!std::isfinite(scale) || !std::isfinite(offset))
        throw Error(what + ": sample scale and offset must be finite");
    Volume v;
    v.dims = dims;
    v.spacing = spacing;
    v.origin = origin;
    v.external_ = samples;
    v.keepAlive_ = std::move(storage);
    v.type_ = type;
    v.scale_ = scale;
    v.offset_ = offset;
    v.identity_ = scale == 1.0 && offset == 0.0;
    v.source = std::string(sampleTypeName(type)) + " samples";
    return v;
}

void Volume::values(std::size_t first, std::size_t count, float* out) const {
    if (!external_) {
        std::copy(data.begin() + std::ptrdiff_t(first),
                  data.begin() + std::ptrdiff_t(first + count), out);
        return;
    }
    for (std::size_t n = 0; n < count; ++n) out[n] = value(first + n);
}

Volume makeVolume(const glm::ivec3& dims, const glm::dvec3& spacing, const std::string& what) {
    const std::uint64_t count = checkedVoxelCount(dims, what);
    checkSpacing(spacing, what);
    Volume v;
    v.dims = dims;
    v.spacing = spacing;
    try {
        v.data.assign(std::size_t(count), 0.0f);
    } catch (const std::bad_alloc&) {
        throw Error(what + ": not enough memory for " + std::to_string(count) + " voxels");
    }
    v.source = what;
    return v;
}

float backgroundFromFaces(const Volume& v) {
    if (!v.hasSamples()) return 0.0f;
    std::vector<float> face;
    const glm::ivec3 d = v.dims;
    auto take = [&](int i, int j, int k) {
        const float x = v.at(i, j, k);
        if (std::isfinite(x)) face.push_back(x);
    };
    for (int k = 0; k < d.z; ++k)
        for (int j = 0; j < d.y; ++j)
            for (int i = 0; i < d.x; ++i) {
                const bool outer =
                    i == 0 || j == 0 || k == 0 || i == d.x - 1 || j == d.y - 1 || k == d.z - 1;
                if (outer) take(i, j, k);
                // Inner rows of an inner slice: jump to the row's last sample.
                else if (i == 1)
                    i = d.x - 2;
            }
    if (face.empty()) return 0.0f;
    auto mid = face.begin() + std::ptrdiff_t(face.size() / 2);
    std::nth_element(face.begin(), mid, face.end());
    return *mid;
}

bool looksLikeHounsfield(const Volume& v) {
    return v.background >= -3100.0f && v.background <= -900.0f;
}

VolumeStats volumeStats(const Volume& v, int bins) {
    VolumeStats s;
    bins = std::max(bins, 1);
    s.histogram.assign(std::size_t(bins), 0);
    if (!v.hasSamples()) return s;
    float lo = std::numeric_limits<float>::infinity(), hi = -lo;
    double sum = 0;
    std::size_t finite = 0;
    const std::size_t count = v.voxelCount();
    for (std::size_t n = 0; n < count; ++n) {
        const float d = v.value(n);
        if (!std::isfinite(d)) continue;
        lo = std::min(lo, d);
        hi = std::max(hi, d);
        sum += d;
        ++finite;
    }
    if (finite == 0) return s;
    s.minValue = lo;
    s.maxValue = hi;
    s.mean = sum / double(finite);
    double range = double(hi) - double(lo);
    for (std::size_t n = 0; n < count; ++n) {
        const float d = v.value(n);
        if (!std::isfinite(d)) continue;
        int b = range > 0 ? int((double(d) - lo) / range * bins) : 0;
        s.histogram[std::size_t(std::clamp(b, 0, bins - 1))]++;
    }
    return s;
}

std::string describeVolume(const Volume& v) {
    std::ostringstream out;
    char buf[256];
    auto line = [&](const char* fmt, auto... args) {
        std::snprintf(buf, sizeof buf, fmt, args...);
        out << buf << '\n';
    };
    out << "source:      " << v.source << '\n';
    line("dimensions:  %d x %d x %d (%zu voxels)", v.dims.x, v.dims.y, v.dims.z, v.voxelCount());
    line("spacing:     %g x %g x %g mm", v.spacing.x, v.spacing.y, v.spacing.z);
    glm::dvec3 extent = glm::dvec3(v.dims) * v.spacing;
    // World frame: RAS millimetres (docs/design.md "World frame").
    const glm::dvec3 first = v.worldPosition(glm::dvec3(0.0));
    const glm::dvec3 last = v.worldPosition(glm::dvec3(v.dims) - 1.0);
    line("extent:      %g x %g x %g mm", extent.x, extent.y, extent.z);
    line("origin:      (%.9g, %.9g, %.9g), last sample at (%.9g, %.9g, %.9g) (world: RAS mm)",
         first.x, first.y, first.z, last.x, last.y, last.z);
    // The world step of one index along each axis: +x is R, +y is A, +z is S.
    glm::dvec3 axes[3];
    for (int a = 0; a < 3; ++a) axes[a] = v.direction[a] * v.spacing[a];
    line("axes:        i (%.9g, %.9g, %.9g), j (%.9g, %.9g, %.9g), k (%.9g, %.9g, %.9g)%s",
         axes[0].x, axes[0].y, axes[0].z, axes[1].x, axes[1].y, axes[1].z, axes[2].x, axes[2].y,
         axes[2].z, v.rotated() ? " (oblique)" : "");
    VolumeStats s = volumeStats(v, 16);
    line("values:      %g .. %g, mean %g", double(s.minValue), double(s.maxValue), s.mean);
    // Where the (first) maximum is: one voxel anyone can find in another viewer.
    for (std::size_t n = 0; n < v.voxelCount(); ++n)
        if (v.value(n) == s.maxValue) {
            const glm::ivec3 p(int(n % std::size_t(v.dims.x)),
                               int(n / std::size_t(v.dims.x) % std::size_t(v.dims.y)),
                               int(n / (std::size_t(v.dims.x) * std::size_t(v.dims.y))));
            const glm::dvec3 w = v.worldPosition(glm::dvec3(p));
            line("maximum:     at index (%d, %d, %d), world (%.9g, %.9g, %.9g)", p.x, p.y, p.z, w.x,
                 w.y, w.z);
            break;
        }
    std::size_t peak = 1;
    for (std::size_t c : s.histogram) peak = std::max(peak, c);
    out << "histogram:\n";
    const int width = 40;
    double binWidth = (double(s.maxValue) - s.minValue) / double(s.histogram.size());
    for (std::size_t b = 0; b < s.histogram.size(); ++b) {
        std::size_t c = s.histogram[b];
        // Bars on a linear scale; any non-empty bin shows at least one mark.
        int n = int(std::lround(double(c) / double(peak) * width));
        if (c > 0 && n == 0) n = 1;
        std::snprintf(buf, sizeof buf, "  [%10.4g, %10.4g%c %-*s %zu", s.minValue + b * binWidth,
                      s.minValue + (b + 1) * binWidth, b + 1 == s.histogram.size() ? ']' : ')',
                      width, std::string(std::size_t(n), '#').c_str(), c);
        out << buf << '\n';
    }
    line("memory:      %.1f MiB (%s samples%s)", double(v.bytes()) / (1024.0 * 1024.0),
         sampleTypeName(v.sampleType()), v.borrowed() ? ", borrowed" : "");
    if (v.sampleScale() != 1.0 || v.sampleOffset() != 0.0)
        line("scaling:     value = raw * %g + %g", v.sampleScale(), v.sampleOffset());
    line("background:  %g (%s)", double(v.background), v.backgroundSource.c_str());
    if (!v.note.empty()) out << "note:        " << v.note << '\n';
    return out.str();
}

}  // namespace splat
