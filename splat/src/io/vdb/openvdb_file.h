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

/// That volume's geometry and background (no samples), from the grid's metadata when the
/// file records its bounding box, else from its tree.
Volume vdbGeometry(const std::filesystem::path& p, const LoadOptions& options);

/// The samples [lo, hi) of that volume, origin at sample lo; only the part of the tree that
/// intersects the box is read from the file.
Volume loadVdbBrick(const std::filesystem::path& p, const LoadOptions& options,
                    const glm::ivec3& lo, const glm::ivec3& hi);

}  // namespace splat::detail
