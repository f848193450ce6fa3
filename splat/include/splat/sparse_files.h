#pragma once
// What a sparse or multiscale file holds, for `splat info` and for programs that choose a
// grid, level, time point or channel before loading (LoadOptions::grid, level, time,
// channel). loadVolume reads both kinds: an OpenVDB file (`.vdb`, when splat is built with
// OpenVDB) and an OME-Zarr image (a folder: OME-NGFF 0.4 multiscales over Zarr v2 arrays).
#include <cstdint>
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "splat/settings.h"

namespace splat {

/// True when this splat was built with OpenVDB (CMake option SPLAT_OPENVDB).
bool openVdbAvailable();

/// One grid of an OpenVDB file.
struct VdbGridInfo {
    std::string name;
    std::string valueType;  ///< "float", "double", "vec3s", "int32", "bool", ...
    std::uint64_t activeVoxels = 0;
    glm::ivec3 bboxMin{0}, bboxMax{-1};  ///< active voxels' index bounding box, inclusive
    double background = 0.0;             ///< float and double grids (0 for others)
    glm::dvec3 voxelSize{1.0};           ///< the transform's scale (an affine's column norms)
    bool axisAligned = true;             ///< scale and translation only: splat can load it
};

/// The grids of the OpenVDB file `path`, in file order; throws splat::Error for a file that
/// is not a readable OpenVDB file or when splat is built without OpenVDB.
std::vector<VdbGridInfo> listVdbGrids(const std::string& path);

/// One resolution level of an OME-Zarr image.
struct ZarrLevelInfo {
    std::string path;  ///< the array's folder inside the image
    glm::ivec3 dims{0};
    glm::dvec3 spacing{1.0}, origin{0.0};
    std::vector<std::int64_t> chunks;  ///< the array's chunk shape, in its axis order
    std::string dtype, compressor;
};

/// An OME-Zarr image: its axes (e.g. "tczyx"), time points, channels and levels (level 0
/// the finest).
struct ZarrImageInfo {
    std::string axes;
    int times = 1, channels = 1;
    std::vector<ZarrLevelInfo> levels;
};

/// True for a folder that loadVolume reads as an OME-Zarr image or bare Zarr array (one
/// holding `.zarray`, `.zattrs` or `.zgroup`, or named `*.zarr`).
bool isZarrFolder(const std::string& path);

/// Reads an OME-Zarr image's metadata (no chunks); throws splat::Error with one line for a
/// folder that is not one or whose levels disagree.
ZarrImageInfo describeZarr(const std::string& folder);

/// The level of `image` that splat's level-of-detail rule picks for the view of `settings`
/// (docs/input-files.md "Choosing a level"): the file's pyramid stands for the one the
/// splatters would build. With `--lod PIXELS` the first level whose voxel covers at least
/// PIXELS pixels (else the coarsest); with `--lod auto` lodAutoLevel's level in the modes it
/// applies to; level 0 with level of detail off, with `--lod brick` and for the reference
/// ray caster. The camera is the one the renderer places for level 0.
int zarrLevelForView(const ZarrImageInfo& image, const RenderSettings& settings);

}  // namespace splat
