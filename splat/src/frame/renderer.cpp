// The frame pipeline: one frame of a Scene, every stage in order, on the frame's threads.
//
//   shade -> project -> order -> bin -> tiles (cut kernels into sheets, composite) -> resolve
//
// The stages are free functions over plain arrays (frame/, splatters/); the two splatters
// differ only in `order` and in how `tiles` cuts a kernel into sheets. The reference ray
// caster renders the same Scene's fields instead (reference/).
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <chrono>
#include <memory>

#include "frame/compositing.h"
#include "frame/frame.h"
#include "frame/projection.h"
#include "frame/stopwatch.h"
#include "frame/tile_binning.h"
#include "model/brick_lod.h"
#include "model/level_of_detail.h"
#include "reference/pixel_filter.h"
#include "reference/reference_frame.h"
#include "splat/error.h"
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
    projectSplats(
        scene.splats, camera, scene.volume->spacing, scene.kernel.radius(), work.proj,
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

}  // namespace

PolicyContext policyContext(const Scene::Impl& scene, const Camera& camera,
                            const RenderSettings& s) {
    PolicyContext ctx;
    ctx.mode = s.mode;
    ctx.classification = s.classification;
    ctx.transfer = &scene.transfer;
    const bool postDvr = s.mode == RenderMode::Dvr && s.classification == Classification::Post;
    ctx.gradients = postDvr && scene.needsGradients();
    ctx.shade = postDvr && s.shading.enabled;
    ctx.shading = s.shading;
    ctx.light = lightFrame(s.shading, camera.view);
    if (postDvr) ctx.edges = s.edges;
    const float g = scene.splats.gradientScale;
    ctx.invGradientScale = g > 0.0f ? 1.0f / g : 0.0f;
    // The sheets hold f - b (SplatList::background): the level is compared as level - b.
    ctx.isoLevel = float(s.isoLevel - double(scene.splats.background));
    ctx.isoColour = glm::vec3(s.transfer.sample(float(s.isoLevel)));
    if (s.mode == RenderMode::Dvr && scene.settings.labels.enabled)
        ctx.labelTable = &scene.labelTable;
    return ctx;
}

