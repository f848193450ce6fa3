// DICOM series through GDCM.
//
// Every file's header is read up to the pixel data (SeriesInstanceUID, ImagePositionPatient,
// ImageOrientationPatient, PixelSpacing, RescaleSlope/Intercept, Rows/Columns); the files
// of one series are sorted by their position along the slice normal (row direction x
// column direction), the slice spacing is the mean gap between neighbours (uneven gaps are
// refused, a gantry tilt is warned about), values become real units (Hounsfield units for
// CT) through each file's rescale, and the LPS patient coordinates become the RAS world
// NIfTI uses, so the same orientation code makes a head upright. A folder holding several
// series needs LoadOptions::dicomSeries (CLI: --series UID).
#include <fcntl.h>
#include <gdcmCSAHeader.h>
#include <gdcmDicts.h>
#include <gdcmElement.h>
#include <gdcmGlobal.h>
#include <gdcmImageReader.h>
#include <gdcmReader.h>
#include <gdcmSplitMosaicFilter.h>
#include <gdcmStringFilter.h>
#include <gdcmTrace.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <map>
#include <new>
#include <sstream>

#include "splat/error.h"
#include "volume_detail.h"

namespace fs = std::filesystem;

#if defined(__SANITIZE_ADDRESS__)
#define SPLAT_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SPLAT_ASAN 1
#endif
#endif
#ifndef SPLAT_ASAN
#define SPLAT_ASAN 0
#endif

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

/// GDCM reports to std::cerr unless told not to; errors reach the user as splat::Error.
void quietGdcm() {
    gdcm::Trace::DebugOff();
    gdcm::Trace::WarningOff();
    gdcm::Trace::ErrorOff();
}

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

/// Where a file's pixels are, from the element walk (checkDicomLengths).
struct DicomLayout {
    bool bigEndian = false;
    std::string syntax;
    bool pixelData = false, encapsulated = false;
    std::uint64_t pixelOffset = 0, pixelLength = 0;  ///< the last (top-level) Pixel Data
};

/// What one file's header says, before any pixel is read.
struct SliceInfo {
    fs::path path;
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

int intOf(const std::optional<std::vector<double>>& v, int fallback, const std::string& what,
          const char* field) {
    if (!v) return fallback;
    const double d = v->front();
    if (!(d >= -2147483648.0 && d <= 2147483647.0) || d != std::floor(d))
        throw Error(what + ": bad DICOM " + field + " " + std::to_string(d));
    return int(d);
}

/// GDCM reports some problems by throwing (gdcm::Exception is a std::exception): they
/// become splat::Error naming the file, like every other problem.
template <typename F>
auto guarded(const fs::path& p, F f) {
    try {
        return f();
    } catch (const Error&) {
        throw;
    } catch (const std::exception& e) {
        throw Error(displayName(p) + ": not a readable DICOM file (" +
                    std::string(e.what()).substr(0, 120) + ")");
    }
}

/// A tag as DICOM writes it: (7fe0,0010).
std::string hexTag(std::uint32_t group, std::uint32_t element) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "(%04x,%04x)", unsigned(group & 0xFFFF),
                  unsigned(element & 0xFFFF));
    return buf;
}

