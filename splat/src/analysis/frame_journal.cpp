// Frame journal (see frame_journal.h). Record: "SPLATFR1", int32 width, height, sheet axis,
// sheet sign, float64 milliseconds, width * height * 4 float32 (RGBA), uint64 FNV-1a of
// everything before it; host byte order (the journal never leaves the machine).
#include "frame_journal.h"

#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <vector>

#include "splat/atomic_file.h"

namespace splat::journal {

namespace {
constexpr char kMagic[8] = {'S', 'P', 'L', 'A', 'T', 'F', 'R', '1'};
constexpr std::size_t kHeader = 8 + 4 * 4 + 8;

std::uint64_t fnv1a(const unsigned char* p, std::size_t n) {
    std::uint64_t h = 1469598103934665603ull;
    for (std::size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
    return h;
}

std::size_t recordBytes(int width, int height) {
    return kHeader + std::size_t(width) * std::size_t(height) * 16 + 8;
}

template <class T>
void append(std::vector<unsigned char>& out, const T& v) {
    const auto* p = reinterpret_cast<const unsigned char*>(&v);
    out.insert(out.end(), p, p + sizeof v);
}
}  // namespace

void storeFrame(const std::filesystem::path& file, const Image& image, const RenderStats& stats) {
    std::vector<unsigned char> bytes;
    bytes.reserve(recordBytes(image.width, image.height));
    bytes.insert(bytes.end(), kMagic, kMagic + 8);
    append(bytes, std::int32_t(image.width));
    append(bytes, std::int32_t(image.height));
    append(bytes, std::int32_t(stats.sheetAxis));
    append(bytes, std::int32_t(stats.sheetSign));
    append(bytes, stats.milliseconds);
    const auto* px = reinterpret_cast<const unsigned char*>(image.pixels.data());
    bytes.insert(bytes.end(), px, px + image.pixels.size() * sizeof(glm::vec4));
    append(bytes, fnv1a(bytes.data(), bytes.size()));
    writeFileAtomic(file, bytes.data(), bytes.size());
}

bool hasFrame(const std::filesystem::path& file, int width, int height) {
    std::error_code ec;
    const auto size = std::filesystem::file_size(file, ec);
    return !ec && size == recordBytes(width, height);
}

bool loadFrame(const std::filesystem::path& file, int width, int height, Image& image,
               RenderStats& stats) {
    if (!hasFrame(file, width, height)) return false;
    std::ifstream in(file, std::ios::binary);
    std::vector<unsigned char> bytes(recordBytes(width, height));
    if (!in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(bytes.size())))
        return false;
    std::uint64_t sum;
    std::memcpy(&sum, bytes.data() + bytes.size() - 8, 8);
    if (std::memcmp(bytes.data(), kMagic, 8) != 0 || fnv1a(bytes.data(), bytes.size() - 8) != sum)
        return false;
    std::int32_t w, h, axis, sign;
    std::memcpy(&w, bytes.data() + 8, 4);
    std::memcpy(&h, bytes.data() + 12, 4);
    std::memcpy(&axis, bytes.data() + 16, 4);
    std::memcpy(&sign, bytes.data() + 20, 4);
    if (w != width || h != height) return false;
    Image im(width, height);
    std::memcpy(&stats.milliseconds, bytes.data() + 24, 8);
    std::memcpy(im.pixels.data(), bytes.data() + kHeader, im.pixels.size() * sizeof(glm::vec4));
    stats.sheetAxis = axis;
    stats.sheetSign = sign;
    image = std::move(im);
    return true;
}

}  // namespace splat::journal
