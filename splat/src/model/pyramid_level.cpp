// The level of a stored pyramid (an OME-Zarr image's levels) that the level-of-detail rule
// picks for a view (splat/sparse_files.h zarrLevelForView): the rule the splatters apply to
// the pyramid they build (dispatch levelOfDetail), applied to the file's levels instead, so
// that only the chosen level is read.
#include <footprint/kernel.h>

#include <stdexcept>

#include "model/level_of_detail.h"
#include "splat/error.h"
#include "splat/sparse_files.h"

namespace splat {
namespace {

/// The level the rule of `q` picks in `mode` from a pyramid whose level l has voxels of
/// voxelPixels[l] pixels (the one place that reads Quality::lod):
/// a pixel threshold: the first level whose voxel covers at least that many pixels (else the
/// last); auto: lodAutoLevel of level 0's voxel in the modes where it applies; brick (levels
/// per brick, which the renderer builds from level 0) and off: level 0.
int pyramidLevel(const Quality& q, RenderMode mode, double kernelVariance,
                 const std::vector<double>& voxelPixels) {
    const int last = int(voxelPixels.size()) - 1;
    using Kind = LevelOfDetail::Kind;
    switch (q.lod.kind) {
    case Kind::Auto: {
        if (!lodAutoApplies(mode)) return 0;
        const double sigma = q.pixelFilter > 0 ? q.pixelFilter : Quality::kEwaDefaultSigma;
        return lodAutoLevel(voxelPixels[0], sigma, kernelVariance, last);
    }
    case Kind::Pixels: {
        int level = 0;
        while (level < last && voxelPixels[std::size_t(level)] < q.lod.pixels) ++level;
        return level;
    }
    case Kind::Off:
    case Kind::Brick: break;
    }
    return 0;
}

double kernelVarianceOf(const RenderSettings& s) {
    try {
        return footprint::Kernel::fromName(s.kernel, s.kernelSigma, s.kernelRadius).variance();
    } catch (const std::invalid_argument& e) {
        throw Error(e.what());
    }
}

}  // namespace

int zarrLevelForView(const ZarrImageInfo& image, const RenderSettings& settings) {
    if (image.levels.size() < 2 || settings.renderer == RendererKind::Reference) return 0;
    // The camera of level 0, as the renderer places it for the volume of level 0.
    Volume level0;
    level0.dims = image.levels[0].dims;
    level0.spacing = image.levels[0].spacing;
    level0.origin = image.levels[0].origin;
    const Camera camera(settings.camera, level0);
    std::vector<double> pixels;
    for (const ZarrLevelInfo& L : image.levels) {
        Volume g;
        g.spacing = L.spacing;
        pixels.push_back(voxelPixels(camera, g));
    }
    return pyramidLevel(settings.quality, settings.mode, kernelVarianceOf(settings), pixels);
}

}  // namespace splat
