#pragma once
// Where a volume file keeps its samples and how they become the model's volume: what a
// loader learns from the header (private, not installed). With it a brick is read alone
// (docs/parallel.md): the rows of the brick's box in the file's own
// index order are read by byte ranges (pread) from a raw-stored file, or picked out of the
// decompressed stream of a compressed one, decoded and scaled exactly as the whole-file
// loader does, and moved to the model's axes by the same signed permutation
// (applyOrientation), so a brick equals the crop of the whole loaded volume bit for bit.
#include <cstdint>
#include <filesystem>
#include <glm/glm.hpp>
#include <limits>
#include <string>
#include <vector>

#include "splat/volume.h"
#include "splat/volume_io.h"
#include "volume_detail.h"

namespace splat::detail {

struct SampleLayout {
    enum class Codec { None, Gzip, Bzip2 };  ///< Gzip: gzip or zlib, auto-detected
    std::filesystem::path file;              ///< the file holding the samples
    std::string fileName;                    ///< its name in messages
    Codec codec = Codec::None;
    /// None: byte of the first sample in `file`. Compressed: first byte of the stream.
    std::uint64_t start = 0;
    /// Compressed: bytes of the stream from `start` (MetaImage CompressedDataSize), or all.
    std::uint64_t streamBytes = std::numeric_limits<std::uint64_t>::max();
    /// Compressed: bytes of the decompressed stream before the first sample (NRRD byte skip).
    std::uint64_t skip = 0;
    /// The data must end with the samples (NRRD, MetaImage, raw): more is an error, as in the
    /// whole-file loader.
    bool exact = false;
    glm::ivec3 dims{1};  ///< in the file's index order
    SampleType type = SampleType::U8;
    bool bigEndian = false;
    /// value = slope * stored + inter, applied as the NIfTI loader does (slope 0: none).
    double slope = 0, inter = 0;
    /// The file's index-to-world affine, for applyOrientation (`orientation` names it).
    glm::dmat3 M{1.0};
    glm::dvec3 t{0.0};
    std::string orientation = "spacing";
    std::string name;    ///< the volume's name (makeVolume's `what`)
    std::string source;  ///< Volume::source
    std::vector<std::string> notes;

    std::uint64_t sampleBytes() const;
    /// True when stored values are rescaled (NIfTI scl_slope/scl_inter).
    bool scaled() const;
};

/// The layout of `spec` when its samples can be read by range or stream (uncompressed or
/// compressed binary NIfTI, NRRD, MetaImage, .raw); false for anything else (DICOM,
/// slices, NRRD text/hex, ANALYZE pairs, synthetic). Parses and validates the header like
/// the loader (same errors), reading only the header's bytes.
bool sampleLayoutOf(const std::string& spec, const LoadOptions& options, SampleLayout* layout);

std::optional<SampleLayout> niftiLayout(const std::filesystem::path& p,
                                        const LoadOptions& options);
std::optional<SampleLayout> nrrdLayout(const std::filesystem::path& p, const LoadOptions& options);
std::optional<SampleLayout> metaImageLayout(const std::filesystem::path& p,
                                            const LoadOptions& options);
SampleLayout rawSampleLayout(const std::filesystem::path& p, const RawOptions& options);

/// The whole volume's geometry (dims, spacing, origin, direction in the model's axes; source
/// and notes), without samples.
Volume layoutGeometry(const SampleLayout& L);

/// The samples [lo, hi) (model axes) of the volume `whole` = layoutGeometry(L): the crop
/// of the whole loaded volume, bit for bit, non-finite samples treated by `policy`.
Volume readLayoutBrick(const SampleLayout& L, const Volume& whole, const glm::ivec3& lo,
                       const glm::ivec3& hi, NonFinitePolicy policy);

/// The default background rule (backgroundFromFaces: the median of the finite samples on
/// the six outer faces, after `policy`) from the outer faces alone: the first and last
/// slices, the first and last row of every other slice, the first and last sample of every
/// other row. Equal to backgroundFromFaces of the whole loaded volume (the faces of the
/// file's box are the volume's faces, permuted and flipped).
float layoutBackground(const SampleLayout& L, NonFinitePolicy policy);

}  // namespace splat::detail
