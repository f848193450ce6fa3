// Image comparisons shared by the tests of bricks and ranks: the largest channel value and
// the largest per-channel difference of two frames of one size.
#pragma once
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

#include "splat/image.h"

namespace splat::test {

/// The largest value of any channel (the "peak" that bounds are relative to).
inline float peakOf(const Image& im) {
    float m = 0;
    for (const glm::vec4& p : im.pixels) m = std::max({m, p.r, p.g, p.b, p.a});
    return m;
}

/// The largest absolute difference over every pixel and channel (frames of one size).
inline float maxDiff(const Image& a, const Image& b) {
    REQUIRE(a.pixels.size() == b.pixels.size());
    float m = 0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i)
        for (int c = 0; c < 4; ++c) m = std::max(m, std::abs(a.pixels[i][c] - b.pixels[i][c]));
    return m;
}

}  // namespace splat::test