// GDCM allocates an element's value from its length field before reading it, so a
// 100-byte file declaring a 4 GB element would allocate 4 GB. This walk over the element
// headers (Part 10 files: preamble, explicit-VR meta group, then the data set in its
// transfer syntax) checks every defined length against the bytes that follow before GDCM
// sees the file. Sequences and items of undefined length are walked into; in implicit VR
// the public dictionary says which tags are sequences, as it does for GDCM.
DicomLayout checkDicomLengths(const std::vector<unsigned char>& b, const std::string& name) {
    DicomLayout layout;
    auto fail = [&](const std::string& why) {
        throw Error(name + ": malformed DICOM file (" + why + ")");
    };
    if (b.size() < 132 || std::memcmp(&b[128], "DICM", 4) != 0)
        fail("no DICM marker after the 128-byte preamble: only DICOM Part 10 files are read");
    static const std::string longVrs = "OBODOFOLOVOWSQSVUCUNURUTUV";
    static const std::string shortVrs = "AEASATCSDADSDTFLFDISLOLTPNSHSLSSSTTMUIULUS";
    const gdcm::Dicts& dicts = gdcm::Global::GetInstance().GetDicts();
    std::size_t pos = 132;
    bool inMeta = true, explicitVr = true, bigEndian = false;
    std::string syntax;
    auto read16 = [&](std::size_t at, bool be) {
        return be ? std::uint32_t(b[at] << 8 | b[at + 1]) : std::uint32_t(b[at] | b[at + 1] << 8);
    };
    auto read32 = [&](std::size_t at, bool be) {
        return be ? (read16(at, true) << 16 | read16(at + 2, true))
                  : (read16(at, false) | read16(at + 2, false) << 16);
    };
    auto isVr = [](const std::string& list, const char* vr) {
        for (std::size_t i = 0; i + 1 < list.size(); i += 2)
            if (list[i] == vr[0] && list[i + 1] == vr[1]) return true;
        return false;
    };
    // One entry per open sequence of undefined length: true when its content is implicit
    // VR little endian (an undefined-length UN, PS3.5 6.2.2, and everything inside it).
    std::vector<bool> scopes;
    // The ends of the open items and sequences of defined length: GDCM reads such a value
    // as a bounded block and resumes at its declared end, so an element that crosses that
    // end would make GDCM and this walk part ways (found by fuzz_dicom): refused.
    std::vector<std::size_t> ends;
    auto within = [&](std::uint64_t upTo) {
        if (!ends.empty() && upTo > ends.back())
            fail("an element crosses the end of its item or sequence");
    };
    while (pos < b.size()) {
        while (!ends.empty() && pos == ends.back()) ends.pop_back();
        within(pos);
        if (b.size() - pos < 8) fail("truncated element header");
        if (inMeta && read16(pos, false) != 0x0002) {
            inMeta = false;
            while (!syntax.empty() && (syntax.back() == '\0' || syntax.back() == ' '))
                syntax.pop_back();
            if (syntax == "1.2.840.10008.1.2.1.99")
                fail("deflated transfer syntax is not supported");
            // GDCM guesses the encoding when the meta group or its transfer syntax is missing
            // or unknown, and its guess can part ways with this walk (found by fuzz_dicom):
            // such files are refused, not guessed at.
            if (pos == 132) fail("no file meta information (group 0002) after DICM");
            if (syntax.empty()) fail("no transfer syntax (0002,0010) in the file meta information");
            if (syntax != "1.2.840.10008.1.2" && syntax != "1.2.840.10008.1.2.1" &&
                syntax != "1.2.840.10008.1.2.2" && syntax != "1.2.840.10008.1.2.5" &&
                !syntax.starts_with("1.2.840.10008.1.2.4."))
                fail("unknown transfer syntax '" + syntax.substr(0, 64) + "'");
            explicitVr = syntax != "1.2.840.10008.1.2";
            bigEndian = syntax == "1.2.840.10008.1.2.2";
            // A data set written in implicit VR under an explicit-VR transfer syntax (pydicom's
            // SC_rgb_jpeg.dcm): no VR where the first element's VR belongs. pydicom guesses
            // and reads it; GDCM's recovery runs out of memory on it. Refused, naming that.
            if (explicitVr && b.size() - pos >= 8) {
                const char vr[2] = {char(b[pos + 4]), char(b[pos + 5])};
                if (!isVr(longVrs, vr) && !isVr(shortVrs, vr))
                    fail("the data set is encoded in implicit VR, but its transfer syntax " +
                         syntax + " says explicit VR");
            }
        }
        const bool forced = !scopes.empty() && scopes.back();
        const bool ex = inMeta || (explicitVr && !forced), be = !inMeta && bigEndian && !forced;
        const std::uint32_t group = read16(pos, be), element = read16(pos + 2, be);
        if (group == 0xFFFE) {  // item or delimiter: tag + 4-byte length, no VR
            const std::uint32_t len = read32(pos + 4, be);
            pos += 8;
            // PS3.5 7.5: group fffe holds only the item (e000) and the item (e00d) and
            // sequence (e0dd) delimiters; GDCM reads anything else as an element.
            if (element != 0xE000 && element != 0xE00D && element != 0xE0DD)
                fail("invalid item tag " + hexTag(group, element));
            if (element == 0xE000 && len != 0xFFFFFFFFu && len > b.size() - pos)
                fail("an item declares " + std::to_string(len) + " bytes, the file holds " +
                     std::to_string(b.size() - pos));
            if (element == 0xE000 && len != 0xFFFFFFFFu) {
                within(pos + len);
                if (len > 0) ends.push_back(pos + len);
            }
            if (element == 0xE0DD && !scopes.empty()) scopes.pop_back();
            continue;  // walk into items; delimiters have no value
        }
        std::uint64_t len = 0;
        bool sequence = false, unknown = false;
        if (ex) {
            const char vr[2] = {char(b[pos + 4]), char(b[pos + 5])};
            if (isVr(longVrs, vr)) {
                if (b.size() - pos < 12) fail("truncated element header");
                len = read32(pos + 8, be);
                pos += 12;
            } else if (isVr(shortVrs, vr)) {
                len = read16(pos + 6, be);
                pos += 8;
            } else {
                fail("unknown value representation in element " + hexTag(group, element));
            }
            sequence = vr[0] == 'S' && vr[1] == 'Q';
            unknown = vr[0] == 'U' && vr[1] == 'N';
        } else {
            len = read32(pos + 4, be);
            pos += 8;
            const gdcm::VR vr =
                dicts.GetDictEntry(gdcm::Tag(std::uint16_t(group), std::uint16_t(element))).GetVR();
            sequence = vr == gdcm::VR::SQ;
        }
        // GDCM asserts (aborts the process) on a sequence or an undefined length in the meta
        // group, and on a file that ends inside it.
        if (inMeta && (sequence || len == 0xFFFFFFFFu))
            fail("a sequence or undefined length in the file meta information");
        // Pixel Data: a nested one (icon) comes before the top-level one, which is last.
        const bool pixels = group == 0x7FE0 && element == 0x0010;
        if (pixels) {
            layout.pixelData = true;
            layout.encapsulated = len == 0xFFFFFFFFu;
            layout.pixelOffset = pos;
            layout.pixelLength = len == 0xFFFFFFFFu ? 0 : len;
        }
        if (pixels && len == 0xFFFFFFFFu) {
            // Encapsulated (compressed) pixels, PS3.5 A.4: an offset table item, then one
            // item per fragment, then a sequence delimiter. Fragments hold codestreams,
            // not elements.
            while (true) {
                if (b.size() - pos < 8) fail("encapsulated Pixel Data ends without its delimiter");
                const std::uint32_t g = read16(pos, be), el = read16(pos + 2, be);
                const std::uint32_t flen = read32(pos + 4, be);
                pos += 8;
                if (g == 0xFFFE && el == 0xE0DD) break;
                if (g != 0xFFFE || el != 0xE000 || flen == 0xFFFFFFFFu)
                    fail("encapsulated Pixel Data holds " + hexTag(g, el) +
                         " where a fragment item belongs");
                if (flen > b.size() - pos)
                    fail("a Pixel Data fragment declares " + std::to_string(flen) +
                         " bytes, the file holds " + std::to_string(b.size() - pos));
                if (layout.pixelLength == 0 && flen > 0 && layout.pixelOffset + 8 < pos) {
                    layout.pixelOffset = pos;  // the first fragment after the offset table
                    layout.pixelLength = flen;
                }
                pos += flen;
            }
            continue;
        }
        if (len == 0xFFFFFFFFu) {  // undefined length: walk into its items
            scopes.push_back(forced || unknown);
            continue;
        }
        if (len > b.size() - pos)
            fail("element " + hexTag(group, element) + " declares " + std::to_string(len) +
                 " bytes, the file holds " + std::to_string(b.size() - pos));
        within(pos + len);
        if (sequence && len > 0) ends.push_back(pos + std::size_t(len));
        if (inMeta && group == 0x0002 && element == 0x0010)
            syntax.assign(reinterpret_cast<const char*>(&b[pos]), std::size_t(len));
        if (!sequence) pos += std::size_t(len);  // a sequence's items are checked too
    }
    if (inMeta) fail("no data set after the file meta information");
    layout.bigEndian = bigEndian;
    layout.syntax = syntax;
    return layout;
}

