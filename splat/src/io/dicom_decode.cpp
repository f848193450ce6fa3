// DICOM pixels into rescaled floats: native (uncompressed) Pixel Data decoded here from the
// bytes the element walk located; compressed pixels through gdcm::ImageReader in a forked
// child (dicom_isolation.cpp), which writes the floats into a shared mapping.
#include <gdcmImageReader.h>
#include <sys/mman.h>

#include <algorithm>
#include <cstdio>
#include <cstring>

#include "dicom_detail.h"

namespace splat::detail {
namespace {

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

}  // namespace

void readPixels(const SliceInfo& s, float* out) {
    guarded(s.path, [&] {
        readPixelsUnguarded(s, out);
        return 0;
    });
}

}  // namespace splat::detail
