#pragma once
// OpenVDB files (.vdb) as the model's volumes (private, not installed). One float or double
// grid is chosen by name (LoadOptions::grid; default `density`, else the first float or
// double grid). Its transform must be a scale per axis and a translation: voxel ijk sits at
// world t + S ijk, the model's x = origin + S p with p = ijk - the active bounding box's
// minimum. Inactive voxels and tiles hold the grid's background value, which becomes the
// model's background value b; active tiles fill their boxes. Without OpenVDB in the build
// (SPLAT_OPENVDB) every function throws "FILE: this splat was built without OpenVDB".
#include <filesystem>
#include <glm/glm.hpp>

#include "splat/volume.h"
#include "splat/volume_io.h"

namespace splat::detail {

/// True for a `.vdb` file name.
bool isVdbFile(const std::filesystem::path& p);

/// The chosen grid as a volume over its active voxels' bounding box.
Volume loadVdb(const std::filesystem::path& p, const LoadOptions& options);

/// That volume's geometry and background (no samples). The grid's tree is read whole once
/// and kept for the bricks of the same file and grid (memory follows its active voxels).
Volume vdbGeometry(const std::filesystem::path& p, const LoadOptions& options);

/// The samples [lo, hi) of that volume, origin at sample lo, filled from the kept tree: b,
/// then the active voxels and tiles inside the box (only the leaves that meet it are read).
Volume loadVdbBrick(const std::filesystem::path& p, const LoadOptions& options,
                    const glm::ivec3& lo, const glm::ivec3& hi);

/// The smallest and largest of that volume's samples, from the tree: its active values, and
/// b unless every voxel of the box is active.
glm::dvec2 vdbValueRange(const std::filesystem::path& p, const LoadOptions& options);

/// Whether the samples [lo, hi) of that volume all equal b: no active voxel or tile of
/// another value meets the box (from the tree, no samples filled).
bool vdbBoxHoldsOnlyBackground(const std::filesystem::path& p, const LoadOptions& options,
                               const glm::ivec3& lo, const glm::ivec3& hi);

}  // namespace splat::detail
