#pragma once
// Private pieces of the DICOM loader (not installed), one concern per file:
//   dicom_series.cpp     which files form which series: each file's header read up to its
//                        pixel data into a SliceInfo, grouped by SeriesInstanceUID
//   dicom_geometry.cpp   a series' slice order, spacing and orientation (and a mosaic's)
//   dicom_decode.cpp     one slice's pixels into rescaled floats
//   dicom_rle.cpp        the RLE Lossless codec
//   dicom_isolation.cpp  GDCM kept from harming the process: every length checked before
//                        GDCM reads a file, every GDCM parse tried in a forked child
//   load_dicom.cpp       loadDicomFiles: one series chosen, checked and assembled
#include <cstdint>
#include <exception>
#include <filesystem>
#include <functional>
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <vector>

#include "splat/error.h"
#include "volume_detail.h"

namespace splat::detail {

/// Where a file's pixels are, from the element walk (checkDicomLengths).
struct DicomLayout {
    bool bigEndian = false;
    std::string syntax;
    bool pixelData = false, encapsulated = false;
    std::uint64_t pixelOffset = 0, pixelLength = 0;  ///< the last (top-level) Pixel Data
};

/// What one file's header says, before any pixel is read.
struct SliceInfo {
    std::filesystem::path path;
    std::string uid, description, modality;
    int seriesNumber = -1, instance = -1;
    int rows = 0, columns = 0, frames = 1, samples = 1, bitsAllocated = 16, bitsStored = 16;
    bool signedPixels = false;
    bool mosaic = false;   ///< ImageType holds MOSAIC: a Siemens mosaic, slices tiled in one image
    int mosaicImages = 0;  ///< NumberOfImagesInMosaic of the Siemens CSA image header (0: none)
    std::optional<glm::dvec3> csaNormal;  ///< SliceNormalVector of the CSA image header
    DicomLayout layout;
    std::uint64_t fileSize = 0;
    std::optional<glm::dvec3> position;
    std::optional<std::vector<double>> orientation, pixelSpacing;
    std::optional<double> thickness, between;
    double slope = 1, intercept = 0;
    std::optional<double> padding;  ///< Pixel Padding Value (stored, not rescaled)
};

// ---- GDCM isolation (dicom_isolation.cpp) ------------------------------------------

/// GDCM reports to std::cerr unless told not to; errors reach the user as splat::Error.
void quietGdcm();

/// The element walk of a whole Part 10 file `b`: every defined length checked against the
/// bytes that follow, before GDCM sees the file; throws "NAME: malformed DICOM file (...)".
/// Returns the transfer syntax and where the top-level Pixel Data is.
DicomLayout checkDicomLengths(const std::vector<unsigned char>& b, const std::string& name);

/// Runs `work` in a forked child; a child killed by a signal, timed out or out of memory
/// becomes one "NAME: malformed DICOM file (GDCM WHAT ...)" error.
void survivesInChild(const std::string& name, const char* what, const std::function<void()>& work);

/// GDCM reports some problems by throwing (gdcm::Exception is a std::exception): they
/// become splat::Error naming the file, like every other problem.
template <typename F>
auto guarded(const std::filesystem::path& p, F f) {
    try {
        return f();
    } catch (const Error&) {
        throw;
    } catch (const std::exception& e) {
        throw Error(displayName(p) + ": not a readable DICOM file (" +
                    std::string(e.what()).substr(0, 120) + ")");
    }
}

// ---- series discovery (dicom_series.cpp) -------------------------------------------

/// Every file's header (element walk, then GDCM up to the Pixel Data), in `files` order;
/// files without Pixel Data are left out (all of them: refused, "no pixel data").
std::vector<SliceInfo> readInfos(const std::vector<std::filesystem::path>& files);
/// The series of `infos`, sorted by series number then UID.
std::vector<DicomSeriesInfo> groupSeries(const std::vector<SliceInfo>& infos);

// ---- geometry (dicom_geometry.cpp) -------------------------------------------------

/// A series' index-to-world affine (RAS) for applyOrientation, with the warnings it needs.
struct DicomGeometry {
    glm::dmat3 M{1.0};
    glm::dvec3 t{0.0};
    std::string what;                ///< what applyOrientation names the matrix
    std::vector<std::string> notes;  ///< assumptions, in the order they were made
};
/// The slices of one series (same size, one frame each) sorted into volume order, in place;
/// their spacing and orientation. `uid` names the series in errors.
DicomGeometry seriesGeometry(const std::string& name, const std::string& uid,
                             std::vector<SliceInfo>& slices);
/// The geometry of one Siemens mosaic file whose tiles are tileCols x tileRows pixels.
DicomGeometry mosaicGeometry(const SliceInfo& s, int tileRows, int tileCols);

// ---- decoding (dicom_decode.cpp) ---------------------------------------------------

/// Reads the pixels of one single-frame slice into `out` (columns x rows floats, rescaled).
void readPixels(const SliceInfo& s, float* out);

/// One RLE Lossless frame (dicom_rle.cpp, PS3.5 Annex G) of `count` scalar samples of
/// `bytesPerSample` bytes, as little-endian samples; throws "NAME: corrupt RLE Lossless pixel
/// data (...)" when the frame does not decode to exactly that.
std::vector<unsigned char> decodeRleFrame(const unsigned char* frame, std::size_t size,
                                          std::size_t count, int bytesPerSample,
                                          const std::string& name);

}  // namespace splat::detail