/// Runs `work` in a forked child and reports how the child ended. Debian's GDCM keeps its
/// assertions: a malformed file can abort the process inside gdcm::Reader (SIGABRT from
/// gdcm::DataSet::ReadNested, FileMetaInformation::ReadCompat, ...). Each GDCM parse is
/// first tried in a child; a child killed by a signal becomes one error line. Measured
/// cost: README "Input files" (fork per slice of a 500-slice series).
template <typename F>
void survivesInChild(const std::string& name, const char* what, F work) {
    std::fflush(nullptr);
    const pid_t pid = fork();
    if (pid < 0) throw Error(name + ": cannot start a process to parse the DICOM file");
    if (pid == 0) {
        alarm(60);  // a parser that hangs is a failure too
        // GDCM's recovery heuristics (explicit/implicit mixes, guessed byte orders) can read a
        // length the element walk never saw and allocate it. The child's address space is
        // capped (its present size + 1 GiB; not under AddressSanitizer, whose shadow memory
        // needs terabytes of address space), and an allocation that fails ends the child
        // with status 3, which the parent reports.
#if !SPLAT_ASAN
        {
            long pages = 0;
            if (FILE* f = std::fopen("/proc/self/statm", "r")) {
                if (std::fscanf(f, "%ld", &pages) != 1) pages = 0;
                std::fclose(f);
            }
            if (pages > 0) {
                const rlim_t cap =
                    rlim_t(pages) * rlim_t(sysconf(_SC_PAGESIZE)) + (rlim_t(1) << 30);
                const rlimit limit{cap, cap};
                setrlimit(RLIMIT_AS, &limit);
            }
        }
#endif
        std::set_new_handler([] { _exit(3); });
        // GDCM's assertion text is not for the user: the parent prints the one error line.
        // The host's crash handlers (a test framework's, a fuzzer's) must not report the
        // child's death as its own: the child dies plainly and quietly.
        for (int sig : {SIGABRT, SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGALRM}) signal(sig, SIG_DFL);
        const int null = open("/dev/null", O_WRONLY);
        if (null >= 0) {
            dup2(null, 1);
            dup2(null, 2);
        }
        try {
            work();
        } catch (...) {
        }
        _exit(0);
    }
    int status = 0;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) throw Error(name + ": lost the DICOM parsing process");
    if (WIFEXITED(status) && WEXITSTATUS(status) == 3)
        throw Error(name + ": malformed DICOM file (GDCM " + what +
                    " ran out of memory: a length the file cannot hold)");
    if (WIFSIGNALED(status)) {
        const int sig = WTERMSIG(status);
        throw Error(name + ": malformed DICOM file (GDCM " + what + " died on it with " +
                    (sig == SIGABRT   ? std::string("SIGABRT, a failed assertion")
                     : sig == SIGALRM ? std::string("a timeout")
                                      : "signal " + std::to_string(sig)) +
                    ")");
    }
}

