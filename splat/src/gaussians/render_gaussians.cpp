// renderGaussians: one frame of a Gaussian scene, project -> bin to tiles -> render, with the
// renderer of the options (splat/gaussians.h).
#include <tbb/task_arena.h>

#include <cmath>
#include <string>

#include "renderers.h"
#include "splat/error.h"

namespace splat {

const char* gaussianRendererName(GaussianRenderer renderer) {
    switch (renderer) {
        case GaussianRenderer::Rasterizer:
            return "3dgs";
        case GaussianRenderer::PixelSorted:
            return "3dgs-pixel";
        case GaussianRenderer::Sheet:
            return "sheet";
        case GaussianRenderer::Reference:
            return "reference";
    }
    return "?";
}

GaussianRenderer parseGaussianRenderer(const std::string& name) {
    for (GaussianRenderer r : {GaussianRenderer::Rasterizer, GaussianRenderer::PixelSorted,
                               GaussianRenderer::Sheet, GaussianRenderer::Reference})
        if (name == gaussianRendererName(r)) return r;
    throw Error("unknown Gaussian renderer '" + name + "' (3dgs, 3dgs-pixel, sheet, reference)");
}

Image renderGaussians(const GaussianScene& scene, const CameraParams& params,
                      const GaussianRenderOptions& options) {
    using namespace gaussians;
    if (!(options.slab >= 0) || !std::isfinite(options.slab))
        throw Error("slab thickness must be a finite number >= 0 (0: automatic)");
    if (!(options.tolerance > 0) || !std::isfinite(options.tolerance))
        throw Error("reference tolerance must be a finite number > 0");
    if (options.threads < 0) throw Error("threads must be >= 0 (0: all)");
    const Camera camera(params, scene.geometry());
    const ViewFrame frame = viewFrame(camera);
    const GaussianRenderer kind = options.renderer;
    auto run = [&] {
        const bool volume = kind == GaussianRenderer::Sheet || kind == GaussianRenderer::Reference;
        // Gaussians whose optical depth along a ray stays below epsilon are left out of the
        // volume renderers: at most epsilon of opacity each.
        const double epsilon = kind == GaussianRenderer::Reference ? 0.1 * options.tolerance : 1e-6;
        const Projected p = project(scene, frame, volume ? Footprint::Volume : Footprint::Splat,
                                    epsilon, kind != GaussianRenderer::Rasterizer);
        const TileLists tiles = binToTiles(p, camera.width(), camera.height());
        switch (kind) {
            case GaussianRenderer::Rasterizer:
                return rasterize(p, tiles, camera.width(), camera.height());
            case GaussianRenderer::PixelSorted:
                return rasterizePixelSorted(scene, p, tiles, camera);
            case GaussianRenderer::Sheet: {
                const double slab =
                    options.slab > 0 ? options.slab : 2.0 * camera.boundingRadius / 256.0;
                return renderSlabs(scene, p, tiles, camera, slab, epsilon);
            }
            case GaussianRenderer::Reference:
                return renderReference(scene, p, tiles, camera, options.tolerance, epsilon);
        }
        return Image();
    };
    if (options.threads > 0) {
        tbb::task_arena arena(options.threads);
        return arena.execute(run);
    }
    return run();
}

}  // namespace splat