namespace {

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

Image splatFrame(const Scene::Impl& scene, const Camera& camera, const RenderSettings& s,
                 RenderStats& stats, Image* depth) {
    const Splatter& splatter =
        s.renderer == RendererKind::Axis ? axisAlignedSplatter() : imageAlignedSplatter();
    const WorkspaceLease work(scene);
    stats.ewaSigma =
        footprintFilter(scene.kernel, s.quality, s.mode, camera, *scene.volume, scene.level)
            .lowPass;
    const Emission e = shade(scene, camera, *work, stats);
    if (!splatter.streams()) project(scene, camera, s.quality, s.mode, *work, stats);
    const SheetPlan plan = order(splatter, scene, camera, s, *work, stats);
    if (!splatter.streams()) bin(camera, s, *work, stats);
    PolicyContext ctx = policyContext(scene, camera, s);
    // Issue 13: clipping cuts the sheets at the planes and box per pixel (frame/clip_cut.h).
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

/// The reference's nearest-voxel label lookup (null without labels).
const LabelLookup* labelLookup(const Scene::Impl& scene) {
    if (!scene.settings.labels.enabled) return nullptr;
    thread_local LabelLookup lookup;
    lookup = {scene.volume->dims, &scene.labelGrid, &scene.labelTable};
    return &lookup;
}

Image referenceFrame(const Scene::Impl& scene, const Camera& camera, const RenderSettings& s,
                     RenderStats& stats, Image* depth) {
    if (!scene.shaded())
        return renderReference(*scene.volume, scene.referenceField(), camera, s, &stats, depth,
                               scene.splats.gradientScale, labelLookup(scene));
    // Shaded emission depends on the view: the field is made for this frame.
    SplatList lit = scene.splats;
    lit.expandEmission();
    shadeEmission(scene.splats, scene.settings.shading, camera.view, lit.r, lit.g, lit.b);
    const ReferenceField field(*scene.volume, lit, scene.kernel, FieldLayout::Emission);
    return renderReference(*scene.volume, field, camera, s, &stats, depth,
                           scene.splats.gradientScale, labelLookup(scene));
}

/// The reference through the Gaussian pixel filter (Quality::pixelFilter, pixel_filter.h);
/// an iso depth image stays point-sampled (a filtered depth is no surface's depth).
Image filteredReferenceFrame(const Scene::Impl& scene, const Camera& camera,
                             const RenderSettings& s, RenderStats& stats, Image* depth) {
    RenderStats fine;
    const PixelFilterResult r = filteredImage(
        camera, s.quality.pixelFilter, s.quality.pixelFilterTolerance, [&](const CameraParams& p) {
            return referenceFrame(scene, Camera(p, *scene.volume), s, fine, nullptr);
        });
    stats.referenceStep = fine.referenceStep;
    stats.pixelSamples = r.samples;
    stats.pixelFilterChange = r.change;
    if (depth) {
        RenderStats centre;
        (void)referenceFrame(scene, camera, s, centre, depth);
    }
    return r.image;
}

/// True when a perspective frame has a kernel whose bounding sphere comes within two of its
/// radii of the eye plane (or behind it): there the local-affine footprint (the Jacobian at
/// the kernel centre) is no longer a valid approximation, and a kernel straddling the near
/// plane has no finite footprint at all.
bool needsExactPath(const Scene::Impl& scene, const Camera& camera) {
    if (!camera.perspective()) return false;
    const SplatList& s = scene.splats;
    const glm::dvec3 sp = scene.volume->spacing;
    const double bound = scene.kernel.radius() * std::max(sp.x, std::max(sp.y, sp.z));
    const double nearest = 3.0 * bound;
    const glm::dvec3 eye = camera.eye, view = camera.view;
    return tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, s.size(), 8192), false,
        [&](const tbb::blocked_range<std::size_t>& r, bool found) {
            for (std::size_t n = r.begin(); n != r.end() && !found; ++n) {
                const glm::dvec3 w = s.world(n);
                const double depth = glm::dot(w - eye, view);
                // Kernels entirely behind the eye contribute nothing to any ray.
                if (depth > -bound && depth < nearest) found = true;
            }
            return found;
        },
        [](bool a, bool b) { return a || b; });
}

/// The lists the splatters render for this view, finest first (one unless `--lod brick`
/// mixes levels). Quality::lod: the level of detail coarser while a voxel of the level covers
/// fewer than `lod` pixels. Auto (Quality::lodAuto): lodAutoLevel of the level-0 voxel's size,
/// in the modes where it was measured free (lodAutoApplies). Brick (Quality::lodBrick): in
/// the same modes a level per brick of the level-0 grid (model/brick_lod.h), one list per
/// level in use. Each list is the scene itself, a level of its pyramid, or a part of one.
std::vector<std::shared_ptr<const Scene::Impl>> levelOfDetail(const Scene::Impl& scene,
                                                              const Camera& camera,
                                                              const Quality& q, RenderMode mode) {
    // Levels are owned by the pyramid: no owner here.
    auto one = [](const Scene::Impl& l) {
        return std::vector<std::shared_ptr<const Scene::Impl>>{
            std::shared_ptr<const Scene::Impl>(std::shared_ptr<const Scene::Impl>(), &l)};
    };
    const double sigma = q.pixelFilter > 0 ? q.pixelFilter : Quality::kEwaDefaultSigma;
    const Scene::Impl* level = &scene;
    if (q.lodAuto) {
        if (!lodAutoApplies(mode)) return one(scene);
        const int target =
            lodAutoLevel(voxelPixels(camera, *scene.volume), sigma, scene.kernel.variance(), 16);
        while (level->level < target) {
            const Scene::Impl* next = level->coarser();
            if (!next) break;
            level = next;
        }
        return one(*level);
    }
    if (q.lodBrick) {
        if (!lodAutoApplies(mode)) return one(scene);
        auto levels = [&](const BrickDetail* detail) {
            return brickLevels(camera, scene.splats.origin, scene.splats.spacing,
                               scene.volume->dims, sigma, scene.kernel.variance(),
                               kLodBrickMaxLevel, detail);
        };
        // The geometric rule alone first: where it keeps every brick at level 0 (a voxel
        // covering more than ~0.47 pixels) the pyramid is not even made.
        const std::vector<std::uint8_t> geometric = levels(nullptr);
        if (std::all_of(geometric.begin(), geometric.end(), [](std::uint8_t l) { return l == 0; }))
            return one(scene);
        return scene.lodParts(levels(&scene.brickDetail()));
    }
    const double lod = q.lod;
    if (lod > 0)
        while (voxelPixels(camera, *level->volume) < lod) {
            const Scene::Impl* next = level->coarser();
            if (!next) break;
            level = next;
        }
    return one(*level);
}

