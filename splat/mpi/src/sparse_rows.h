#pragma once
// Rows of an RGBA float image as the spans of their pixels that are not transparent (the
// sparse direct-send of brick_group.cpp). A pixel is transparent when its four floats are all
// +0 bit for bit, so the rows unpacked are the rows packed, bit for bit.
#include <cstdint>
#include <cstring>
#include <vector>

#include "splat/error.h"
#include "splat/image.h"

namespace splat::mpi {

inline bool transparent(const glm::vec4& p) {
    std::uint32_t b[4];
    std::memcpy(b, &p, sizeof b);
    return (b[0] | b[1] | b[2] | b[3]) == 0;
}

/// Appends rows [r0, r1) of `image` to `out`: for each row, the first column of its pixels
/// that are not transparent and one past the last (two int32 in the slots of two floats;
/// equal for an empty row), then the pixels between them.
inline void packRows(const Image& image, int r0, int r1, std::vector<float>& out) {
    for (int y = r0; y < r1; ++y) {
        const glm::vec4* row = &image.pixels[std::size_t(y) * std::size_t(image.width)];
        std::int32_t x0 = 0, x1 = image.width;
        while (x0 < x1 && transparent(row[x0])) ++x0;
        while (x1 > x0 && transparent(row[x1 - 1])) --x1;
        float span[2];
        std::memcpy(&span[0], &x0, sizeof x0);
        std::memcpy(&span[1], &x1, sizeof x1);
        out.insert(out.end(), span, span + 2);
        out.insert(out.end(), &row[x0].x, &row[x0].x + 4 * std::size_t(x1 - x0));
    }
}

/// Reads `rows` rows packed by packRows from `in` (`n` floats left) into the rows from `at`
/// of `image`, whose other pixels stay as they are (transparent: a fresh Image); returns the
/// floats read.
inline std::size_t unpackRows(const float* in, std::size_t n, Image& image, int at, int rows) {
    std::size_t used = 0;
    for (int y = at; y < at + rows; ++y) {
        std::int32_t x[2];
        if (n - used < 2) throw Error("MPI: a sparse strip ended early");
        std::memcpy(x, in + used, sizeof x);
        used += 2;
        if (x[0] < 0 || x[1] < x[0] || x[1] > image.width)
            throw Error("MPI: a sparse strip holds a bad span");
        const std::size_t floats = 4 * std::size_t(x[1] - x[0]);
        if (n - used < floats) throw Error("MPI: a sparse strip ended early");
        std::memcpy(&image.pixels[std::size_t(y) * std::size_t(image.width) + std::size_t(x[0])].x,
                    in + used, floats * sizeof(float));
        used += floats;
    }
    return used;
}

}  // namespace splat::mpi
