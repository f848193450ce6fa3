// DICOM pixels into rescaled floats: native (uncompressed) Pixel Data decoded here from the
// bytes the element walk located, RLE Lossless by dicom_rle.cpp; the other compressed
// transfer syntaxes through gdcm::ImageReader in a forked child (dicom_isolation.cpp), which
// writes the floats into a shared mapping.
#include <gdcmImageReader.h>
#include <sys/mman.h>

#include <algorithm>
#include <cstdio>
#include <cstring>

#include "dicom_detail.h"

namespace splat::detail {
namespace {

const char* const kRleLossless = "1.2.840.10008.1.2.5";

std::uint32_t be32(const unsigned char* p) {
    return std::uint32_t(p[0]) << 24 | std::uint32_t(p[1]) << 16 | std::uint32_t(p[2]) << 8 |
           std::uint32_t(p[3]);
}

/// A JPEG 2000 codestream (ISO/IEC 15444-1 A.5.1: SOC FF4F, then the SIZ marker FF51 with
/// Lsiz, Rsiz, Xsiz, Ysiz, XOsiz, YOsiz) must declare the image the DICOM header does:
/// Xsiz - XOsiz = Columns, Ysiz - YOsiz = Rows. A codestream that declares another (pydicom's
/// JPEG2000-embedded-sequence-delimiter.dcm: four bytes of its SIZ overwritten, a 3722445056
/// x 1024 image) is refused with that, before a decoder sees it.
void checkJpeg2000Size(const SliceInfo& s) {
    const DicomLayout& l = s.layout;
    if (l.pixelLength < 4 + 38) return;
    const std::vector<unsigned char> head = readFileRange(s.path, l.pixelOffset, 4 + 38);
    const unsigned char* p = head.data();
    if (!(p[0] == 0xFF && p[1] == 0x4F && p[2] == 0xFF && p[3] == 0x51)) return;  // a JP2 file
    const std::uint64_t x = be32(p + 8), y = be32(p + 12), x0 = be32(p + 16), y0 = be32(p + 20);
    if (x > x0 && y > y0 && x - x0 == std::uint64_t(s.columns) && y - y0 == std::uint64_t(s.rows))
        return;
    throw Error(displayName(s.path) + ": corrupt JPEG 2000 codestream: its SIZ marker declares a " +
                std::to_string(x > x0 ? x - x0 : 0) + " x " + std::to_string(y > y0 ? y - y0 : 0) +
                " image, the DICOM header Columns x Rows " + std::to_string(s.columns) + " x " +
                std::to_string(s.rows));
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

/// Compressed pixels (JPEG baseline/extended/lossless, JPEG-LS, JPEG 2000: the codecs
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
    if (l.syntax == kRleLossless && l.encapsulated) {
        // One fragment per frame (PS3.5 A.4.2), the first after the offset table.
        const std::vector<unsigned char> frame =
            readFileRange(s.path, l.pixelOffset, l.pixelLength);
        const std::vector<unsigned char> raw =
            decodeRleFrame(frame.data(), frame.size(), std::size_t(count), int(size), name);
        storedToReal(raw.data(), std::size_t(count), std::size_t(size), s.bitsStored,
                     s.signedPixels, false, s.slope, s.intercept, out);
        return;
    }
    if (compressed) {
        if (l.encapsulated &&
            (l.syntax == "1.2.840.10008.1.2.4.90" || l.syntax == "1.2.840.10008.1.2.4.91"))
            checkJpeg2000Size(s);
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

}  // namespace

void readPixels(const SliceInfo& s, float* out) {
    guarded(s.path, [&] {
        readPixelsUnguarded(s, out);
        return 0;
    });
}

}  // namespace splat::detail
