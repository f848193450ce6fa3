// The splatters' frame pipeline: one frame of one list (a Scene or a level of detail of
// it), every stage in order:
//
//   shade -> project -> order -> bin -> tiles (cut kernels into sheets, composite) -> resolve
//
// The stages are free functions over plain arrays (frame/, splatters/); the two splatters
// differ only in `order` and in how `tiles` cuts a kernel into sheets.
#include <algorithm>
#include <chrono>

#include "frame/clip_cut.h"
#include "frame/policy_context.h"
#include "frame/projection.h"
#include "frame/stopwatch.h"
#include "frame/tile_binning.h"
#include "frame/workspace.h"
#include "splatters/factorised_sheets.h"
#include "splatters/splatter.h"

namespace splat {

namespace {

/// Emission to splat: null (the list's own, SplatList::emission) or (shaded scenes) this
/// view's shaded emission.
struct Emission {
    const float *r, *g, *b;
};

/// Stage "shade": headlight shading of the emission for this view, only when the scene is
/// shaded.
Emission shade(const Scene::Impl& scene, const Camera& camera, FrameWorkspace& work,
               RenderStats& stats) {
    const SplatList& s = scene.splats;
    if (!scene.shaded()) return {nullptr, nullptr, nullptr};  // the list's own (emission())
    const auto start = Clock::now();
    shadeEmission(s, scene.settings.shading, camera.view, work.r, work.g, work.b);
    stats.shadeMs = msSince(start);
    return {work.r.data(), work.g.data(), work.b.data()};
}

/// Stage "project": screen positions, depths and footprint ellipses of every splat.
void project(const Scene::Impl& scene, const Camera& camera, const Quality& quality,
             RenderMode mode, FrameWorkspace& work, RenderStats& stats) {
    const auto start = Clock::now();
    projectSplats(scene.splats, camera, scene.volume->spacing, scene.kernel.radius(), work.proj,
                  footprintFilter(scene.kernel, quality, mode, camera, *scene.volume, scene.level));
    stats.projectMs = msSince(start);
}

/// Stage "order": the splatter's visiting order and sheet plan.
SheetPlan order(const Splatter& splatter, const Scene::Impl& scene, const Camera& camera,
                const RenderSettings& s, FrameWorkspace& work, RenderStats& stats) {
    const auto start = Clock::now();
    const SheetPlan plan = splatter.order(scene, camera, s, work, stats);
    stats.orderMs = msSince(start);
    return plan;
}

/// Stage "bin": every splat listed in the screen tiles its footprint touches.
void bin(const Camera& camera, const RenderSettings& s, FrameWorkspace& work, RenderStats& stats) {
    const auto start = Clock::now();
    binToTiles(work.proj, work.order, work.key, work.span,
               TileGrid(camera.width(), camera.height(), s.quality.tileSize), work.bins);
    stats.binMs = msSince(start);
}

/// Iso: the hit positions (fractional sheets in visiting order) as world distances along
/// each pixel's ray from Camera::ray's origin.
Image isoDepthFromSheets(const Image& positions, const SheetPlan& plan, const Camera& camera,
                         const Volume& volume) {
    Image depth(positions.width, positions.height);
    for (int y = 0; y < positions.height; ++y)
        for (int x = 0; x < positions.width; ++x) {
            const glm::vec4 p = positions.at(x, y);
            if (p.a == 0.0f) continue;
            const Ray ray = camera.ray(x + 0.5, y + 0.5);
            double t;
            if (plan.axis >= 0) {  // axis-aligned: the slice plane index = sigma
                const int m = plan.axis;
                const double sigma = plan.ascending ? p.r : double(plan.sheets) - 1.0 - p.r;
                const double p0 = (ray.origin[m] - volume.origin[m]) / volume.spacing[m];
                t = (sigma - p0) / (ray.dir[m] / volume.spacing[m]);
            } else {  // image-aligned: slab centres
                const double d = plan.depthOrigin + (double(p.r) + 0.5) * plan.thickness;
                t = d / glm::dot(ray.dir, camera.view) -
                    glm::dot(ray.origin - camera.eye, camera.view);
            }
            depth.at(x, y) = glm::vec4(glm::vec3(float(t)), 1.0f);
        }
    return depth;
}

/// Factorised sheets with Quality::warpTolerance: the pixels flagged in `edges` (where the
/// warp cannot follow the intermediate image) taken from the per-splat frame, which renders
/// only the tiles holding them (their pixels are the whole per-splat frame's bit for bit:
/// the other tiles count as opaque to its culling, which only skips what they alone need).
void fixEdges(const Splatter& splatter, const Scene::Impl& scene, const Camera& camera,
              const RenderSettings& s, const Emission& e, const std::vector<std::uint8_t>& edges,
              FrameWorkspace& work, RenderStats& stats, Image& image) {
    const TileGrid g(camera.width(), camera.height(), s.quality.tileSize);
    std::vector<std::uint8_t> tiles(std::size_t(g.count()), 0);
    bool any = false;
    for (int y = 0; y < camera.height(); ++y)
        for (int x = 0; x < camera.width(); ++x)
            if (edges[std::size_t(y) * std::size_t(camera.width()) + std::size_t(x)]) {
                tiles[std::size_t(g.tileOf(y) * g.tilesX + g.tileOf(x))] = 1;
                any = true;
            }
    if (!any) return;
    RenderStats fixStats;
    const SheetPlan plan = splatter.order(scene, camera, s, work, fixStats);
    const PolicyContext ctx = policyContext(scene, camera, s);
    TileInputs in{scene, camera, s, work.proj, work.bins, plan, e.r, e.g, e.b, ctx, nullptr};
    in.tiles = &tiles;
    const Image exact = splatter.rasterize(in, work, &fixStats);
    // Whole tiles: the pixels beside a flagged one are near the same edge, and the per-splat
    // frame has drawn them anyway.
    for (int t = 0; t < g.count(); ++t) {
        if (!tiles[std::size_t(t)]) continue;
        const int ox = (t % g.tilesX) * g.tileSize, oy = (t / g.tilesX) * g.tileSize;
        const int w = std::min(g.tileSize, g.width - ox), h = std::min(g.tileSize, g.height - oy);
        for (int y = oy; y < oy + h; ++y)
            std::copy_n(&exact.at(ox, y), w, &image.at(ox, y));
        stats.warpFixPixels += std::size_t(w) * std::size_t(h);
        ++stats.warpFixTiles;
    }
    stats.binMs += fixStats.binMs;
    stats.tilesMs += fixStats.tilesMs;
    stats.footprintPixels += fixStats.footprintPixels;
    stats.culledSplats += fixStats.culledSplats;
}

}  // namespace

Image splatFrame(const Scene::Impl& scene, const Camera& camera, const RenderSettings& s,
                 RenderStats& stats, Image* depth) {
    const Splatter& splatter =
        s.renderer == RendererKind::Axis ? axisAlignedSplatter() : imageAlignedSplatter();
    const WorkspaceLease work(scene);
    stats.ewaSigma =
        footprintFilter(scene.kernel, s.quality, s.mode, camera, *scene.volume, scene.level)
            .lowPass;
    const Emission e = shade(scene, camera, *work, stats);
    if (!depth && factorisedSheetsApply(camera, s, scene.settings.labels.enabled,
                                        s.clipping.enabled(), stats.ewaSigma, scene.level)) {
        std::vector<std::uint8_t> edges;
        const bool fix = s.quality.warpTolerance > 0 && splatter.streams();
        Image image =
            renderFactorisedSheets(scene, camera, s, e.r, e.g, e.b, stats, fix ? &edges : nullptr);
        if (fix) fixEdges(splatter, scene, camera, s, e, edges, *work, stats, image);
        applyBackground(image, s.mode, s.background, scene.splats.background);
        return image;
    }
    if (!splatter.streams()) project(scene, camera, s.quality, s.mode, *work, stats);
    const SheetPlan plan = order(splatter, scene, camera, s, *work, stats);
    if (!splatter.streams()) bin(camera, s, *work, stats);
    PolicyContext ctx = policyContext(scene, camera, s);
    // Clipping cuts the sheets at the planes and box per pixel (frame/clip_cut.h).
    const ClipCut cut(s.clipping, camera, plan, *scene.volume, scene.kernel.radius(),
                      s.order == CompositeOrder::FrontToBack);
    if (!cut.empty()) ctx.cut = &cut;
    Image positions;
    if (depth) positions = Image(camera.width(), camera.height());
    const TileInputs in{scene,
                        camera,
                        s,
                        work->proj,
                        work->bins,
                        plan,
                        e.r,
                        e.g,
                        e.b,
                        ctx,
                        depth ? &positions : nullptr};
    Image image = splatter.rasterize(in, *work, &stats);
    applyBackground(image, s.mode, s.background, scene.splats.background);
    if (depth) *depth = isoDepthFromSheets(positions, plan, camera, *scene.volume);
    return image;
}

}  // namespace splat