/// Adds the counters of a frame of one part of a mixed-level frame to the frame's.
void addPartStats(const RenderStats& part, RenderStats& frame) {
    frame.footprintPixels += part.footprintPixels;
    frame.sheets += part.sheets;
    frame.culledSplats += part.culledSplats;
    frame.slabs += part.slabs;
    frame.pathScalePixels += part.pathScalePixels;
    frame.shadeMs += part.shadeMs;
    frame.projectMs += part.projectMs;
    frame.orderMs += part.orderMs;
    frame.binMs += part.binMs;
    frame.tilesMs += part.tilesMs;
    if (frame.sheetAxis < 0) {
        frame.sheetAxis = part.sheetAxis;
        frame.sheetSign = part.sheetSign;
    }
    if (!(frame.ewaSigma > 0)) frame.ewaSigma = part.ewaSigma;
}

/// The splatters' frame of the lists `parts` (levelOfDetail): one list is one frame; more
/// (X-ray, a sum over splats) are a frame per list, summed.
Image splatParts(const std::vector<std::shared_ptr<const Scene::Impl>>& parts,
                 const Camera& camera, const RenderSettings& s, RenderStats& stats,
                 Image* depth) {
    stats.lodLevelSplats.clear();
    auto count = [&](const Scene::Impl& part) {
        const std::size_t L = std::size_t(part.level);
        if (stats.lodLevelSplats.size() <= L) stats.lodLevelSplats.resize(L + 1, 0);
        stats.lodLevelSplats[L] += part.splats.size();
        stats.lodLevel = std::max(stats.lodLevel, part.level);
        stats.lodSplats += part.splats.size();
    };
    // `--lod brick` below a pixel per voxel: level 0 through the pixel filter too (as EWA),
    // like the merged levels, whatever --ewa says (the levels' footprints then carry the same
    // total variance), also where every brick kept level 0.
    RenderSettings filtered = s;
    if (s.quality.lodBrick && lodAutoApplies(s.mode) &&
        voxelPixels(camera, *parts.front()->volume) < Quality::kEwaAutoPixels)
        filtered.quality.ewa = Ewa::On;
    if (parts.size() == 1) {
        count(*parts.front());
        return splatFrame(*parts.front(), camera, filtered, stats, depth);
    }
    if (s.mode != RenderMode::Xray)
        throw Error("internal: levels of detail are mixed in a frame only in X-ray");
    Image image;
    for (const auto& part : parts) {
        count(*part);
        RenderStats ps;
        const Image im = splatFrame(*part, camera, filtered, ps, nullptr);
        addPartStats(ps, stats);
        if (image.pixels.empty()) {
            image = im;
            continue;
        }
        for (std::size_t p = 0; p < image.pixels.size(); ++p)
            image.pixels[p] += glm::vec4(glm::vec3(im.pixels[p]), 0.0f);
    }
    return image;
}

}  // namespace

