// The image-aligned sheet-buffer splatter (Mueller & Crawfis 1998, "Eliminating popping
// artifacts in sheet buffer-based splatting"): sheets are slabs of thickness T parallel to
// the image plane; every kernel adds to each slab it crosses the section of its footprint
// between the slab's two depths, C(r, z1) - C(r, z0) from the cumulative slab table. The
// sheets never change orientation, so there is no popping; the cost grows as T shrinks.
//
// Splats are visited through depth buckets: sorted by the first slab they touch (last
// slab for back-to-front). Each tile sweeps its slabs in visiting order with a ring of
// sheet buffers as deep as a kernel is thick: when the sweep reaches a splat it adds the
// splat's sections to every slab it crosses at once (sharing r^2, the footprint and the
// section boundaries between them), and the sheet at the sweep position, complete now,
// is composited. Empty sheet space between splats is skipped.
#include "image_aligned_splatter.h"

#include <chrono>
#include <cmath>

#include "frame/tile_binning.h"

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
    // A kernel spans at most this many slabs; a tile keeps that many sheets in a ring, so a
    // splat is cut into all its slab sections at once when the sweep reaches it.
    const std::uint32_t ring = std::uint32_t(std::ceil(2.0f * ext / thickness)) + 2;
    return renderTiles<NCh>(
        in, bins, pathScale, stats,
        [&](int t, TileAccumulator& acc, const float* tileScale, TileCounters& cnt) {
            const int ox = (t % bins.grid.tilesX) * bins.grid.tileSize;
            const int oy = (t / bins.grid.tilesX) * bins.grid.tileSize;
            std::vector<SheetBuffer<NCh>> sheets;
            sheets.reserve(ring);
            for (std::uint32_t k = 0; k < ring; ++k)
                sheets.emplace_back(ox, oy, acc.width(), acc.height());
            std::vector<SheetBuffer<NCh>*> target(ring);
            std::vector<float> tb(ring + 1);
            std::uint32_t next = bins.begin[t];
            const std::uint32_t end = bins.begin[t + 1];
            // Sweep position (slab index in visiting order) and the last position that has
            // sections pending in the ring.
            std::uint32_t step = key[bins.splats[next]], pendingEnd = step;
            bool pending = false;
            while (next < end || pending) {
                if (!pending)
                    step = std::max(step, key[bins.splats[next]]);  // skip empty sheet space
                for (; next < end && key[bins.splats[next]] == step; ++next) {
                    const std::uint32_t id = bins.splats[next];
                    const PixelRect r = clipToTile(proj.rect[id], bins.grid, t);
                    if (acc.rectOpaque(r.x0 - ox, r.y0 - oy, r.x1 - ox, r.y1 - oy)) {
                        ++cnt.culled;
                        continue;
                    }
                    // Slabs first..last in depth order; in the sweep they are step..step+n-1.
                    const int n = int(last[id] - first[id]) + 1;
                    const footprint::EllipticalFootprint& e = proj.ellipse(id);
                    // Depths along this splat's rays relative to its centre: t = (plane depth -
                    // centre) / cos; the slab sections use z = depthScale (t - (tx dx + ty dy)).
                    const float perRay = proj.perspective ? proj.depthPerRay[id] : 1.0f;
                    for (int b = 0; b <= n; ++b) {
                        const std::uint32_t plane =
                            ftb ? first[id] + std::uint32_t(b) : last[id] + 1 - std::uint32_t(b);
                        tb[b] = (zmin + float(plane) * thickness - proj.depth[id]) * perRay;
                    }
                    for (int j = 0; j < n; ++j)
                        target[j] = &sheets[(step + std::uint32_t(j)) % ring];
                    float v[NCh];
                    splatValues<NCh>(in, id, v);
                    cnt.footprintPixels +=
                        splatSections(target.data(), n, v, proj.sx[id], proj.sy[id], e, r, table,
                                      in.poly, tb.data());
                    pendingEnd = std::max(pendingEnd, step + std::uint32_t(n) - 1);
                    pending = true;
                }
                SheetBuffer<NCh>& sheet = sheets[step % ring];
                if (sheet.dirty()) {
                    sheet.flush(acc, model, thickness, tileScale);
                    ++cnt.sheets;
                }
                pending = step < pendingEnd;
                ++step;
                if (acc.allOpaque()) {
                    cnt.culled += end - next;
                    break;
                }
            }
        });
}

}  // namespace

Image renderImageAligned(const FrameInputs& in, const ProjectedSplats& proj, RenderStats* stats) {
    return withChannels(in.settings, [&]<int NCh>() { return renderSlabs<NCh>(in, proj, stats); });
}

}  // namespace splat
