#pragma once
// Loading and saving volumes. The format is chosen by extension or, for folders, by
// content. See docs/design.md "Command line" for the VOLUME syntax.
#include <optional>
#include <string>
#include <vector>

#include "splat/volume.h"

namespace splat {

/// What to do with NaN or Inf samples found while loading.
enum class NonFinitePolicy {
    Error,  ///< refuse the volume: "FILE: N NaN/Inf samples (first at i,j,k)" (default)
    Zero,   ///< replace them by 0 and record the count in Volume::note
};

/// Options for headerless `.raw` files. Unset fields are taken from a name of the form
/// `name_XxYxZ_type.raw` (e.g. `skull_256x256x256_uint8.raw`); spacing defaults to 1.
struct RawOptions {
    std::optional<glm::ivec3> dims;
    std::string type;  ///< uint8, int8, uint16, int16, uint32, int32, float32, float64
    std::optional<glm::dvec3> spacing;
    bool bigEndian = false;
    std::size_t headerBytes = 0;  ///< bytes to skip at the start of the file (or of the
                                  ///< decompressed stream of a .raw.gz)
};

struct LoadOptions {
    RawOptions raw;
    NonFinitePolicy nonFinite = NonFinitePolicy::Error;
    /// NRRD "data file" and MetaImage ElementDataFile may name files outside the header's
    /// folder (absolute paths, `..`). Off by default: a downloaded header could otherwise
    /// read any file on the machine into the image (CLI: --allow-outside-data).
    bool allowOutsideDataFiles = false;
    /// DICOM: the SeriesInstanceUID to load when a folder holds several series (CLI:
    /// --series UID). Empty: the folder must hold exactly one series.
    std::string dicomSeries;
    /// OpenVDB: the grid to load. Empty: `density`, else the first float or double grid.
    std::string grid;
    /// OME-Zarr: the resolution level (0, the finest, when unset).
    std::optional<int> level;
    /// OME-Zarr: the channel of a 4D or 5D image (0 when unset, with a note).
    std::optional<int> channel;
    /// Time series (4D NIfTI, NRRD with a time axis, a folder of 3D files, a series of
    /// Siemens mosaics, OME-Zarr `t`): the time step to load, from 0 (CLI: --time T). Unset:
    /// the first, with a note when there are more. A step past the last throws OptionError;
    /// a file without a time axis has the one step 0.
    std::optional<int> time;
};

/// Loads `spec`: a file (.nii, .nii.gz, .hdr/.img ANALYZE 7.5 or NIfTI pair, NIfTI-2,
/// .nrrd, .nhdr, .mhd, .mha, .raw, .raw.gz, .dcm, .vdb with OpenVDB), a folder of 2D slices
/// (PNG/TIFF, natural sort order) or of DICOM files, an OME-Zarr image (a folder, see
/// splat/sparse_files.h), or `synthetic:NAME[:N]`.
/// Throws splat::Error with one line naming the file and the problem. Anything accepted
/// but worth a word (an assumption, an ignored field) is in Volume::note.
Volume loadVolume(const std::string& spec, const LoadOptions& options = {});

/// One DICOM series of a folder (SeriesInstanceUID, with what identifies it to a user).
struct DicomSeriesInfo {
    std::string uid;
    std::string description;  ///< SeriesDescription (may be empty)
    std::string modality;
    int seriesNumber = -1;  ///< -1 when absent
    std::size_t files = 0;
    int rows = 0, columns = 0;
};
/// The DICOM series in `folder` (empty when it holds no DICOM files), sorted by series
/// number then UID. Throws splat::Error when the folder cannot be listed.
std::vector<DicomSeriesInfo> listDicomSeries(const std::string& folder);

/// Writers (float32 samples, spacing and origin kept), atomic: temporary file then rename.
void saveNifti(const std::string& path, const Volume& v);      ///< .nii or .nii.gz
void saveNrrd(const std::string& path, const Volume& v);       ///< .nrrd, raw encoding
void saveMetaImage(const std::string& path, const Volume& v);  ///< .mha (single file) or .mhd+.raw

}  // namespace splat
