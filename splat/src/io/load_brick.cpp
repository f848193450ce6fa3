// Reading one brick of a volume (splat/bricks.h): synthetic volumes compute only the brick;
// OME-Zarr images read the chunks the brick intersects (zarr/ome_zarr.h) and OpenVDB files
// the part of the tree it intersects (vdb/openvdb_file.h); NIfTI, NRRD,
// MetaImage and .raw files are read by byte ranges when raw-stored and by one pass over the
// decompressed stream when compressed (sample_layout.h); anything else (DICOM, slice
// folders, NRRD text/hex, ANALYZE pairs) is loaded whole and cropped.
#include "sample_layout.h"
#include "splat/atomic_file.h"
#include "splat/bricks.h"
#include "splat/error.h"
#include "splat/synthetic.h"
#include "splat/volume_io.h"
#include "io/vdb/openvdb_file.h"
#include "volume_detail.h"
#include "io/zarr/ome_zarr.h"

namespace fs = std::filesystem;

namespace splat {

namespace {

bool isSynthetic(const std::string& spec) { return spec.rfind("synthetic:", 0) == 0; }

bool isZarr(const std::string& spec) {
    std::error_code ec;
    return !spec.empty() && fs::is_directory(spec, ec) && detail::isZarrFolder(spec);
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

}  // namespace

Volume volumeGeometry(const std::string& spec, const LoadOptions& options, bool* alone,
                      bool background) {
    Volume g;
    detail::SampleLayout L;
    const bool zarr = !isSynthetic(spec) && isZarr(spec);
    const bool vdb = !isSynthetic(spec) && detail::isVdbFile(spec);
    const bool byLayout = !zarr && !vdb && detail::sampleLayoutOf(spec, options, &L);
    if (zarr) {
        g = detail::zarrGeometry(spec, options, background);
    } else if (vdb) {
        g = detail::vdbGeometry(spec, options);  // b is the grid's background
    } else if (isSynthetic(spec)) {
        const auto [name, n] = detail::syntheticSpec(spec);
        g = makeSyntheticBrick(name, n, glm::ivec3(0), glm::ivec3(1));
        g.dims = glm::ivec3(n);
        g.origin = glm::dvec3(0.0);
        g.backgroundSource = "synthetic volume";
    } else if (byLayout) {
        g = detail::layoutGeometry(L);
        if (background) {  // loadVolume's rule, from the outer faces alone
            g.background = detail::layoutBackground(L, options.nonFinite);
            g.backgroundSource = "median of the outer faces";
        }
    } else {
        g = loadVolume(spec, options);
    }
    g.data.clear();
    g.data.shrink_to_fit();
    if (alone) *alone = isSynthetic(spec) || byLayout || zarr || vdb;
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
    if (isZarr(spec)) {
        Volume v = detail::loadZarrBrick(spec, options, lo, hi);
        detail::applyNonFinitePolicy(v, options.nonFinite, spec);
        return v;
    }
    if (!isSynthetic(spec) && detail::isVdbFile(spec))
        return detail::loadVdbBrick(spec, options, lo, hi);
    detail::SampleLayout L;
    if (detail::sampleLayoutOf(spec, options, &L))
        return detail::readLayoutBrick(L, detail::layoutGeometry(L), lo, hi, options.nonFinite);
    return crop(loadVolume(spec, options), lo, hi);
}

bool volumeReadsByBrick(const std::string& spec, const LoadOptions& options) {
    detail::SampleLayout L;
    return isSynthetic(spec) || isZarr(spec) || detail::isVdbFile(spec) ||
           detail::sampleLayoutOf(spec, options, &L);
}

bool volumeIsSparse(const std::string& spec) {
    return !isSynthetic(spec) && detail::isVdbFile(spec);
}

bool sparseValueRange(const std::string& spec, const LoadOptions& options, float& lo, float& hi) {
    if (!volumeIsSparse(spec)) return false;
    const glm::dvec2 r = detail::vdbValueRange(spec, options);
    lo = float(r.x);
    hi = float(r.y);
    return true;
}

bool brickHoldsOnlyBackground(const std::string& spec, const LoadOptions& options,
                              const glm::ivec3& lo, const glm::ivec3& hi) {
    return volumeIsSparse(spec) && detail::vdbBoxHoldsOnlyBackground(spec, options, lo, hi);
}

}  // namespace splat
