#pragma once
// Loading and saving volumes. The format is chosen by extension or, for folders, by
// content. See splat/DESIGN.md ("Command line") for the VOLUME syntax.
#include <optional>
#include <string>

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
    std::size_t headerBytes = 0;  ///< bytes to skip at the start of the file
};

struct LoadOptions {
    RawOptions raw;
    NonFinitePolicy nonFinite = NonFinitePolicy::Error;
};

/// Loads `spec`: a file (.nii, .nii.gz, .nrrd, .nhdr, .mhd, .mha, .raw), a folder of 2D
/// slices (PNG/TIFF, natural sort order) or of DICOM files, or `synthetic:NAME[:N]`.
/// Throws splat::Error with one line naming the file and the problem.
Volume loadVolume(const std::string& spec, const LoadOptions& options = {});

/// Writers (float32 samples, spacing and origin kept), atomic: temporary file then rename.
void saveNifti(const std::string& path, const Volume& v);      ///< .nii or .nii.gz
void saveNrrd(const std::string& path, const Volume& v);       ///< .nrrd, raw encoding
void saveMetaImage(const std::string& path, const Volume& v);  ///< .mha (single file) or .mhd+.raw

}  // namespace splat
