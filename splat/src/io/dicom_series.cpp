// DICOM series discovery: each file's header is read up to its pixel data (after the element
// walk of dicom_isolation.cpp, and first in a forked child) into a SliceInfo:
// SeriesInstanceUID, ImagePositionPatient, ImageOrientationPatient, PixelSpacing,
// RescaleSlope/Intercept, Rows/Columns, the Siemens CSA mosaic fields; the files are grouped
// by SeriesInstanceUID.
#include <gdcmCSAHeader.h>
#include <gdcmElement.h>
#include <gdcmReader.h>
#include <gdcmSplitMosaicFilter.h>
#include <gdcmStringFilter.h>
#include <sys/mman.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "dicom_detail.h"

namespace fs = std::filesystem;

namespace splat::detail {
namespace {

const gdcm::Tag kPixelData(0x7fe0, 0x0010);
const gdcm::Tag kSeriesUid(0x0020, 0x000e);
const gdcm::Tag kSeriesNumber(0x0020, 0x0011);
const gdcm::Tag kSeriesDescription(0x0008, 0x103e);
const gdcm::Tag kModality(0x0008, 0x0060);
const gdcm::Tag kImageType(0x0008, 0x0008);
const gdcm::Tag kInstanceNumber(0x0020, 0x0013);
const gdcm::Tag kPosition(0x0020, 0x0032);
const gdcm::Tag kOrientation(0x0020, 0x0037);
const gdcm::Tag kPixelSpacing(0x0028, 0x0030);
const gdcm::Tag kSliceThickness(0x0018, 0x0050);
const gdcm::Tag kSpacingBetweenSlices(0x0018, 0x0088);
const gdcm::Tag kRows(0x0028, 0x0010);
const gdcm::Tag kColumns(0x0028, 0x0011);
const gdcm::Tag kFrames(0x0028, 0x0008);
const gdcm::Tag kSamplesPerPixel(0x0028, 0x0002);
const gdcm::Tag kBitsAllocated(0x0028, 0x0100);
const gdcm::Tag kBitsStored(0x0028, 0x0101);
const gdcm::Tag kPixelRepresentation(0x0028, 0x0103);
const gdcm::Tag kSlope(0x0028, 0x1053);
const gdcm::Tag kIntercept(0x0028, 0x1052);
const gdcm::Tag kPixelPadding(0x0028, 0x0120);

/// Decimal numbers of a "a\b\c" value; nullopt when absent, throws when malformed.
std::optional<std::vector<double>> numbersOf(gdcm::StringFilter& sf, const gdcm::DataSet& ds,
                                             const gdcm::Tag& tag, const std::string& what,
                                             const char* field) {
    if (!ds.FindDataElement(tag) || ds.GetDataElement(tag).IsEmpty()) return std::nullopt;
    std::string s = sf.ToString(tag);
    for (char& c : s)
        if (c == '\\') c = ' ';
    std::vector<double> out;
    const char* p = s.c_str();
    while (true) {
        while (*p == ' ') ++p;
        if (!*p) break;
        char* end = nullptr;
        double v = std::strtod(p, &end);
        if (end == p || !std::isfinite(v))
            throw Error(what + ": bad DICOM " + field + " '" + s.substr(0, 60) + "'");
        out.push_back(v);
        p = end;
    }
    if (out.empty()) return std::nullopt;
    return out;
}

std::string textOf(gdcm::StringFilter& sf, const gdcm::DataSet& ds, const gdcm::Tag& tag) {
    if (!ds.FindDataElement(tag) || ds.GetDataElement(tag).IsEmpty()) return "";
    return trim(std::string(sf.ToString(tag).c_str()));  // stops at an embedded NUL
}

int intOf(const std::optional<std::vector<double>>& v, int fallback, const std::string& what,
          const char* field) {
    if (!v) return fallback;
    const double d = v->front();
    if (!(d >= -2147483648.0 && d <= 2147483647.0) || d != std::floor(d))
        throw Error(what + ": bad DICOM " + field + " " + std::to_string(d));
    return int(d);
}

/// One file's element walk (checkDicomLengths), before GDCM sees it.
struct Checked {
    fs::path path;
    DicomLayout layout;
    std::uint64_t fileSize = 0;
};

/// A Siemens mosaic's CSA image header (private group 0029, "SIEMENS CSA HEADER"): the
/// number of slices tiled in the image and the slice normal, as nibabel's MosaicWrapper and
/// dcm2niix read them.
void readMosaicHeader(const gdcm::File& file, SliceInfo& s) {
    s.mosaicImages =
        int(std::min(gdcm::SplitMosaicFilter::GetNumberOfImagesInMosaic(file), 1u << 20));
    gdcm::CSAHeader csa;
    const gdcm::PrivateTag& tag = csa.GetCSAImageHeaderInfoTag();
    const gdcm::DataSet& ds = file.GetDataSet();
    if (!ds.FindDataElement(tag) || !csa.LoadFromDataElement(ds.GetDataElement(tag)) ||
        !csa.FindCSAElementByName("SliceNormalVector"))
        return;
    const gdcm::CSAElement& e = csa.GetCSAElementByName("SliceNormalVector");
    const gdcm::ByteValue* bv = e.IsEmpty() ? nullptr : e.GetByteValue();
    if (!bv || !bv->GetPointer()) return;
    // The items as text, "x\\y\\z".
    std::string text(bv->GetPointer(), bv->GetLength());
    for (char& ch : text)
        if (ch == '\\' || ch == '\0') ch = ' ';
    std::istringstream in(text);
    glm::dvec3 n;
    if (in >> n.x >> n.y >> n.z && std::isfinite(n.x) && std::isfinite(n.y) && std::isfinite(n.z) &&
        glm::length(n) > 0.5)
        s.csaNormal = n;
}

SliceInfo readHeaderWithGdcm(const fs::path& p, const DicomLayout& layout, std::uint64_t fileSize) {
    const std::string name = displayName(p);
    gdcm::Reader reader;
    reader.SetFileName(p.string().c_str());
    if (!reader.ReadUpToTag(kPixelData)) throw Error(name + ": not a readable DICOM file");
    const gdcm::DataSet& ds = reader.GetFile().GetDataSet();
    gdcm::StringFilter sf;
    sf.SetFile(reader.GetFile());
    SliceInfo s;
    s.path = p;
    s.fileSize = fileSize;
    s.layout = layout;
    s.uid = textOf(sf, ds, kSeriesUid);
    s.description = textOf(sf, ds, kSeriesDescription);
    s.modality = textOf(sf, ds, kModality);
    const std::string imageType = textOf(sf, ds, kImageType);
    s.mosaic = ("\\" + imageType + "\\").find("\\MOSAIC\\") != std::string::npos;
    if (s.mosaic) readMosaicHeader(reader.GetFile(), s);
    s.seriesNumber =
        intOf(numbersOf(sf, ds, kSeriesNumber, name, "SeriesNumber"), -1, name, "SeriesNumber");
    s.instance = intOf(numbersOf(sf, ds, kInstanceNumber, name, "InstanceNumber"), -1, name,
                       "InstanceNumber");
    s.rows = intOf(numbersOf(sf, ds, kRows, name, "Rows"), 0, name, "Rows");
    s.columns = intOf(numbersOf(sf, ds, kColumns, name, "Columns"), 0, name, "Columns");
    s.frames = intOf(numbersOf(sf, ds, kFrames, name, "NumberOfFrames"), 1, name, "NumberOfFrames");
    s.samples = intOf(numbersOf(sf, ds, kSamplesPerPixel, name, "SamplesPerPixel"), 1, name,
                      "SamplesPerPixel");
    s.bitsAllocated =
        intOf(numbersOf(sf, ds, kBitsAllocated, name, "BitsAllocated"), 16, name, "BitsAllocated");
    s.bitsStored = intOf(numbersOf(sf, ds, kBitsStored, name, "BitsStored"), s.bitsAllocated, name,
                         "BitsStored");
    s.signedPixels = intOf(numbersOf(sf, ds, kPixelRepresentation, name, "PixelRepresentation"), 0,
                           name, "PixelRepresentation") == 1;
    if (auto v = numbersOf(sf, ds, kPosition, name, "ImagePositionPatient")) {
        if (v->size() != 3) throw Error(name + ": DICOM ImagePositionPatient needs 3 numbers");
        s.position = glm::dvec3((*v)[0], (*v)[1], (*v)[2]);
    }
    s.orientation = numbersOf(sf, ds, kOrientation, name, "ImageOrientationPatient");
    if (s.orientation && s.orientation->size() != 6)
        throw Error(name + ": DICOM ImageOrientationPatient needs 6 numbers");
    s.pixelSpacing = numbersOf(sf, ds, kPixelSpacing, name, "PixelSpacing");
    if (s.pixelSpacing &&
        (s.pixelSpacing->size() != 2 || !((*s.pixelSpacing)[0] > 0) || !((*s.pixelSpacing)[1] > 0)))
        throw Error(name + ": DICOM PixelSpacing must be two numbers > 0");
    if (auto v = numbersOf(sf, ds, kSliceThickness, name, "SliceThickness"))
        s.thickness = v->front();
    if (auto v = numbersOf(sf, ds, kSpacingBetweenSlices, name, "SpacingBetweenSlices"))
        s.between = v->front();
    if (auto v = numbersOf(sf, ds, kSlope, name, "RescaleSlope")) s.slope = v->front();
    if (auto v = numbersOf(sf, ds, kIntercept, name, "RescaleIntercept")) s.intercept = v->front();
    if (auto v = numbersOf(sf, ds, kPixelPadding, name, "PixelPaddingValue"))
        s.padding = v->front();
    return s;
}

Checked checkFile(const fs::path& p) {
    return guarded(p, [&] {
        const std::uint64_t fileSize = regularFileSize(p);
        return Checked{p, checkDicomLengths(readFileBytes(p), displayName(p)), fileSize};
    });
}

}  // namespace

std::vector<SliceInfo> readInfos(const std::vector<fs::path>& files) {
    quietGdcm();
    std::vector<Checked> checked;
    checked.reserve(files.size());
    for (const fs::path& p : files) checked.push_back(checkFile(p));
    // A file without Pixel Data (a DICOMDIR, a structured report, nibabel's
    // csa_slice_norm.dcm) is no slice, and GDCM's header reader asserts on some of them: it
    // is left out of a folder that holds images, and refused alone.
    const auto image = [](const Checked& c) { return c.layout.pixelData; };
    if (!checked.empty() && std::none_of(checked.begin(), checked.end(), image))
        throw Error(displayName(checked.front().path) +
                    ": DICOM file without pixel data (no Pixel Data element (7fe0,0010)): not "
                    "an image");
    checked.erase(
        std::remove_if(checked.begin(), checked.end(), [&](const Checked& c) { return !image(c); }),
        checked.end());
    // Every header is first parsed in one child process for the whole series (one fork per
    // series, not per slice: docs/decisions.md has the measured cost); the child records
    // which file it is in, so a death names the file.
    auto* at = static_cast<std::size_t*>(mmap(nullptr, sizeof(std::size_t), PROT_READ | PROT_WRITE,
                                              MAP_SHARED | MAP_ANONYMOUS, -1, 0));
    if (at == MAP_FAILED) throw Error("DICOM: out of memory");
    *at = 0;
    struct Unmap {
        std::size_t* p;
        ~Unmap() { munmap(p, sizeof(std::size_t)); }
    } unmap{at};
    try {
        survivesInChild("", "reading the header", [&] {
            for (std::size_t i = 0; i < checked.size(); ++i) {
                *at = i;
                try {
                    (void)readHeaderWithGdcm(checked[i].path, checked[i].layout,
                                             checked[i].fileSize);
                } catch (...) {
                }
            }
        });
    } catch (const Error& e) {  // the message starts with the (empty) name: ": malformed ..."
        throw Error(displayName(checked[std::min(*at, checked.size() - 1)].path) + e.what());
    }
    std::vector<SliceInfo> infos;
    infos.reserve(checked.size());
    for (const Checked& c : checked)
        infos.push_back(
            guarded(c.path, [&] { return readHeaderWithGdcm(c.path, c.layout, c.fileSize); }));
    return infos;
}

std::vector<DicomSeriesInfo> groupSeries(const std::vector<SliceInfo>& infos) {
    std::map<std::string, DicomSeriesInfo> byUid;
    for (const SliceInfo& s : infos) {
        DicomSeriesInfo& d = byUid[s.uid];
        if (d.files == 0) {
            d.uid = s.uid;
            d.description = s.description;
            d.modality = s.modality;
            d.seriesNumber = s.seriesNumber;
            d.rows = s.rows;
            d.columns = s.columns;
        }
        ++d.files;
    }
    std::vector<DicomSeriesInfo> out;
    for (auto& [uid, d] : byUid) out.push_back(d);
    std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) {
        return a.seriesNumber != b.seriesNumber ? a.seriesNumber < b.seriesNumber : a.uid < b.uid;
    });
    return out;
}

}  // namespace splat::detail

namespace splat {

std::vector<DicomSeriesInfo> listDicomSeries(const std::string& folder) {
    const fs::path dir(folder);
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) return {};
    std::vector<fs::path> files;
    for (const auto& entry : fs::directory_iterator(dir, ec)) {
        if (!entry.is_regular_file()) continue;
        if (entry.path().filename().string().starts_with(".")) continue;
        if (detail::isDicomFile(entry.path())) files.push_back(entry.path());
    }
    if (ec) throw Error(folder + ": cannot list folder (" + ec.message() + ")");
    std::sort(files.begin(), files.end());
    return detail::groupSeries(detail::readInfos(files));
}

}  // namespace splat