void validateFrame(const RenderSettings& s) {
    const Quality& q = s.quality;
    if (!(q.slab > 0) || !std::isfinite(q.slab) || q.slab > 1e4)
        throw Error("slab thickness must be a positive number of voxels (got " +
                    std::to_string(q.slab) + ")");
    if (s.renderer == RendererKind::Sheet && q.slab < 1e-3)
        throw Error("slab thickness below 0.001 voxels would need millions of sheets");
    if (!(q.earlyTermination >= 0 && q.earlyTermination < 1))
        throw Error("early termination threshold must be in [0, 1)");
    if (q.tileSize < 8 || q.tileSize > 64) throw Error("tile size must be between 8 and 64 pixels");
    if (!(q.lod >= 0 && q.lod <= 64))
        throw Error("level of detail threshold must be between 0 (off) and 64 pixels per voxel");
    if (!(q.pixelFilter >= 0 && q.pixelFilter <= 4))
        throw Error("pixel filter sigma must be between 0 (point sampling) and 4 pixels");
    if (!(q.pixelFilterTolerance > 0) || !std::isfinite(q.pixelFilterTolerance))
        throw Error("pixel filter tolerance must be a positive number");
    if (s.threads < 0 || s.threads > 1024)
        throw Error("thread count must be between 0 (all) and 1024");
    if (!(q.referenceStep >= 0) || !(q.referenceTolerance > 0))
        throw Error("reference step must be >= 0 (0: automatic) and tolerance positive");
    for (int c = 0; c < 4; ++c)
        if (!(s.background[c] >= 0 && s.background[c] <= 1))
            throw Error("background must be in [0, 1]");
}

Image renderFrame(const Scene::Impl& scene, const RenderSettings& given, RenderStats* stats,
                  Image* depth) {
    const auto start = Clock::now();
    validateFrame(given);
    RenderSettings s = given;
    // Iso in the splatters is the first hit front to back (the option table warns of --order).
    if (s.mode == RenderMode::Iso) s.order = CompositeOrder::FrontToBack;
    RenderStats local;
    local.splats = scene.splats.size();
    local.voxels = scene.splats.voxels;
    local.normals = scene.splats.nx.size();
    Image image;
    runOnThreads(s.threads, [&] {
        const Camera camera(s.camera, *scene.volume);
        local.perspective = camera.perspective();
        // The camera is the full-resolution scene's: a level's grid is centred differently
        // when a dimension is odd.
        const auto parts = s.renderer == RendererKind::Reference
                               ? std::vector<std::shared_ptr<const Scene::Impl>>{}
                               : levelOfDetail(scene, camera, s.quality, s.mode);
        if (s.renderer == RendererKind::Reference) {
            image = s.quality.pixelFilter > 0
                        ? filteredReferenceFrame(scene, camera, s, local, depth)
                        : referenceFrame(scene, camera, s, local, depth);
        } else if (needsExactPath(*parts.front(), camera)) {
            image = referenceFrame(scene, camera, s, local, depth);
            local.exactPixels = std::size_t(camera.width()) * std::size_t(camera.height());
            local.exactReason =
                "the eye is inside or within two kernel radii of the splats (a kernel straddles "
                "the perspective near plane, where a splat footprint is invalid): every pixel "
                "was rendered by the reference ray caster";
        } else {
            image = splatParts(parts, camera, s, local, depth);
        }
    });
    local.milliseconds = msSince(start);
    if (stats) *stats = local;
    return image;
}

std::vector<float> perspectivePathScale(const Camera& camera, const glm::dvec3& axis) {
    if (!camera.perspective()) return {};
    const int w = camera.width(), h = camera.height();
    std::vector<float> scale(std::size_t(w) * h);
    const double ref = std::abs(glm::dot(camera.view, axis));
    tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& rows) {
        for (int y = rows.begin(); y != rows.end(); ++y)
            for (int x = 0; x < w; ++x) {
                const Ray r = camera.ray(x + 0.5, y + 0.5);
                scale[std::size_t(y) * w + x] = float(ref / std::abs(glm::dot(r.dir, axis)));
            }
    });
    return scale;
}

}  // namespace splat
