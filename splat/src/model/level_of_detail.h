#pragma once
// Level of detail for sub-pixel voxels (Laur & Hanrahan, "Hierarchical splatting",
// SIGGRAPH 1991): the next level of a scene merges each 2x2x2 cell of voxels into one splat
// on a grid of twice the spacing, splatted with the same kernel (in voxel units), so twice
// as wide in world units. Values are averaged over the eight voxels of a cell, the voxels
// that are not splats counting as zero: the classified extinction and premultiplied
// emission (pre-classified dvr), the density and its gradient (every mode). Since the kernel
// integrates to one voxel volume, the average keeps each cell's integral of rho, e and f (so
// an X-ray image keeps its mass) and a constant region stays that constant.
#include <glm/glm.hpp>

#include "splat/camera.h"
#include "splat/classify.h"
#include "splat/settings.h"
#include "splat/volume.h"

namespace splat {

/// The grid of the next level: dims ceil(n / 2), twice the spacing, origin at the centre of
/// cell (0, 0, 0) (fine index 0.5 on every axis). Holds no samples.
Volume coarserGrid(const Volume& fine);

/// The next level's splat list of `fine` (a list in (k, j, i) order on a grid of `fineDims`),
/// in (k, j, i) order on coarserGrid's grid: one splat per cell holding at least one splat.
/// Averages every per-splat value (values by palette become arrays: averages are no longer a
/// few distinct values); unit normals become the extinction-weighted mean normal,
/// normalised (zero where the members' normals cancel); a label becomes the most frequent
/// label of the cell's splats (the lowest on a tie).
SplatList coarserSplats(const SplatList& fine, const glm::ivec3& fineDims);

/// The size of a voxel of `volume` on the screen, in pixels: its largest spacing over the
/// camera's pixel size (perspective: at the nearest depth of the volume's bounding sphere;
/// infinite when the eye is inside it).
double voxelPixels(const Camera& camera, const Volume& volume);

/// The variance of the pyramid's low-pass at level L, per axis in level-0 voxels^2: a merged
/// splat holds the mean of its cell's 2^L voxels along each axis, which lie at (2a + 1 - 2^L)
/// / 2, a = 0 .. 2^L - 1, from the cell centre: a discrete box of variance (4^L - 1) / 12
/// (0.25 at level 1).
double lodBoxVariance(int level);

/// `--lod auto` (LevelOfDetail::Kind::Auto): how a merged level L is splatted so that it reconstructs
/// the level-0 field low-passed as the pixel-filtered reference sees it. Derivation
/// (docs/speed-vs-accuracy.md "Level of detail"): level 0 with EWA renders sum_v f_v (h0 * g)(x - x_v) ~ f * h0 * g, h0
/// the kernel (per-axis variance k^2 = Kernel::variance(), voxels^2) and g the screen
/// low-pass (sigma^2, pixels^2), which is what the filtered reference sees of the field
/// f * h0. The merged level holds the cell means m_c = (f * D_L)(x_c), D_L the discrete box of
/// variance B_L = lodBoxVariance(L), each splat integrating to its cell's volume, so it
/// renders sum_c m_c (hL * gL)(x - x_c) ~ f * D_L * hL * gL. Variances add under
/// convolution, so the merged footprint must carry k^2 + sigma^2 - B_L, not the doubled kernel
/// plus the box (4^L k^2 + B_L + sigma^2, what numeric --lod renders: silhouettes grow): the
/// kernel narrowed to variance k^2 - B_L (0.078 voxels^2 at level 1 for the default Gaussian)
/// and the pixel filter sigma as EWA's low-pass. Where k^2 - B_L < kLodMinKernel k^2 (level 2
/// on: B_2 = 1.25), the kernel keeps kLodMinKernel k^2 and the rest is taken from the screen
/// low-pass, sigma_L^2 = sigma^2 - (B_L - (1 - kLodMinKernel) k^2) v0^2 (v0 the level-0 voxel
/// in pixels; exact for isotropic spacing in orthographic views). lodAutoLevel keeps that
/// positive. Energy: every footprint keeps its integral (FootprintFilter::kernelScale).
struct LodFootprint {
    double kernelScale;  ///< the kernel as a fraction of the level's voxel
    double lowPass;      ///< screen low-pass sigma, pixels
};
LodFootprint lodFootprint(double kernelVariance, int level, double sigma, double voxelPixels0);
constexpr double kLodMinKernel = 0.1;

/// `--lod auto`: the modes where merged levels were measured free in accuracy against the
/// pixel-filtered reference (docs/speed-vs-accuracy.md "Level of detail").
bool lodAutoApplies(RenderMode mode);

/// `--lod auto`: the coarsest level L (at most maxLevel) whose merged footprints (lodFootprint:
/// variance (k^2 - B_L) v0^2 + sigma^2 pixels^2, v0 = `voxelPixels` of a level-0 voxel) are
/// still wide enough on their own grid of 2^L v0 pixels to sum to a constant:
///     (k^2 - B_L) v0^2 + sigma^2 >= kLodAutoSmooth (2^L v0)^2.
/// That also keeps the pyramid's box within the pixel filter (B_L v0^2 < sigma^2): the detail
/// a merged level drops is detail the filtered reference removes anyway. For the default
/// Gaussian and sigma 0.5: level 1 at v0 <= 0.472 pixels, level 2 at v0 <= 0.209; 0 at more.
int lodAutoLevel(double voxelPixels, double sigma, double kernelVariance, int maxLevel);

/// The least footprint variance, in its level's voxels^2, that lodAutoLevel accepts: a
/// Gaussian of this variance summed over a unit grid ripples by 2 exp(-2 pi^2 0.3) = 0.54% per
/// axis (0.31% for the default Gaussian kernel on its own grid).
constexpr double kLodAutoSmooth = 0.3;

}  // namespace splat