SliceInfo readHeaderWithGdcm(const fs::path& p, const DicomLayout& layout, std::uint64_t fileSize);

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

/// Reads the pixels of one single-frame slice into `out` (columns x rows floats, rescaled).
void readPixelsUnguarded(const SliceInfo& s, float* out);
void readPixels(const SliceInfo& s, float* out) {
    guarded(s.path, [&] {
        readPixelsUnguarded(s, out);
        return 0;
    });
}

/// Stored values (the low `bitsStored` bits of `size`-byte words, two's complement when
/// signed) through the rescale into floats.
void storedToReal(const unsigned char* raw, std::size_t count, std::size_t size, int bitsStored,
                  bool signedPixels, bool bigEndian, double slope, double intercept, float* out) {
    const std::uint64_t mask =
        bitsStored >= 32 ? 0xFFFFFFFFull : (std::uint64_t(1) << bitsStored) - 1;
    const std::uint64_t signBit = std::uint64_t(1) << (bitsStored - 1);
    for (std::size_t i = 0; i < count; ++i) {
        std::uint64_t v = 0;
        for (std::size_t k = 0; k < size; ++k) {
            const std::size_t at = i * size + (bigEndian ? size - 1 - k : k);
            v |= std::uint64_t(raw[at]) << (8 * k);
        }
        v &= mask;
        const double value = signedPixels && (v & signBit)
                                 ? double(std::int64_t(v) - std::int64_t(mask) - 1)
                                 : double(v);
        out[i] = float(slope * value + intercept);
    }
}

/// Compressed pixels (JPEG baseline/extended/lossless, JPEG-LS, JPEG 2000, RLE: every codec
/// Debian's GDCM links) decoded by gdcm::ImageReader in a forked child, as the header is
/// (survivesInChild): the child writes the rescaled floats into a shared mapping.
void decodeCompressed(const SliceInfo& s, std::size_t count, float* out) {
    const std::string name = displayName(s.path);
    const std::size_t bytes = count * sizeof(float) + 64;
    void* shared = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
    if (shared == MAP_FAILED) throw Error(name + ": out of memory for the decoded DICOM pixels");
    struct Unmap {
        void* p;
        std::size_t n;
        ~Unmap() { munmap(p, n); }
    } unmap{shared, bytes};
    auto* status = static_cast<char*>(shared);  // 64 bytes: the child's message
    auto* pixels = reinterpret_cast<float*>(static_cast<char*>(shared) + 64);
    std::snprintf(status, 64, "%s", "GDCM did not decode it");
    survivesInChild(name, "decoding the compressed pixels", [&] {
        gdcm::ImageReader reader;
        reader.SetFileName(s.path.string().c_str());
        if (!reader.Read()) return;
        const gdcm::Image& image = reader.GetImage();
        const gdcm::PixelFormat& pf = image.GetPixelFormat();
        const std::size_t size = std::size_t(pf.GetBitsAllocated()) / 8;
        if (pf.GetSamplesPerPixel() != 1 || (size != 1 && size != 2 && size != 4)) {
            std::snprintf(status, 64, "decoded to %d samples of %d bits",
                          int(pf.GetSamplesPerPixel()), int(pf.GetBitsAllocated()));
            return;
        }
        if (image.GetBufferLength() != count * size) {
            std::snprintf(status, 64, "decoded to %lu bytes, not %lu",
                          (unsigned long)image.GetBufferLength(), (unsigned long)(count * size));
            return;
        }
        std::vector<char> buffer(count * size);
        if (!image.GetBuffer(buffer.data())) return;
        const int stored = std::clamp(int(pf.GetBitsStored()), 1, int(size * 8));
        storedToReal(reinterpret_cast<const unsigned char*>(buffer.data()), count, size, stored,
                     pf.GetPixelRepresentation() == 1, false, s.slope, s.intercept, pixels);
        status[0] = '\0';
    });
    if (status[0] != '\0')
        throw Error(name + ": compressed DICOM (transfer syntax " + s.layout.syntax +
                    ") could not be decoded: " + std::string(status, strnlen(status, 63)));
    std::memcpy(out, pixels, count * sizeof(float));
}

