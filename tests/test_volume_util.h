#pragma once
// Helpers for the volume tests: write bytes/text files and small hand-made volumes.
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cli_util.h"
#include "splat/error.h"
#include "splat/volume.h"

namespace splat::test {

inline void writeBytes(const std::filesystem::path& p, const std::string& bytes) {
    std::ofstream out(p, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), std::streamsize(bytes.size()));
}

/// Little- or big-endian bytes of a trivially copyable value.
template <typename T>
std::string bytesOf(T value, bool bigEndian = false) {
    std::string s(sizeof(T), '\0');
    std::memcpy(s.data(), &value, sizeof(T));
    if (bigEndian) std::string(s.rbegin(), s.rend()).swap(s);
    return s;
}

/// Encodes `values` as samples of type T.
template <typename T>
std::string samples(const std::vector<double>& values, bool bigEndian = false) {
    std::string s;
    for (double v : values) s += bytesOf(static_cast<T>(v), bigEndian);
    return s;
}

/// 0, 1, 2, ... n-1
inline std::vector<double> ramp(std::size_t n) {
    std::vector<double> v(n);
    for (std::size_t i = 0; i < n; ++i) v[i] = double(i);
    return v;
}

/// The message of the splat::Error thrown by f (empty if none was thrown).
template <typename F>
std::string errorOf(F f) {
    try {
        f();
    } catch (const splat::Error& e) {
        return e.what();
    }
    return "";
}

}  // namespace splat::test
