// The same samples written by three libraries splat did not write — nibabel (NIfTI),
// python3-openvdb (a sparse VDB grid: the background's voxels inactive) and python3-zarr (an
// OME-Zarr image whose background chunks are not stored) — with the same geometry and a
// background value of 3, render the same image in every renderer and mode: max abs
// difference <= 1e-5 of the image's peak (tests/sparse/make_sparse_data.py).
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>

#include "image_diff.h"
#include "sparse_util.h"
#include "splat/bricks.h"
#include "splat/render.h"
#include "splat/sparse_files.h"
#include "splat/volume_io.h"

using namespace splat;
using namespace splat::test;

TEST_CASE("sparse files: NIfTI, OpenVDB and OME-Zarr of the same data render the same image",
          "[vdb][zarr][images]") {
    SPARSE_DATA_OR_SKIP(data);
    const Volume nii = loadVolume((data / "same.nii.gz").string());
    const Volume zarr = loadVolume((data / "same.zarr").string());
    std::vector<std::pair<const char*, const Volume*>> others = {{"zarr", &zarr}};
    Volume vdb;
    if (openVdbAvailable()) {
        vdb = loadVolume((data / "same.vdb").string());
        others.push_back({"vdb", &vdb});
    } else {
        WARN("splat is built without OpenVDB (SPLAT_OPENVDB): the VDB image is skipped");
    }
    REQUIRE(nii.background == 3.0f);
    for (RendererKind r : {RendererKind::Axis, RendererKind::Sheet, RendererKind::Reference})
        for (RenderMode m : {RenderMode::Dvr, RenderMode::Mip, RenderMode::Xray, RenderMode::Iso})
            for (Classification cl : {Classification::Pre, Classification::Post}) {
                if (cl == Classification::Post && m != RenderMode::Dvr) continue;
                RenderSettings s;
                s.renderer = r;
                s.mode = m;
                s.classification = cl;
                s.camera.width = s.camera.height = 36;
                s.camera.azimuthDeg = 25;
                s.camera.elevationDeg = 17;
                s.isoLevel = 0.4;
                s.isoNormalized = true;
                s.threads = 2;
                const Image ref = render(nii, s);
                const double top = peakOf(ref);
                REQUIRE(top > 0);
                for (const auto& [name, v] : others) {
                    INFO(name << " renderer " << int(r) << " mode " << int(m) << " classification "
                              << int(cl));
                    CHECK(maxDiff(render(*v, s), ref) <= 1e-5 * top);
                }
            }
}

TEST_CASE("sparse files: bricks read alone from VDB and OME-Zarr render the NIfTI's bricked image",
          "[vdb][zarr][images][bricks]") {
    SPARSE_DATA_OR_SKIP(data);
    std::vector<std::string> files = {"same.nii.gz", "same.zarr"};
    if (openVdbAvailable()) files.push_back("same.vdb");
    RenderSettings s;
    s.renderer = RendererKind::Axis;
    s.mode = RenderMode::Dvr;
    s.camera.width = s.camera.height = 32;
    s.camera.azimuthDeg = 35;
    s.camera.elevationDeg = 20;
    s.threads = 2;
    std::vector<Image> images;
    for (const std::string& name : files) {
        const std::string spec = (data / name).string();
        const Volume g = volumeGeometry(spec, LoadOptions{}, nullptr);
        LocalBrickGroup group;
        BrickStats stats;
        images.push_back(renderBricked(
            g,
            [&](const Brick& b) {
                Volume v = loadVolumeBrick(spec, LoadOptions{}, b.loadLo, b.loadHi);
                v.background = g.background;
                return v;
            },
            s, 3, group, &stats));
        CHECK(stats.bricks == 3);
    }
    const double top = peakOf(images[0]);
    REQUIRE(top > 0);
    for (std::size_t n = 1; n < images.size(); ++n) {
        INFO(files[n]);
        CHECK(maxDiff(images[n], images[0]) <= 1e-5 * top);
    }
}