void readPixelsUnguarded(const SliceInfo& s, float* out) {
    // Native (uncompressed) Pixel Data is decoded here from the bytes the element walk
    // located; compressed pixels go through gdcm::ImageReader in a child process
    // (decodeCompressed): Debian's GDCM keeps its asserts.
    const std::string name = displayName(s.path);
    const DicomLayout& l = s.layout;
    static const char* native[] = {"1.2.840.10008.1.2", "1.2.840.10008.1.2.1",
                                   "1.2.840.10008.1.2.2"};
    if (!l.pixelData) throw Error(name + ": DICOM file has no Pixel Data");
    const bool compressed = std::none_of(std::begin(native), std::end(native),
                                         [&](const char* t) { return l.syntax == t; }) ||
                            l.encapsulated;
    if (s.bitsAllocated != 8 && s.bitsAllocated != 16 && s.bitsAllocated != 32)
        throw Error(name + ": DICOM BitsAllocated " + std::to_string(s.bitsAllocated) +
                    " is not supported (8, 16 or 32)");
    if (s.bitsStored < 1 || s.bitsStored > s.bitsAllocated)
        throw Error(name + ": DICOM BitsStored " + std::to_string(s.bitsStored) +
                    " does not fit BitsAllocated " + std::to_string(s.bitsAllocated));
    const std::uint64_t count = std::uint64_t(s.columns) * std::uint64_t(s.rows);
    const std::uint64_t size = std::uint64_t(s.bitsAllocated / 8);
    const std::uint64_t bytes = checkedMul(count, size, name);
    if (compressed) {
        decodeCompressed(s, std::size_t(count), out);
        return;
    }
    if (l.pixelLength < bytes)
        throw Error(name + ": DICOM Pixel Data holds " + std::to_string(l.pixelLength) +
                    " bytes, Rows x Columns needs " + std::to_string(bytes));
    const std::vector<unsigned char> raw = readFileRange(s.path, l.pixelOffset, bytes);
    storedToReal(raw.data(), std::size_t(count), std::size_t(size), s.bitsStored, s.signedPixels,
                 l.bigEndian, s.slope, s.intercept, out);
}

std::string fmt(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4g", v);
    return buf;
}

