// The axis-aligned sheet-buffer splatter (Westover 1990, "Footprint evaluation for volume
// rendering"): sheets are the volume slices perpendicular to the volume axis most
// parallel to the view; every kernel is integrated whole (its footprint) into the sheet
// of its slice, and sheets are composited in visibility order. When the major axis
// changes (e.g. at 45 degrees) the sheets change orientation: that is the popping
// artifact the image-aligned splatter removes.
#include "axis_splatter.h"

#include <chrono>
#include <cmath>

#include "frame/tile_binning.h"

namespace splat {

int majorAxis(const glm::dvec3& view) {
    const glm::dvec3 a = glm::abs(view);
    return a.x >= a.y && a.x >= a.z ? 0 : (a.y >= a.z ? 1 : 2);
}

namespace {

template <int NCh>
Image renderAxis(const FrameInputs& in, const ProjectedSplats& proj, RenderStats* stats) {
    const auto start = std::chrono::steady_clock::now();
    const SplatList& s = in.splats;
    const int m = majorAxis(in.camera.view);
    const bool ascending =
        (in.camera.view[m] >= 0) == (in.settings.order == CompositeOrder::FrontToBack);
    const std::vector<std::uint16_t>& index = m == 0 ? s.i : (m == 1 ? s.j : s.k);

    // Visiting order: by slice, in visibility order for the compositing direction. The
    // list arrives sorted by slice along m, so the order is the list or its reverse.
    std::vector<std::uint32_t>& order = in.work.order;
    order.resize(s.size());
    for (std::size_t n = 0; n < s.size(); ++n)
        order[n] = std::uint32_t(ascending ? n : s.size() - 1 - n);
    TileBins& bins = in.work.bins;
    binToTiles(proj, order, TileGrid(in.camera.width(), in.camera.height(), in.settings.tileSize),
               bins);

    // A ray crosses the slab around one slice over spacing_m / |view_m| world units.
    glm::dvec3 axis(0.0);
    axis[m] = 1.0;
    const float pathLength = float(in.volume.spacing[m] / std::abs(in.camera.view[m]));
    const std::vector<float> pathScale = perspectivePathScale(in.camera, axis);
    const SheetModel model{in.settings.mode, in.settings.classification, &in.transfer};
    const footprint::FootprintTable& table = in.table;

    if (stats) stats->binMs = msSince(start);
    return renderTiles<NCh>(
        in, bins, pathScale, stats,
        [&](int t, TileAccumulator& acc, const float* tileScale, TileCounters& cnt) {
            const int ox = (t % bins.grid.tilesX) * bins.grid.tileSize;
            const int oy = (t / bins.grid.tilesX) * bins.grid.tileSize;
            SheetBuffer<NCh> sheet(ox, oy, acc.width(), acc.height());
            int current = -1;
            for (std::uint32_t n = bins.begin[t]; n < bins.begin[t + 1]; ++n) {
                const std::uint32_t id = bins.splats[n];
                if (index[id] != current) {
                    if (sheet.dirty()) {
                        sheet.flush(acc, model, pathLength, tileScale);
                        ++cnt.sheets;
                    }
                    current = index[id];
                    if (acc.allOpaque()) {
                        cnt.culled += bins.begin[t + 1] - n;
                        break;
                    }
                }
                const PixelRect r = clipToTile(proj.rect[id], bins.grid, t);
                if (acc.rectOpaque(r.x0 - ox, r.y0 - oy, r.x1 - ox, r.y1 - oy)) {
                    ++cnt.culled;
                    continue;
                }
                const footprint::EllipticalFootprint& e = proj.ellipse(id);
                float v[NCh];
                splatValues<NCh>(in, id, v);
                cnt.footprintPixels +=
                    sheet.splatFootprint(v, proj.sx[id], proj.sy[id], e, r, table, in.poly);
            }
            if (sheet.dirty()) {
                sheet.flush(acc, model, pathLength, tileScale);
                ++cnt.sheets;
            }
        });
}

}  // namespace

Image renderAxisAligned(const FrameInputs& in, const ProjectedSplats& proj, RenderStats* stats) {
    return withChannels(in.settings, [&]<int NCh>() { return renderAxis<NCh>(in, proj, stats); });
}

}  // namespace splat
