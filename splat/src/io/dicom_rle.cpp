// RLE Lossless, the DICOM transfer syntax 1.2.840.10008.1.2.5 (DICOM PS3.5 Annex G).
//
// A frame is one fragment: a 64-byte header (the number of segments, 1 to 15, then 15
// offsets from the header's start, unused ones 0) and the segments. Each segment holds one
// byte plane of the frame, most significant byte first (a 16-bit sample is segments 0 = high
// byte, 1 = low byte), compressed by the PackBits scheme of G.3.1: a header byte n read as
// a signed 8-bit number copies the next n + 1 bytes literally for 0 <= n <= 127, repeats the
// next byte 1 - n times for -127 <= n <= -1, and does nothing for -128. Each decoded segment
// holds exactly Rows x Columns bytes (a segment may end with one padding byte).
#include <cstring>

#include "dicom_detail.h"

namespace splat::detail {
namespace {

std::uint32_t le32(const unsigned char* p) {
    return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 |
           std::uint32_t(p[3]) << 24;
}

/// One PackBits segment [in, end) into exactly `count` bytes at `out`; the segment may hold
/// up to one byte more (its padding to an even length).
void unpackSegment(const unsigned char* in, const unsigned char* end, unsigned char* out,
                   std::size_t count, const std::string& name, int segment) {
    std::size_t n = 0;
    auto fail = [&](const std::string& why) {
        throw Error(name + ": corrupt RLE Lossless pixel data (segment " + std::to_string(segment) +
                    " " + why + ")");
    };
    while (n < count) {
        if (in >= end)
            fail("ends after " + std::to_string(n) + " of its " + std::to_string(count) + " bytes");
        const int header = static_cast<signed char>(*in++);
        if (header >= 0) {
            const std::size_t run = std::size_t(header) + 1;
            if (std::size_t(end - in) < run) fail("ends inside a literal run");
            if (count - n < run) fail("decodes to more than Rows x Columns bytes");
            std::memcpy(out + n, in, run);
            in += run;
            n += run;
        } else if (header != -128) {
            const std::size_t run = std::size_t(1 - header);
            if (in >= end) fail("ends inside a repeat run");
            if (count - n < run) fail("decodes to more than Rows x Columns bytes");
            std::memset(out + n, *in++, run);
            n += run;
        }
    }
}

}  // namespace

std::vector<unsigned char> decodeRleFrame(const unsigned char* frame, std::size_t size,
                                          std::size_t count, int bytesPerSample,
                                          const std::string& name) {
    if (size < 64)
        throw Error(name + ": corrupt RLE Lossless pixel data (a " + std::to_string(size) +
                    "-byte frame, shorter than the 64-byte RLE header)");
    const std::uint32_t segments = le32(frame);
    if (segments != std::uint32_t(bytesPerSample))
        throw Error(name + ": RLE Lossless pixel data with " + std::to_string(segments) +
                    " segments; " + std::to_string(bytesPerSample) + "-byte scalar samples need " +
                    std::to_string(bytesPerSample));
    std::vector<std::uint32_t> offsets(segments + 1);
    for (std::uint32_t k = 0; k < segments; ++k) offsets[k] = le32(frame + 4 + 4 * k);
    offsets[segments] = std::uint32_t(size);
    for (std::uint32_t k = 0; k < segments; ++k)
        if (offsets[k] < 64 || offsets[k] > offsets[k + 1])
            throw Error(name + ": corrupt RLE Lossless pixel data (segment " + std::to_string(k) +
                        " starts at byte " + std::to_string(offsets[k]) + " of the " +
                        std::to_string(size) + "-byte frame)");
    // Segment k is byte plane k, most significant first; the samples come out little-endian.
    std::vector<unsigned char> plane(count), out(count * std::size_t(bytesPerSample));
    for (std::uint32_t k = 0; k < segments; ++k) {
        unpackSegment(frame + offsets[k], frame + offsets[k + 1], plane.data(), count, name,
                      int(k));
        const std::size_t byte = std::size_t(bytesPerSample) - 1 - k;
        for (std::size_t i = 0; i < count; ++i)
            out[i * std::size_t(bytesPerSample) + byte] = plane[i];
    }
    return out;
}

}  // namespace splat::detail