std::vector<SliceInfo> readInfos(const std::vector<fs::path>& files) {
    quietGdcm();
    std::vector<Checked> checked;
    checked.reserve(files.size());
    for (const fs::path& p : files) checked.push_back(checkFile(p));
    // Every header is first parsed in one child process for the whole series (one fork per
    // series, not per slice: README "Input files" has the measured cost); the child records
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
    infos.reserve(files.size());
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

/// Background value (issue 21): the padding value where the file says it, else the
/// rescaled minimum for CT; other modalities take the common rule (volumeBackground).
void setBackground(Volume& v, const SliceInfo& first) {
    if (first.padding) {
        v.background = float(first.slope * *first.padding + first.intercept);
        v.backgroundSource = "DICOM Pixel Padding Value";
    } else if (first.modality == "CT") {
        v.background = volumeStats(v, 1).minValue;
        v.backgroundSource = "minimum of the CT data (no Pixel Padding Value)";
    }
}

/// A Siemens mosaic (issue 22): one file holds a volume, its n = NumberOfImagesInMosaic
/// slices tiled m x m (m = ceil(sqrt n)) in one image, row by row; read as nibabel's
/// MosaicWrapper reads it. ImagePositionPatient is that of the whole tiled image's first
/// pixel, so the first slice's is moved by half the difference between the mosaic's and a
/// tile's size along the rows and columns; slices are stacked along the slice normal (the
/// sign of the CSA SliceNormalVector) at SpacingBetweenSlices (else SliceThickness). A
/// series of mosaic files is a time series: its first file is loaded, with a warning.
Volume loadMosaic(const std::string& name, std::vector<SliceInfo> files) {
    std::vector<std::string> notes;
    if (files.size() > 1) {
        std::stable_sort(files.begin(), files.end(), [](const SliceInfo& a, const SliceInfo& b) {
            return a.instance < b.instance;
        });
        notes.push_back("Siemens mosaic series of " + std::to_string(files.size()) +
                        " files (one volume each): only the first was loaded");
    }
    const SliceInfo& s = files.front();
    const std::string sn = displayName(s.path);
    if (s.mosaicImages < 1)
        throw Error(sn +
                    ": Siemens mosaic DICOM (ImageType MOSAIC) without NumberOfImagesInMosaic "
                    "in its CSA image header: the slices tiled in its " +
                    std::to_string(s.columns) + " x " + std::to_string(s.rows) +
                    " image cannot be told apart");
    const int m = int(std::ceil(std::sqrt(double(s.mosaicImages)) - 1e-9));
    if (s.rows % m != 0 || s.columns % m != 0)
        throw Error(sn + ": Siemens mosaic of " + std::to_string(s.mosaicImages) +
                    " images does not tile its " + std::to_string(s.columns) + " x " +
                    std::to_string(s.rows) + " image in " + std::to_string(m) + " x " +
                    std::to_string(m) + " tiles");
    const int tileRows = s.rows / m, tileCols = s.columns / m;
    const glm::ivec3 dims(tileCols, tileRows, s.mosaicImages);
    checkedVoxelCount(dims, name);

    std::vector<float> image(std::size_t(s.rows) * std::size_t(s.columns));
    readPixels(s, image.data());
    Volume v = makeVolume(dims, glm::dvec3(1.0), name);
    for (int k = 0; k < dims.z; ++k) {
        const int r0 = (k / m) * tileRows, c0 = (k % m) * tileCols;
        for (int j = 0; j < tileRows; ++j)
            std::copy_n(image.data() + std::size_t(r0 + j) * std::size_t(s.columns) + c0, tileCols,
                        v.data.data() + v.index(0, j, k));
    }

    double dx = 1, dy = 1;
    if (s.pixelSpacing) {
        dy = (*s.pixelSpacing)[0];
        dx = (*s.pixelSpacing)[1];
    } else {
        notes.push_back("DICOM: no PixelSpacing, 1 x 1 mm pixels assumed");
    }
    double gap = 1;
    if (s.between && *s.between > 0)
        gap = *s.between;
    else if (s.thickness && *s.thickness > 0)
        gap = *s.thickness;
    glm::dmat3 M(glm::dvec3(dx, 0, 0), glm::dvec3(0, dy, 0), glm::dvec3(0, 0, gap));
    glm::dvec3 t(0.0);
    std::string what = "DICOM spacing";
    if (s.position && s.orientation) {
        const std::vector<double>& o = *s.orientation;
        glm::dvec3 r(o[0], o[1], o[2]), c(o[3], o[4], o[5]);
        if (!(glm::length(r) > 0.5) || !(glm::length(c) > 0.5) ||
            std::abs(glm::dot(glm::normalize(r), glm::normalize(c))) > 1e-3)
            throw Error(sn + ": DICOM ImageOrientationPatient is not two orthogonal unit vectors");
        // nibabel: the normal from the orientation (r, c as given), its sign from the CSA
        // SliceNormalVector (without one, column x row direction).
        glm::dvec3 n = glm::cross(r, c);
        if (s.csaNormal ? glm::dot(n, *s.csaNormal) < 0 : true) n = -n;
        const glm::dvec3 first = *s.position + r * (dx * double(s.columns - tileCols) / 2) +
                                 c * (dy * double(s.rows - tileRows) / 2);
        const glm::dmat3 lpsToRas(glm::dvec3(-1, 0, 0), glm::dvec3(0, -1, 0), glm::dvec3(0, 0, 1));
        M = lpsToRas * glm::dmat3(r * dx, c * dy, n * gap);
        t = lpsToRas * first;
        what = "DICOM ImageOrientationPatient";
    } else {
        notes.push_back(
            "DICOM: no ImagePositionPatient/ImageOrientationPatient, orientation "
            "unknown");
    }
    std::string modality = s.modality.empty() ? "" : s.modality + " ";
    v.source = "DICOM " + modality + "Siemens mosaic, " + std::to_string(dims.z) + " slices (" +
               name + ")";
    applyOrientation(v, M, t, what);
    for (const std::string& n : notes) addNote(v, n);
    setBackground(v, s);
    return v;
}

}  // namespace

