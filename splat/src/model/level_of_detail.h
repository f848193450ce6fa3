#pragma once
// Level of detail for sub-pixel voxels (issue 11; Laur & Hanrahan, "Hierarchical splatting",
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

}  // namespace splat
