#pragma once
// OME-Zarr images (OME-NGFF 0.4 `multiscales` over Zarr v2 arrays, or one bare Zarr array)
// as the model's volumes (private, not installed): the level, time point and channel a
// LoadOptions selects, with the level's scale and translation as spacing and origin (x the
// fastest axis). Whole volumes and bricks read only the chunks their box intersects.
#include <filesystem>
#include <glm/glm.hpp>

#include "splat/volume.h"
#include "splat/volume_io.h"

namespace splat::detail {

/// True for a folder holding a Zarr array (`.zarray`) or group (`.zattrs`, `.zgroup`), or
/// named `*.zarr`.
bool isZarrFolder(const std::filesystem::path& dir);

/// The whole selected 3D volume (loadVolume's Zarr loader). The background value is the
/// array's fill_value when one of the volume's chunks is not stored; otherwise
/// backgroundSource is left at its default, for loadVolume's rule.
Volume loadZarr(const std::filesystem::path& dir, const LoadOptions& options);

/// The geometry of that volume (no samples); with `background`, b by loadZarr's choice and
/// loadVolume's rule (the outer faces, read alone), so it equals the whole volume's.
Volume zarrGeometry(const std::filesystem::path& dir, const LoadOptions& options, bool background);

/// The samples [lo, hi) of that volume, origin at sample lo (the crop of loadZarr's volume).
Volume loadZarrBrick(const std::filesystem::path& dir, const LoadOptions& options,
                     const glm::ivec3& lo, const glm::ivec3& hi);

}  // namespace splat::detail
