#pragma once
// Factorised sheets: the axis-aligned splatter's frame by the shear-warp factorisation
// (P. Lacroute and M. Levoy, "Fast volume rendering using a shear-warp factorization of the
// viewing transformation", SIGGRAPH 1994) with Westover's whole-kernel footprints.
//
// In an orthographic view a voxel (u, v) of sheet q (the slice q along the major axis m of
// S^-1 view; u, v the other two axes) lands on the screen at c + J (u + T_u q, v + T_v q),
// J the 2x2 screen map of the sheet's axes and T = J^-1 A_m the sheet's shear. On an
// intermediate image aligned with the sheets, samples (U0 + a / n, V0 + b / n) for n samples
// per voxel, every voxel of sheet q therefore has the same sub-sample phase, and the sheet's
// optical depth and emission there are the sheet's voxels convolved with ONE footprint stamp
// (fp(r^2) of footprint_table.h at the sheet's phase), added without a polynomial per pixel
// and without binning. The sheets are composited on the intermediate image (front to back
// with early termination on column blocks of bands of rows, or back to front) and the
// composited image is warped to the screen once, by the Catmull-Rom spline through its
// samples.
//
// The intermediate image samples the very function the per-splat splatter samples at pixel
// centres (the same sheets, the same compositing), at other points; the only added error is
// the warp's interpolation, of order h^3 in the sample spacing h = 1 / n voxels where the
// image is smooth and largest at opaque silhouettes. The image's detail is the footprint's,
// so n is per voxel, not per pixel: on ch2 (the benchmark's MRI head) n = 2 keeps the
// per-splat frame's error against the reference at 256^2 and 512^2 alike, n = 1 is a faster,
// coarser setting; sharper edges need more (tests/test_factorised_sheets.cpp): the phantoms'
// opaque edges need n = 4..8, which is why the default frame is the per-splat one
// (docs/performance.md "Factorised sheets as the default design: measured, not kept").
// Orthographic views only: perspective rays are not parallel, so a sheet's voxels do not
// share one phase.
#include <cstdint>
#include <vector>

#include "model/scene_impl.h"

namespace splat {

/// True when `settings` ask for factorised sheets (Quality::factorisedSheets) and the frame
/// can take them: axis-aligned, orthographic, pre-classified dvr, no labels, clipping, EWA
/// low-pass or merged level. `lowPass`: the frame's EWA sigma (0: off).
bool factorisedSheetsApply(const Camera& camera, const RenderSettings& settings, bool labels,
                           bool clipped, double lowPass, int level);

/// The frame (premultiplied colour and opacity, no background) of the scene's splats in
/// `camera` by factorised sheets; `er`, `eg`, `eb`: this view's shaded emission, or null for
/// the list's own. With `edges`, also one flag per pixel (row-major): 1 where the pixel's
/// estimated warp error exceeds Quality::warpTolerance (tested until one pixel per row of
/// each screen tile of Quality::tileSize is flagged), whose tiles the caller renders per
/// splat instead.
Image renderFactorisedSheets(const Scene::Impl& scene, const Camera& camera,
                             const RenderSettings& settings, const float* er, const float* eg,
                             const float* eb, RenderStats& stats,
                             std::vector<std::uint8_t>* edges = nullptr);

}  // namespace splat
