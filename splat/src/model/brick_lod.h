#pragma once
// Error-driven level of detail per brick and view (Laur & Hanrahan, "Hierarchical
// splatting", SIGGRAPH 1991, with the merged levels filtered as in level_of_detail.h).
//
// `--lod brick` (LevelOfDetail::Kind::Brick) cuts the level-0 grid into bricks of kLodBrick^3 voxels,
// aligned with the pyramid (a level-L cell, L <= log2 kLodBrick, lies inside one brick), and
// splats every brick from its own level, each level with its footprint (lodFootprint). In
// X-ray the image is the sum over splats of their footprints, so a frame mixing levels is the
// sum of one frame per level over that level's bricks (exact; every brick's mass is kept, and
// voxels equal to the background b are no splats at any level: merged densities are means of
// d - b). `--lod auto` stays the per-view rule (one level per view, renderer.cpp
// levelOfDetail): per brick, the seams below keep bricks with field on their faces at the
// finest level of their neighbours, so on volumes of contiguous tissue the rule is the
// full-resolution splatter (its accuracy, nearly its time) where the per-view rule is 6x
// faster at 1.2-7x the error (docs/speed-vs-accuracy.md "Level of detail").
//
// Derivation of the choice. A brick B splatted from level L renders (level_of_detail.h)
//     I_L = P[ f_L ],   f_L = sum_c m_c (h_L * g_L)(x - x_c),   m_c = (f * D_L)(x_c),
// P the projection along the rays; the filtered reference sees P[f * h0 * g]. lodFootprint
// makes the total variance of D_L * h_L * g_L equal that of h0 * g, so the two agree on every
// component of f that the level's grid represents (f locally linear over a cell: the means
// are exact and the sum of merged footprints reproduces a linear field), which leaves
//     e_L = P[ (f - R_L f) * h0 * g ],   R_L f = the field interpolated from the level's means,
// the detail the level drops (what a level-L grid cannot hold: edges and texture finer than
// 2^L voxels), blurred by the kernel and the pixel filter and integrated along the ray.
//   1. Geometry (lodAutoLevel): the merged footprints must still sum to a constant on their
//      grid, which needs the level's voxel small on the screen: the coarsest level allowed
//      by the level-0 voxel's size v0 at the brick. Perspective: v0 at the brick's nearest
//      depth, so near bricks stay fine and far bricks go coarse; orthographic: one v0.
//   2. Content: the detail a level drops, measured once with the pyramid. For each level l,
//      the level-(l-1) values minus the trilinear interpolation of the level-l means at
//      their positions (a linear field gives 0), squared and averaged over the brick's
//      level-(l-1) voxels; the detail of level L is the root of the sum over l = 1..L (the
//      levels' details are nearly orthogonal, like wavelet bands). This is the detail before
//      the kernel and pixel low-pass (which remove part of it: an upper bound, view-free),
//      and in the field's units. A brick takes the coarsest level allowed by the geometry
//      whose detail is at most kLodDetail times the field's RMS (the RMS of d - b over the
//      level-0 splats): constant or smooth bricks (homogeneous tissue, a smooth ramp) take
//      the geometric level, bricks with edges and texture stay finer. kLodDetail = 0.05 is
//      set, not calibrated over a range of volumes: on the tests' volumes (smooth blobs beside
//      noise) the frame's error against the pixel-filtered reference stays within 5% of the
//      full-resolution splatter's (tests/test_brick_lod.cpp).
//   3. Seams: where a brick of level L meets one of a finer level, the two lattices end at
//      the shared face and the rays that cross it integrate a partial cell of each: a
//      sawtooth along the face's projection whose amplitude is the field on the face times
//      the cell size (measured: one constant 16^3 brick at level 1 inside level-0 constant
//      surroundings, 1/3 pixel per voxel, differs from the same brick at level 0 by up to 1.9%
//      of its X-ray, RMSE 3x the full splatter's against the filtered reference). The volume's
//      own faces do the same at a uniform level (the per-view rule's error is mostly there).
//      So a brick keeps a level coarser than a face-neighbour's only where the field on that
//      face (RMS over its voxel layer, either side) is within kLodDetail of the field's RMS,
//      relaxed until no such face is left: levels change across empty or quiet faces only.
// The content measure never takes a brick coarser than the geometric rule: beyond it the
// merged footprints no longer sum to a constant (ripple even in a constant brick), and a wider
// footprint would blur what the filtered reference keeps. Splitting a level's footprint
// variance differently between the 3D kernel and the screen low-pass does not help the seams
// in orthographic X-ray (the projection of a Gaussian is the same Gaussian either way:
// measured, the seam above changed by 1e-5 relative).
#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

#include "splat/camera.h"
#include "splat/settings.h"

namespace splat {

struct SplatList;

/// Level-0 voxels per brick edge (a power of two: the levels up to log2 of it nest in a brick).
constexpr int kLodBrick = 16;
/// The coarsest level a brick can take (its cells fill the brick).
constexpr int kLodBrickMaxLevel = 4;
/// The content rule's tolerance: the detail a level drops, and the field on a face where two
/// levels meet, as a fraction of the field's RMS.
constexpr double kLodDetail = 0.05;

/// The pyramid's per-brick detail (view-free, made once per scene).
struct BrickDetail {
    glm::ivec3 bricks{0};  ///< brick grid: ceil(level-0 dims / kLodBrick)
    int levels = 0;        ///< levels measured: 1 .. levels
    /// detail[(L - 1) * count() + b]: RMS detail, field units, that level L drops in brick b.
    std::vector<float> detail;
    double fieldRms = 0;  ///< RMS of d - b over the level-0 splats
    std::vector<std::uint8_t> occupied;  ///< per brick: 1 where it holds level-0 splats
    /// face[6 b + f]: RMS of d - b over brick b's layer of voxels on face f (-x, +x, -y, +y,
    /// -z, +z), field units: what a seam between two levels there cuts through.
    std::vector<float> face;
    std::size_t count() const { return std::size_t(bricks.x) * bricks.y * bricks.z; }
    std::size_t brick(int i, int j, int k) const {
        return (std::size_t(k / kLodBrick) * bricks.y + std::size_t(j / kLodBrick)) * bricks.x +
               std::size_t(i / kLodBrick);
    }
};

/// The detail of every brick for the pyramid `levels` (level 0 first; level l's list on the
/// grid `dims[l]`), up to kLodBrickMaxLevel.
BrickDetail brickDetail(const std::vector<const SplatList*>& levels,
                        const std::vector<glm::ivec3>& dims);

/// The level each brick takes in this view: the coarsest allowed by lodAutoLevel at the
/// level-0 voxel's size at the brick (perspective: its nearest depth; 0 where the eye is
/// within the brick's depth) and, below `maxLevel` and the geometric level, whose detail is
/// within kLodDetail (detail null: the geometric rule alone). `origin`, `spacing`: the
/// level-0 grid.
std::vector<std::uint8_t> brickLevels(const Camera& camera, const glm::dvec3& origin,
                                      const glm::dvec3& spacing, const glm::ivec3& dims,
                                      double sigma, double kernelVariance, int maxLevel,
                                      const BrickDetail* detail);

/// The splats of `level` (a list on level L's grid, L <= kLodBrickMaxLevel) whose brick took
/// level L in `levels` (bricks of the level-0 grid `bricks`), in the list's order.
SplatList splatsOfBricks(const SplatList& level, int L, const std::vector<std::uint8_t>& levels,
                         const glm::ivec3& bricks);

}  // namespace splat
