#pragma once
// Private helpers shared by the volume loaders and writers (not installed).
//
// Every loader does the same three things once it has parsed its header: read the
// sample bytes (possibly gzip/zlib-compressed), decode typed samples of either byte
// order into float, and turn the file's index-to-world matrix into the axis-aligned
// model of docs/design.md (flips and permutations applied to the data, oblique rest
// reported). Those pieces live here so no loader has its own copy.
#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <vector>

#include "splat/atomic_file.h"
#include "splat/volume.h"
#include "splat/volume_io.h"

namespace splat::detail {

// ---- sample types ----------------------------------------------------------------

enum class SampleType { U8, I8, U16, I16, U32, I32, F32, F64 };

std::size_t sampleSize(SampleType t);
/// Canonical name: uint8, int8, uint16, int16, uint32, int32, float32, float64.
const char* sampleTypeName(SampleType t);
/// Parses a type name: canonical names, short forms (u8, i16, f32), C names (uchar,
/// short, float, double) and the NRRD spellings ("unsigned char", "signed short int",
/// "int16_t", ...). Returns nullopt for anything else.
std::optional<SampleType> parseSampleType(const std::string& name);

/// Decodes `count` samples of type `t` stored with the given byte order from `bytes`
/// into `out[0..count)`. `bytes` must hold count * sampleSize(t) bytes.
void decodeSamples(const unsigned char* bytes, std::size_t count, SampleType t, bool bigEndian,
                   float* out);

/// Parses ASCII numbers (whitespace separated) into `out[0..count)`; throws naming
/// `what` if fewer numbers are present, one does not parse, or (integer types) one is
/// not an integer in the range of `t` (1.7, -5 or 300 in a uint8 file).
void decodeText(const std::string& text, std::size_t count, SampleType t, float* out,
                const std::string& what);

// ---- checked sizes ---------------------------------------------------------------

/// a * b in 64 bits; throws "WHAT: sizes overflow 64-bit arithmetic" when it wraps.
std::uint64_t checkedMul(std::uint64_t a, std::uint64_t b, const std::string& what);
/// a + b in 64 bits; throws like checkedMul.
std::uint64_t checkedAdd(std::uint64_t a, std::uint64_t b, const std::string& what);
/// Bytes the samples of a dims.x * dims.y * dims.z volume of type t take in a file, after
/// checking every dimension >= 1 and the voxel count <= kMaxVoxels (64-bit, no wrap).
/// Call it before allocating anything a header asks for.
std::size_t volumeBytes(const glm::ivec3& dims, SampleType t, const std::string& what);
/// A header number (parsed as double) as an int dimension: integral, 1 .. 2^31-1; throws
/// "WHAT: invalid FIELD 'TEXT'" otherwise.
int dimensionFrom(double value, const std::string& what, const std::string& field,
                  const std::string& text);

// ---- files -----------------------------------------------------------------------

/// Name used in error messages: the path as given by the user.
std::string displayName(const std::filesystem::path& p);
/// Size of a regular file, checked without opening it (a FIFO or device would block or
/// never end): throws "FILE: no such file" / "FILE: is a folder" / "FILE: not a regular
/// file (FIFO, device or socket)". `role` prefixes the name, e.g. "data file ".
std::uint64_t regularFileSize(const std::filesystem::path& p, const std::string& role = "");
/// Whole (regular) file into memory; throws "FILE: no such file" / "FILE: cannot read".
std::vector<unsigned char> readFileBytes(const std::filesystem::path& p);
/// Exactly `count` bytes at `offset` of a regular file, checked against its size before
/// allocating: "FILE: truncated data: expected N bytes, found M".
std::vector<unsigned char> readFileRange(const std::filesystem::path& p, std::uint64_t offset,
                                         std::uint64_t count);
/// Inflates gzip or zlib data (auto-detected) into at most `limit` bytes: a stream that
/// holds more throws "WHAT: compressed data holds more data than the header declares (N
/// bytes)" as soon as it passes the limit; corrupt data throws "WHAT: corrupt gzip data".
std::vector<unsigned char> inflateAll(const unsigned char* data, std::size_t size,
                                      const std::string& what, std::size_t limit);
/// Decompresses bzip2 data (concatenated streams allowed) into at most `limit` bytes, with
/// inflateAll's messages ("corrupt bzip2 data", "more data than the header declares").
std::vector<unsigned char> bunzip2All(const unsigned char* data, std::size_t size,
                                      const std::string& what, std::size_t limit);
/// The detached data file a header names (NRRD "data file", MetaImage ElementDataFile),
/// resolved against the header's folder. Unless `allowOutside`, an absolute path or one
/// whose `..` leaves that folder is refused: "HEADER: data file 'X' is outside the
/// header's folder (use --allow-outside-data to allow it)". The file must be regular.
std::filesystem::path resolveDataFile(const std::filesystem::path& header, const std::string& field,
                                      bool allowOutside);
/// Appends one warning to v.note ("; " separated). Every command prints the note.
void addNote(Volume& v, const std::string& text);
std::string toLower(std::string s);
std::string trim(const std::string& s);

// ---- orientation -----------------------------------------------------------------

/// Applies a file's index-to-world affine x = t + M p (world = RAS; columns of M = world
/// step of one index along each file axis) to `v`, whose data and dims are in file index
/// order. The signed axis permutation closest to M is applied to the data so that frame
/// axis w runs along index axis w in the positive direction; spacing becomes the column
/// norms in their new places, the rotation left (an oblique file) becomes v.direction
/// (identity below 1e-6) and v.origin the new first sample's position in the volume's
/// frame, so that v.worldPosition(p) = t + M p' for every voxel. Non-orthogonal axes are
/// replaced by the nearest rotation with a warning in v.note. `what` names the matrix's
/// origin ("sform", "space directions").
void applyOrientation(Volume& v, const glm::dmat3& M, const glm::dvec3& t, const std::string& what);

/// The signed axis permutation applyOrientation applies: file index axis a runs along the
/// model's axis `axis[a]`, reversed when sign[a] < 0; length[a] = |M column a| (the spacing).
struct AxisMap {
    std::array<int, 3> axis{0, 1, 2};
    int sign[3] = {1, 1, 1};
    double length[3] = {1, 1, 1};
};
AxisMap axisMapOf(const glm::dmat3& M, const std::string& source, const std::string& what);

/// The time step LoadOptions::time picks from an input of `steps` time steps (0 when unset);
/// a step past the last throws OptionError "NAME: time step T is out of range: ...". Inputs
/// without a time axis have the one step 0.
std::uint64_t timeStep(const std::string& name, const LoadOptions& options, std::uint64_t steps);

/// The NaN/Inf policy of loadVolume (an error naming the first such voxel, or 0 for each).
void applyNonFinitePolicy(Volume& v, NonFinitePolicy policy, const std::string& what);

// ---- the loaders (one per file) --------------------------------------------------

Volume loadNifti(const std::filesystem::path& p, const LoadOptions& options);
Volume loadNrrd(const std::filesystem::path& p, const LoadOptions& options);
Volume loadMetaImage(const std::filesystem::path& p, const LoadOptions& options);
Volume loadRaw(const std::filesystem::path& p, const RawOptions& options);
/// Where a headerless .raw file's samples are: its dims, type and first byte (the name
/// convention or RawOptions); dimensions and sample count checked, the file size not.
struct RawLayout {
    glm::ivec3 dims{0};
    SampleType type = SampleType::U8;
    std::uint64_t offset = 0;
};
RawLayout rawLayout(const std::filesystem::path& p, const RawOptions& options);
/// "synthetic:NAME[:N]" as its name and size (the default size when N is not given).
std::pair<std::string, int> syntheticSpec(const std::string& spec);
Volume loadSliceFolder(const std::filesystem::path& dir, const LoadOptions& options);
/// DICOM files through GDCM (load_dicom.cpp, dicom_detail.h): one series, sorted along the slice normal.
Volume loadDicomFiles(const std::string& name, const std::vector<std::filesystem::path>& files,
                      const LoadOptions& options);
/// DICOM files: ".dcm"/".dicom" or the "DICM" magic after the 128-byte preamble.
bool isDicomFile(const std::filesystem::path& p);

/// Reads one 2D image file through OpenImageIO into `out` (width*height floats, the
/// first channel or the luminance of RGB, native value range: 0..255 for 8-bit).
/// Returns the image size; throws naming the file.
glm::ivec2 readImageSlice(const std::filesystem::path& p, std::vector<float>& out,
                          std::string* formatName = nullptr);

/// "slice2" < "slice10": compares runs of digits by value.
bool naturalLess(const std::string& a, const std::string& b);

/// Checks a sample count against the available bytes; throws
/// "WHAT: truncated data: expected N bytes, found M" (or "... file holds M bytes, more
/// than the N the header describes" when there is too much data and `exact`).
void checkDataLength(std::size_t expected, std::size_t found, const std::string& what, bool exact);

}  // namespace splat::detail
