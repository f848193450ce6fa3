#pragma once
// The two splatters behind one small interface. They share every stage of the frame
// (shade, project, bin, the tile sweep, compositing); each decides only
//   order:     the visiting order of the splats and how the view's sheets lie, and
//   rasterize: how one splat's kernel is cut into the sheets of one tile
//              (its Cutter for the shared tile sweep, frame/tile_driver.h).
// axis_aligned.cpp: Westover's sheets along the volume axis (whole footprints);
// image_aligned.cpp: Mueller & Crawfis's slabs parallel to the image (slab sections).
#include "frame/tile_driver.h"
#include "frame/workspace.h"
#include "model/scene_impl.h"

namespace footprint {
class FootprintPoly;
class SlabTable;
}  // namespace footprint

namespace splat {

class Splatter {
  public:
    virtual ~Splatter() = default;
    /// Stage "order": writes the visiting order into work.order, or work.chunks when it
    /// streams (and any per-splat keys the splatter needs), and returns the view's sheet
    /// plan. A splatter that does not stream finds work.proj projected.
    virtual SheetPlan order(const Scene::Impl& scene, const Camera& camera,
                            const RenderSettings& settings, FrameWorkspace& work,
                            RenderStats& stats) const = 0;
    /// Stage "tiles": the tile sweep with this splatter's Cutter, into a partial image.
    virtual Image rasterize(const TileInputs& in, FrameWorkspace& work,
                            RenderStats* stats) const = 0;
    /// True when the splatter projects and bins its splats itself, chunk by chunk front to
    /// back inside `rasterize` (work.chunks), skipping splats hidden by then; the frame
    /// then runs no whole-frame "project" and "bin" stages (their times are in binMs).
    virtual bool streams() const { return false; }
};

const Splatter& axisAlignedSplatter();

/// The image-aligned splatter's stage "order" on `slabCount` slabs of settings.quality.slab
/// voxels whose first boundary lies at depth zmin: the one-process frame's grid when zmin is
/// its nearest kernel's front (exact bricks, splat/slab_sheets.h, give every brick the
/// whole frame's grid).
SheetPlan orderOnSlabs(const Scene::Impl& scene, const Camera& camera,
                       const RenderSettings& settings, FrameWorkspace& work, RenderStats& stats,
                       float zmin, double slabCount);
/// Exact bricks (splat/slab_sheets.h): adds the slab sections of the binned splats in slabs
/// [first, first + count) (visiting order) into per-tile blocks, tile t's slab first + k at
/// blocks + (t count + k) B, B = channels tileSize^2 floats (channel c, tile-local pixel (x, y)
/// at c tileSize^2 + y tileSize + x), and widens each block's written rectangle, rects + 4 (t
/// count + k) = (x0, y0, -x1, -y1) (tile-local, inclusive), by the minimum.
void addSlabSheets(const TileInputs& in, std::uint32_t first, std::uint32_t count, float* blocks,
                   int* rects);
const Splatter& imageAlignedSplatter();
/// The image-aligned splatter's step "cut": adds one kernel's sections in the n slabs
/// between depths tb[0 .. n] (along its rays, relative to its centre) to sheets[0 .. n - 1],
/// as the tile sweep does; returns the pixels visited. pairNarrowRows false computes
/// rectangles at most 4 pixels wide one row per vector like wider ones (tests compare the
/// two).
int cutIntoSlabs(SheetBuffer<4>* const* sheets, int n, const float (&values)[4], float sx, float sy,
                 const footprint::EllipticalFootprint& e, const PixelRect& rect,
                 const footprint::SlabTable& table, const footprint::FootprintPoly* poly,
                 const float* tb, bool pairNarrowRows);

/// Index (0, 1, 2) of the volume axis most parallel to the ray direction in index space,
/// S^-1 view (docs/design.md: anisotropic spacing is honoured), and the sign of that component.
struct SheetAxis {
    int axis, sign;
};
SheetAxis sheetAxis(const glm::dvec3& view, const glm::dvec3& spacing);

/// The splatters' frame of `scene` (a Scene or one level of detail of it) seen by `camera`
/// (splatters/splat_frame.cpp): settings.renderer's stages shade -> project -> order -> bin ->
/// tiles on the calling thread's arena. With `depth` (iso only): the hit depths as well.
Image splatFrame(const Scene::Impl& scene, const Camera& camera, const RenderSettings& settings,
                 RenderStats& stats, Image* depth);

}  // namespace splat