Volume loadDicomFiles(const std::string& name, const std::vector<fs::path>& files,
                      const LoadOptions& options) {
    if (files.empty()) throw Error(name + ": no DICOM files");
    std::vector<SliceInfo> all = readInfos(files);

    // One series.
    std::vector<DicomSeriesInfo> series = groupSeries(all);
    std::string uid = options.dicomSeries;
    if (uid.empty()) {
        if (series.size() > 1) {
            std::string list;
            for (const auto& d : series) list += (list.empty() ? "" : ", ") + d.uid;
            throw Error(name + ": holds " + std::to_string(series.size()) +
                        " DICOM series; choose one with --series UID (" + list +
                        "; `splat info` lists them)");
        }
        uid = series.front().uid;
    } else if (std::none_of(series.begin(), series.end(),
                            [&](const auto& d) { return d.uid == uid; })) {
        throw Error(name + ": no DICOM series with SeriesInstanceUID " + uid);
    }
    std::vector<SliceInfo> slices;
    for (SliceInfo& s : all)
        if (s.uid == uid) slices.push_back(std::move(s));

    const SliceInfo& first = slices.front();
    for (const SliceInfo& s : slices) {
        const std::string sn = displayName(s.path);
        if (s.mosaic != first.mosaic)
            throw Error(sn + ": series mixes Siemens mosaic and single-slice DICOM files");
        if (s.frames != 1)
            throw Error(sn + ": multi-frame DICOM (" + std::to_string(s.frames) +
                        " frames) is not supported");
        if (s.samples != 1)
            throw Error(sn + ": DICOM with " + std::to_string(s.samples) +
                        " samples per pixel is not supported (need scalar data)");
        if (s.rows < 1 || s.columns < 1)
            throw Error(sn + ": DICOM file has no Rows/Columns (no image?)");
        // The pixels a slice declares must fit its file (with room for 64:1 compression):
        // a 100-byte file cannot make us allocate gigabytes.
        const std::uint64_t pixelBytes =
            checkedMul(checkedMul(std::uint64_t(s.rows), std::uint64_t(s.columns), sn),
                       std::uint64_t(std::clamp(s.bitsAllocated, 8, 64) / 8), sn);
        if (pixelBytes > 64 * s.fileSize + (1u << 20))
            throw Error(sn + ": DICOM Rows x Columns " + std::to_string(s.rows) + " x " +
                        std::to_string(s.columns) + " needs more pixel data than the " +
                        std::to_string(s.fileSize) + "-byte file can hold");
        if (s.rows != first.rows || s.columns != first.columns)
            throw Error(sn + ": slice is " + std::to_string(s.columns) + " x " +
                        std::to_string(s.rows) + ", the first slice is " +
                        std::to_string(first.columns) + " x " + std::to_string(first.rows));
    }
    if (first.mosaic) return loadMosaic(name, std::move(slices));
    if (slices.size() > std::size_t(INT32_MAX)) throw Error(name + ": too many slices");
    const glm::ivec3 dims(first.columns, first.rows, int(slices.size()));
    checkedVoxelCount(dims, name);
    std::vector<std::string> notes;

    // In-plane spacing: PixelSpacing is (row spacing, column spacing) = (dy, dx).
    double dx = 1, dy = 1;
    if (first.pixelSpacing) {
        dy = (*first.pixelSpacing)[0];
        dx = (*first.pixelSpacing)[1];
        for (const SliceInfo& s : slices)
            if (!s.pixelSpacing || *s.pixelSpacing != *first.pixelSpacing)
                throw Error(displayName(s.path) + ": DICOM PixelSpacing differs between slices");
    } else {
        notes.push_back("DICOM: no PixelSpacing, 1 x 1 mm pixels assumed");
    }

    // Order and slice spacing from the geometry when every slice has it.
    const bool geometry = std::all_of(slices.begin(), slices.end(), [](const SliceInfo& s) {
        return s.position && s.orientation;
    });
    glm::dmat3 M(1.0);
    glm::dvec3 t(0.0);
    std::string what = "DICOM ImageOrientationPatient";
    if (geometry) {
        const std::vector<double>& o = *first.orientation;
        glm::dvec3 r(o[0], o[1], o[2]), c(o[3], o[4], o[5]);
        if (!(glm::length(r) > 0.5) || !(glm::length(c) > 0.5) ||
            std::abs(glm::dot(glm::normalize(r), glm::normalize(c))) > 1e-3)
            throw Error(displayName(first.path) +
                        ": DICOM ImageOrientationPatient is not two orthogonal unit vectors");
        // The file's r and c as given (PS3.3 C.7.6.2.1.1's equation, as nibabel and pydicom
        // use them; their rounding in the file is not normalised away), the normal unit.
        const glm::dvec3 r0 = r, c0 = c;
        r = glm::normalize(r);
        c = glm::normalize(c);
        const glm::dvec3 n = glm::cross(r, c);
        for (const SliceInfo& s : slices) {
            const std::vector<double>& so = *s.orientation;
            for (int i = 0; i < 6; ++i)
                if (std::abs(so[std::size_t(i)] - o[std::size_t(i)]) > 1e-4)
                    throw Error(displayName(s.path) +
                                ": DICOM ImageOrientationPatient differs between slices");
        }
        std::stable_sort(slices.begin(), slices.end(), [&](const SliceInfo& a, const SliceInfo& b) {
            return glm::dot(*a.position, n) < glm::dot(*b.position, n);
        });
        double gap = 1;
        glm::dvec3 step = n;
        if (slices.size() > 1) {
            double lo = INFINITY, hi = 0;
            for (std::size_t k = 1; k < slices.size(); ++k) {
                const double g = glm::dot(*slices[k].position - *slices[k - 1].position, n);
                lo = std::min(lo, g);
                hi = std::max(hi, g);
            }
            if (!(lo > 1e-6))
                throw Error(name + ": two DICOM slices of series " + uid +
                            " lie at the same position (several acquisitions in one series?)");
            if (hi > lo * 1.01 + 1e-4)
                throw Error(name + ": uneven DICOM slice gaps in series " + uid + " (from " +
                            fmt(lo) + " to " + fmt(hi) +
                            " mm: missing slices?); a volume needs one slice spacing");
            const glm::dvec3 span = *slices.back().position - *slices.front().position;
            gap = glm::dot(span, n) / double(slices.size() - 1);
            step = span / double(slices.size() - 1);
            const double tilt = std::acos(std::min(1.0, glm::dot(glm::normalize(step), n)));
            if (tilt > 1e-3)
                notes.push_back("DICOM gantry tilt of " + fmt(tilt * 180.0 / M_PI) +
                                " degrees: slices are stacked along the normal, not sheared");
        } else if (first.between && *first.between > 0) {
            gap = *first.between;
        } else if (first.thickness && *first.thickness > 0) {
            gap = *first.thickness;
        }
        // Columns (index x) run along r, rows (index y) along c, slices along n; LPS
        // patient coordinates become RAS (x and y negated), the convention of NIfTI.
        const glm::dmat3 lpsToRas(glm::dvec3(-1, 0, 0), glm::dvec3(0, -1, 0), glm::dvec3(0, 0, 1));
        M = lpsToRas * glm::dmat3(r0 * dx, c0 * dy, n * gap);
        t = lpsToRas * *slices.front().position;
    } else {
        const bool numbered = std::all_of(slices.begin(), slices.end(),
                                          [](const SliceInfo& s) { return s.instance >= 0; });
        if (numbered)
            std::stable_sort(
                slices.begin(), slices.end(),
                [](const SliceInfo& a, const SliceInfo& b) { return a.instance < b.instance; });
        double gap = 1;
        if (first.between && *first.between > 0)
            gap = *first.between;
        else if (first.thickness && *first.thickness > 0)
            gap = *first.thickness;
        M = glm::dmat3(glm::dvec3(dx, 0, 0), glm::dvec3(0, dy, 0), glm::dvec3(0, 0, gap));
        what = "DICOM spacing";
        notes.push_back(std::string("DICOM: no ImagePositionPatient/ImageOrientationPatient, "
                                    "slices ordered by ") +
                        (numbered ? "InstanceNumber" : "file name") + ", slice spacing " +
                        fmt(gap) + " assumed, orientation unknown");
    }

    Volume v = makeVolume(dims, glm::dvec3(1.0), name);
    const std::size_t plane = std::size_t(dims.x) * std::size_t(dims.y);
    for (std::size_t k = 0; k < slices.size(); ++k)
        readPixels(slices[k], v.data.data() + k * plane);
    std::string modality = first.modality.empty() ? "" : first.modality + " ";
    v.source =
        "DICOM " + modality + "series, " + std::to_string(slices.size()) + " files (" + name + ")";
    applyOrientation(v, M, t, what);
    for (const std::string& n : notes) addNote(v, n);
    setBackground(v, first);
    return v;
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
