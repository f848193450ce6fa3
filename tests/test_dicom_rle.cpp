// The RLE Lossless codec (DICOM PS3.5 Annex G) on frames built here byte by byte: literal and
// repeat runs, the -128 no-op, the segments' byte order, and corrupt frames refused in one line.
#include <catch2/catch.hpp>
#include <cstdint>
#include <string>
#include <vector>

#include "io/dicom_detail.h"
#include "test_volume_util.h"

using namespace splat;
using namespace splat::test;

namespace {

/// A frame: the 64-byte header (segment count, 15 offsets) and the segments.
std::vector<unsigned char> frameOf(const std::vector<std::vector<unsigned char>>& segments) {
    std::vector<unsigned char> f(64, 0);
    auto put32 = [&](std::size_t at, std::uint32_t v) {
        for (int b = 0; b < 4; ++b) f[at + std::size_t(b)] = (unsigned char)(v >> (8 * b));
    };
    put32(0, std::uint32_t(segments.size()));
    for (std::size_t k = 0; k < segments.size(); ++k) {
        put32(4 + 4 * k, std::uint32_t(f.size()));
        f.insert(f.end(), segments[k].begin(), segments[k].end());
    }
    return f;
}

std::vector<unsigned char> decode(const std::vector<unsigned char>& f, std::size_t count,
                                  int bytes) {
    return detail::decodeRleFrame(f.data(), f.size(), count, bytes, "f.dcm");
}

}  // namespace

TEST_CASE("RLE Lossless: PackBits runs and byte planes", "[dicom][rle]") {
    // 8-bit: a literal run of 3 (header 2), a repeat of 4 (header -3 = 0xFD), the no-op -128,
    // a literal run of 1, and a padding byte after the segment's 8 bytes.
    const auto one = frameOf({{2, 10, 20, 30, 0xFD, 7, 0x80, 0, 99, 0}});
    CHECK(decode(one, 8, 1) == std::vector<unsigned char>{10, 20, 30, 7, 7, 7, 7, 99});
    // 16-bit: segment 0 holds the high bytes, segment 1 the low bytes; samples come out
    // little-endian: 0x0102, 0x0103, 0xFF04.
    const auto two = frameOf({{0xFF, 1, 0, 0xFF}, {2, 2, 3, 4}});
    CHECK(decode(two, 3, 2) == std::vector<unsigned char>{2, 1, 3, 1, 4, 0xFF});
    // 32-bit: four planes, most significant first (the first sample 0x01020304).
    const auto four = frameOf({{0, 1}, {0, 2}, {0, 3}, {0, 4}});
    CHECK(decode(four, 1, 4) == std::vector<unsigned char>{4, 3, 2, 1});
}

TEST_CASE("RLE Lossless: corrupt frames are one error line", "[dicom][rle]") {
    const std::vector<unsigned char> tiny(10, 0);
    CHECK(errorOf([&] { decode(tiny, 4, 1); }) ==
          "f.dcm: corrupt RLE Lossless pixel data (a 10-byte frame, shorter than the 64-byte RLE "
          "header)");
    CHECK(errorOf([&] {
              decode(frameOf({{0, 1}}), 1, 2);
          }) == "f.dcm: RLE Lossless pixel data with 1 segments; 2-byte scalar samples need 2");
    // A segment that ends early, one that decodes to more than Rows x Columns, a literal run
    // cut by the end of the frame, an offset inside the header.
    CHECK(errorOf([&] {
              decode(frameOf({{0xFE, 5}}), 4, 1);
          }) == "f.dcm: corrupt RLE Lossless pixel data (segment 0 ends after 3 of its 4 bytes)");
    CHECK(errorOf([&] {
              decode(frameOf({{0xFC, 5}}), 4, 1);
          }) ==
          "f.dcm: corrupt RLE Lossless pixel data (segment 0 decodes to more than Rows x "
          "Columns bytes)");
    CHECK(errorOf([&] {
              decode(frameOf({{3, 1, 2}}), 4, 1);
          }) == "f.dcm: corrupt RLE Lossless pixel data (segment 0 ends inside a literal run)");
    auto bad = frameOf({{0xFD, 5}});
    bad[4] = 8;
    CHECK(errorOf([&] { decode(bad, 4, 1); }) ==
          "f.dcm: corrupt RLE Lossless pixel data (segment 0 starts at byte 8 of the 66-byte "
          "frame)");
}
