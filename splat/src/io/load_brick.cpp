// Reading one brick of a volume (splat/bricks.h): synthetic volumes compute only the brick,
// uncompressed .raw files are read by byte ranges, anything else is loaded whole and cropped.
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "splat/atomic_file.h"
#include "splat/bricks.h"
#include "splat/error.h"
#include "splat/synthetic.h"
#include "splat/volume_io.h"
#include "volume_detail.h"

namespace fs = std::filesystem;

namespace splat {

namespace {

bool isSynthetic(const std::string& spec) { return spec.rfind("synthetic:", 0) == 0; }

bool isPlainRaw(const std::string& spec) {
    return !isSynthetic(spec) && lowerExtension(fs::path(spec)) == ".raw";
}

Volume crop(const Volume& whole, const glm::ivec3& lo, const glm::ivec3& hi) {
    Volume v = makeVolume(hi - lo, whole.spacing, whole.source);
    v.origin = whole.world(glm::dvec3(lo));
    v.direction = whole.direction;
    v.background = whole.background;
    v.backgroundSource = whole.backgroundSource;
    v.source = whole.source;
    v.note = whole.note;
    for (int k = 0; k < v.dims.z; ++k)
        for (int j = 0; j < v.dims.y; ++j)
            whole.values(whole.index(lo.x, lo.y + j, lo.z + k), std::size_t(v.dims.x),
                         &v.at(0, j, k));
    return v;
}

/// The rows of the brick [lo, hi) of a .raw file, read with one pread each.
Volume readRawBrick(const fs::path& p, const RawOptions& options, const glm::ivec3& lo,
                    const glm::ivec3& hi) {
    using namespace detail;
    const std::string name = displayName(p);
    const std::uint64_t fileSize = regularFileSize(p);
    const RawLayout L = rawLayout(p, options);
    const std::size_t ss = sampleSize(L.type);
    Volume v = makeVolume(hi - lo, options.spacing.value_or(glm::dvec3(1.0)), name);
    v.origin = v.spacing * glm::dvec3(lo);
    const std::uint64_t lastByte =
        L.offset + ((std::uint64_t(hi.z - 1) * L.dims.y + (hi.y - 1)) * L.dims.x + hi.x) * ss;
    if (lastByte > fileSize)
        throw Error(name + ": truncated data: the brick of samples " + std::to_string(lo.x) + "," +
                    std::to_string(lo.y) + "," + std::to_string(lo.z) + " to " +
                    std::to_string(hi.x - 1) + "," + std::to_string(hi.y - 1) + "," +
                    std::to_string(hi.z - 1) + " ends at byte " + std::to_string(lastByte) +
                    ", the file holds " + std::to_string(fileSize));
    const int fd = ::open(p.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) throw Error(name + ": cannot read (" + std::strerror(errno) + ")");
    std::vector<unsigned char> row(std::size_t(v.dims.x) * ss);
    for (int k = 0; k < v.dims.z; ++k)
        for (int j = 0; j < v.dims.y; ++j) {
            const std::uint64_t at =
                L.offset +
                ((std::uint64_t(lo.z + k) * L.dims.y + (lo.y + j)) * L.dims.x + lo.x) * ss;
            std::size_t got = 0;
            while (got < row.size()) {
                const ssize_t n = ::pread(fd, row.data() + got, row.size() - got, off_t(at + got));
                if (n < 0 && errno == EINTR) continue;
                if (n <= 0) {
                    ::close(fd);
                    throw Error(name + ": cannot read bytes " + std::to_string(at) + " on");
                }
                got += std::size_t(n);
            }
            decodeSamples(row.data(), std::size_t(v.dims.x), L.type, options.bigEndian,
                          &v.at(0, j, k));
        }
    ::close(fd);
    v.source = std::string("raw ") + sampleTypeName(L.type) + " (" + p.filename().string() + ")";
    return v;
}

}  // namespace

Volume volumeGeometry(const std::string& spec, const LoadOptions& options, bool* alone) {
    Volume g;
    if (isSynthetic(spec)) {
        const auto [name, n] = detail::syntheticSpec(spec);
        g = makeSyntheticBrick(name, n, glm::ivec3(0), glm::ivec3(1));
        g.dims = glm::ivec3(n);
        g.origin = glm::dvec3(0.0);
        g.backgroundSource = "synthetic volume";
    } else if (isPlainRaw(spec)) {
        const detail::RawLayout L = detail::rawLayout(fs::path(spec), options.raw);
        g.dims = L.dims;
        g.spacing = options.raw.spacing.value_or(glm::dvec3(1.0));
        g.source = std::string("raw ") + detail::sampleTypeName(L.type) + " (" +
                   fs::path(spec).filename().string() + ")";
    } else {
        g = loadVolume(spec, options);
    }
    g.data.clear();
    g.data.shrink_to_fit();
    if (alone) *alone = isSynthetic(spec) || isPlainRaw(spec);
    return g;
}

Volume loadVolumeBrick(const std::string& spec, const LoadOptions& options, const glm::ivec3& lo,
                       const glm::ivec3& hi) {
    if (isSynthetic(spec)) {
        const auto [name, n] = detail::syntheticSpec(spec);
        Volume v = makeSyntheticBrick(name, n, lo, hi);
        v.backgroundSource = "synthetic volume";
        return v;
    }
    if (isPlainRaw(spec)) return readRawBrick(fs::path(spec), options.raw, lo, hi);
    return crop(loadVolume(spec, options), lo, hi);
}

}  // namespace splat
