// The image-aligned sheet-buffer splatter (Mueller & Crawfis 1998, "Eliminating popping
// artifacts in sheet buffer-based splatting"): sheets are slabs of thickness T parallel to
// the image plane; every kernel adds to each slab it crosses the section of its footprint
// between the slab's two depths, C(r, z1) - C(r, z0) from the cumulative slab table. The
// sheets never change orientation, so there is no popping; the cost grows as T shrinks.
//
// Splats are visited through depth buckets: sorted by the first slab they touch (last
// slab for back-to-front), each tile keeps an active list that splats join when the sweep
// reaches their first slab and leave after their last one.
#include <chrono>
#include <cmath>

#include "image_aligned_splatter.h"
#include "tile_binning.h"

namespace splat {

namespace {

template <int NCh>
Image renderSlabs(const FrameInputs& in, const ProjectedSplats& proj, RenderStats* stats) {
    const auto start = std::chrono::steady_clock::now();
    const SplatList& s = in.splats;
    const bool ftb = in.settings.order == CompositeOrder::FrontToBack;
    const float thickness = float(in.settings.slab * in.volume.minSpacing());
    const float ext = proj.depthExtent;

    // The slab grid covers every kernel's depth range [depth - ext, depth + ext].
    float zmin = 0.0f, zmax = 0.0f;
    if (s.size() > 0) {
        zmin = zmax = proj.depth[0];
        for (float d : proj.depth) {
            zmin = std::min(zmin, d);
            zmax = std::max(zmax, d);
        }
    }
    zmin -= ext;
    zmax += ext;
    const std::uint32_t slabs = std::uint32_t(std::floor((zmax - zmin) / thickness)) + 1;
    std::vector<std::uint32_t>&first = in.work.first, &last = in.work.last, &key = in.work.key;
    first.resize(s.size());
    last.resize(s.size());
    key.resize(s.size());
    for (std::size_t n = 0; n < s.size(); ++n) {
        first[n] = std::min(slabs - 1, std::uint32_t((proj.depth[n] - ext - zmin) / thickness));
        last[n] = std::min(slabs - 1, std::uint32_t((proj.depth[n] + ext - zmin) / thickness));
        key[n] = ftb ? first[n] : slabs - 1 - last[n];
    }
    TileBins& bins = in.work.bins;
    orderByKey(key, slabs, in.work.order);
    binToTiles(proj, in.work.order,
               TileGrid(in.camera.width(), in.camera.height(), in.settings.tileSize), bins);
    const std::vector<float> pathScale = perspectivePathScale(in.camera, in.camera.view);
    const SheetModel model{in.settings.mode, in.settings.classification, &in.transfer};
    const footprint::SlabTable& table = *in.slabs;

    if (stats) stats->binMs = msSince(start);
    const auto tiles = std::chrono::steady_clock::now();
    Image image = renderTiles<NCh>(in, bins, pathScale, stats,
                            [&](int t, SheetBuffer<NCh>& sheet, TileAccumulator& acc,
                                const float* tileScale, TileCounters& cnt) {
        const int ox = (t % bins.grid.tilesX) * bins.grid.tileSize;
        const int oy = (t / bins.grid.tilesX) * bins.grid.tileSize;
        std::vector<std::uint32_t> active, keep;
        std::uint32_t next = bins.begin[t];
        const std::uint32_t end = bins.begin[t + 1];
        std::uint32_t step = key[bins.splats[next]];
        while (next < end || !active.empty()) {
            if (active.empty()) step = key[bins.splats[next]];  // skip empty sheet space
            while (next < end && key[bins.splats[next]] == step) active.push_back(bins.splats[next++]);
            const std::uint32_t slab = ftb ? step : slabs - 1 - step;
            const float z0 = zmin + float(slab) * thickness, z1 = z0 + thickness;
            keep.clear();
            for (std::uint32_t id : active) {
                if ((ftb ? last[id] : first[id]) != slab) keep.push_back(id);
                const PixelRect r = clipToTile(proj.rect[id], bins.grid, t);
                if (acc.rectOpaque(r.x0 - ox, r.y0 - oy, r.x1 - ox, r.y1 - oy)) {
                    ++cnt.culled;
                    continue;
                }
                const footprint::EllipticalFootprint& e = proj.ellipse(id);
                // Depths along this splat's rays, relative to its centre, in kernel units:
                // z = depthScale (t - (tx dx + ty dy)), t = (plane depth - centre) / cos.
                const float perRay = proj.perspective ? proj.depthPerRay[id] : 1.0f;
                const float t0 = (z0 - proj.depth[id]) * perRay, t1 = (z1 - proj.depth[id]) * perRay;
                float v[NCh];
                splatValues<NCh>(in, id, v);
                cnt.footprintPixels += sheet.splatSection(v, proj.sx[id], proj.sy[id], e, r, table,
                                                          in.poly, t0, t1);
            }
            active.swap(keep);
            if (sheet.dirty()) {
                sheet.flush(acc, model, thickness, tileScale);
                ++cnt.sheets;
            }
            ++step;
            if (acc.allOpaque()) {
                cnt.culled += end - next + active.size();
                break;
            }
        }
    });
    if (stats) stats->tilesMs = msSince(tiles);
    return image;
}

}  // namespace

Image renderImageAligned(const FrameInputs& in, const ProjectedSplats& proj, RenderStats* stats) {
    return SheetModel{in.settings.mode, in.settings.classification, nullptr}.channels() == 4
               ? renderSlabs<4>(in, proj, stats)
               : renderSlabs<1>(in, proj, stats);
}

}  // namespace splat
