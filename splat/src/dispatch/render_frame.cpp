// The dispatcher: one frame of a Scene, given to the renderer that draws it. The reference
// ray caster draws its own frames and the perspective views where a splat footprint is
// invalid; the splatters draw the list of the level of detail the view asks for (or, in
// X-ray, one frame per level of a mixed-level frame, summed).
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <chrono>
#include <memory>

#include "dispatch/dispatch.h"
#include "frame/stopwatch.h"
#include "model/brick_lod.h"
#include "model/level_of_detail.h"
#include "reference/reference_frame.h"
#include "splat/error.h"
#include "splatters/splatter.h"

namespace splat {

namespace {

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
    if (q.lod.kind == LevelOfDetail::Kind::Auto) {
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
    if (q.lod.kind == LevelOfDetail::Kind::Brick) {
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
    const double lod = q.lod.pixels;
    if (q.lod.kind == LevelOfDetail::Kind::Pixels)
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
Image splatParts(const std::vector<std::shared_ptr<const Scene::Impl>>& parts, const Camera& camera,
                 const RenderSettings& s, RenderStats& stats, Image* depth) {
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
    if (s.quality.lod.kind == LevelOfDetail::Kind::Brick && lodAutoApplies(s.mode) &&
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

Image renderFrame(const Scene::Impl& scene, const RenderSettings& given, RenderStats* stats,
                  Image* depth) {
    const auto start = Clock::now();
    validateFrame(given);
    RenderSettings s = given;
    // Iso in the splatters is the first hit front to back (inapplicableSettings warns).
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

}  // namespace splat
