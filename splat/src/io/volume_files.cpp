// File helpers shared by the loaders and writers: whole-file reads with clear errors,
// gzip/zlib inflation, atomic writes, extensions and natural sort order.
#include <bzlib.h>
#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <random>
#include <string>

#include "splat/error.h"
#include "volume_detail.h"

namespace fs = std::filesystem;

namespace splat::detail {

std::string displayName(const fs::path& p) { return p.string(); }

std::string toLower(std::string s) {
    for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

std::string trim(const std::string& s) {
    std::size_t b = 0, e = s.size();
    while (b < e && std::isspace(static_cast<unsigned char>(s[b]))) ++b;
    while (e > b && std::isspace(static_cast<unsigned char>(s[e - 1]))) --e;
    return s.substr(b, e - b);
}

std::uint64_t checkedMul(std::uint64_t a, std::uint64_t b, const std::string& what) {
    std::uint64_t r = 0;
    if (__builtin_mul_overflow(a, b, &r))
        throw Error(what + ": sizes overflow 64-bit arithmetic (" + std::to_string(a) + " x " +
                    std::to_string(b) + ")");
    return r;
}

std::uint64_t checkedAdd(std::uint64_t a, std::uint64_t b, const std::string& what) {
    std::uint64_t r = 0;
    if (__builtin_add_overflow(a, b, &r))
        throw Error(what + ": sizes overflow 64-bit arithmetic (" + std::to_string(a) + " + " +
                    std::to_string(b) + ")");
    return r;
}

std::size_t volumeBytes(const glm::ivec3& dims, SampleType t, const std::string& what) {
    return std::size_t(checkedMul(checkedVoxelCount(dims, what), sampleSize(t), what));
}

int dimensionFrom(double value, const std::string& what, const std::string& field,
                  const std::string& text) {
    if (!(value >= 1 && value <= 2147483647.0) || value != std::floor(value))
        throw Error(what + ": invalid " + field + " '" + text + "'");
    return int(value);
}

std::uint64_t regularFileSize(const fs::path& p, const std::string& role) {
    const std::string name = role + displayName(p);
    std::error_code ec;
    // status() is stat(2): it never opens the file, so a FIFO cannot block us here.
    const fs::file_status st = fs::status(p, ec);
    if (!fs::exists(st)) throw Error(name + ": no such file");
    if (fs::is_directory(st)) throw Error(name + ": is a folder, expected a file");
    if (!fs::is_regular_file(st))
        throw Error(name + ": not a regular file (FIFO, device or socket); refusing to read it");
    const std::uintmax_t size = fs::file_size(p, ec);
    if (ec) throw Error(name + ": cannot read (" + ec.message() + ")");
    return std::uint64_t(size);
}

std::vector<unsigned char> readFileRange(const fs::path& p, std::uint64_t offset,
                                         std::uint64_t count) {
    const std::string name = displayName(p);
    const std::uint64_t size = regularFileSize(p);
    const std::uint64_t available = size > offset ? size - offset : 0;
    if (available < count)
        throw Error(name + ": truncated data: expected " + std::to_string(count) +
                    " bytes, found " + std::to_string(available) + " (after byte " +
                    std::to_string(offset) + ")");
    std::ifstream in(p, std::ios::binary);
    if (!in) throw Error(name + ": cannot open for reading");
    in.seekg(std::streamoff(offset));
    std::vector<unsigned char> bytes(static_cast<std::size_t>(count));
    if (count > 0 && !in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(count)))
        throw Error(name + ": cannot read (the file shrank while reading?)");
    return bytes;
}

std::vector<unsigned char> readFileBytes(const fs::path& p) {
    return readFileRange(p, 0, regularFileSize(p));
}

std::vector<unsigned char> inflateAll(const unsigned char* data, std::size_t size,
                                      const std::string& what, std::size_t limit) {
    z_stream zs{};
    // 15 + 32: accept both gzip and zlib headers.
    if (inflateInit2(&zs, 15 + 32) != Z_OK) throw Error(what + ": cannot initialise zlib");
    // The output grows with what the stream really holds (never beyond limit + 1 bytes, so
    // one byte past the declared size is enough to know the stream holds too much).
    std::vector<unsigned char> out;
    const std::size_t cap = limit == SIZE_MAX ? limit : limit + 1;
    out.resize(std::min<std::size_t>(cap, std::max<std::size_t>(size * 4, 1 << 16)));
    std::size_t inPos = 0;
    int ret = Z_OK;
    bool tooMuch = false;
    while (true) {
        if (zs.avail_in == 0 && inPos < size) {
            std::size_t chunk = std::min<std::size_t>(size - inPos, 1u << 30);
            zs.next_in = const_cast<unsigned char*>(data + inPos);
            zs.avail_in = static_cast<uInt>(chunk);
            inPos += chunk;
        }
        if (zs.total_out == out.size()) {
            if (out.size() >= cap) {
                tooMuch = true;
                break;
            }
            out.resize(std::min(cap, out.size() * 2));
        }
        std::size_t room = std::min<std::size_t>(out.size() - zs.total_out, 1u << 30);
        zs.next_out = out.data() + zs.total_out;
        zs.avail_out = static_cast<uInt>(room);
        ret = inflate(&zs, Z_NO_FLUSH);
        if (ret == Z_STREAM_END) {
            // Concatenated gzip members are legal: continue with the next one.
            if (zs.avail_in > 0 || inPos < size) {
                if (inflateReset(&zs) != Z_OK) break;
                continue;
            }
            break;
        }
        if (ret != Z_OK && ret != Z_BUF_ERROR) break;
        if (ret == Z_BUF_ERROR && zs.avail_in == 0 && inPos >= size) break;  // input ends early
    }
    std::size_t produced = zs.total_out;
    const char* msg = zs.msg;
    std::string reason = msg ? msg : (ret == Z_BUF_ERROR ? "unexpected end of stream" : "error");
    inflateEnd(&zs);
    if (tooMuch)
        throw Error(what + ": compressed data holds more data than the header declares (" +
                    std::to_string(limit) + " bytes)");
    if (ret != Z_STREAM_END) throw Error(what + ": corrupt gzip data (" + reason + ")");
    out.resize(produced);
    return out;
}

std::vector<unsigned char> bunzip2All(const unsigned char* data, std::size_t size,
                                      const std::string& what, std::size_t limit) {
    bz_stream bz{};
    if (BZ2_bzDecompressInit(&bz, 0, 0) != BZ_OK) throw Error(what + ": cannot initialise bzip2");
    std::vector<unsigned char> out;
    const std::size_t cap = limit == SIZE_MAX ? limit : limit + 1;
    out.resize(std::min<std::size_t>(cap, std::max<std::size_t>(size * 4, 1 << 16)));
    std::size_t inPos = 0, produced = 0;
    int ret = BZ_OK;
    bool tooMuch = false;
    while (true) {
        if (bz.avail_in == 0 && inPos < size) {
            const std::size_t chunk = std::min<std::size_t>(size - inPos, 1u << 30);
            bz.next_in = reinterpret_cast<char*>(const_cast<unsigned char*>(data + inPos));
            bz.avail_in = unsigned(chunk);
            inPos += chunk;
        }
        if (produced == out.size()) {
            if (out.size() >= cap) {
                tooMuch = true;
                break;
            }
            out.resize(std::min(cap, out.size() * 2));
        }
        const std::size_t room = std::min<std::size_t>(out.size() - produced, 1u << 30);
        bz.next_out = reinterpret_cast<char*>(out.data() + produced);
        bz.avail_out = unsigned(room);
        ret = BZ2_bzDecompress(&bz);
        produced += room - bz.avail_out;
        if (ret == BZ_STREAM_END) {
            // Concatenated bzip2 streams (pbzip2, teem appending) are legal: the next one.
            if (bz.avail_in > 0 || inPos < size) {
                const unsigned left = bz.avail_in;
                char* next = bz.next_in;
                BZ2_bzDecompressEnd(&bz);
                bz = bz_stream{};
                if (BZ2_bzDecompressInit(&bz, 0, 0) != BZ_OK) break;
                bz.next_in = next;
                bz.avail_in = left;
                continue;
            }
            break;
        }
        if (ret != BZ_OK) break;
        // No progress with all the input consumed: the stream ends early.
        if (bz.avail_in == 0 && inPos >= size && bz.avail_out > 0) break;
    }
    BZ2_bzDecompressEnd(&bz);
    if (tooMuch)
        throw Error(what + ": compressed data holds more data than the header declares (" +
                    std::to_string(limit) + " bytes)");
    if (ret != BZ_STREAM_END)
        throw Error(what + ": corrupt bzip2 data (" +
                    (ret == BZ_OK ? std::string("unexpected end of stream")
                                  : "error " + std::to_string(ret)) +
                    ")");
    out.resize(produced);
    return out;
}

fs::path resolveDataFile(const fs::path& header, const std::string& field, bool allowOutside) {
    const std::string name = displayName(header);
    const fs::path given(field);
    fs::path dp;
    if (given.is_absolute()) {
        dp = given;
    } else {
        dp = header.parent_path() / given;
    }
    if (!allowOutside) {
        const fs::path rel = given.lexically_normal();
        const bool escapes = given.is_absolute() || given.has_root_name() || rel.empty() ||
                             (rel.begin() != rel.end() && *rel.begin() == "..");
        if (escapes)
            throw Error(name + ": data file '" + field +
                        "' is outside the header's folder (use --allow-outside-data, or "
                        "LoadOptions::allowOutsideDataFiles, to allow it)");
    }
    std::error_code ec;
    if (!fs::exists(dp, ec))
        throw Error(name + ": data file " + displayName(dp) + " does not exist");
    regularFileSize(dp, "data file ");
    return dp;
}

void addNote(Volume& v, const std::string& text) {
    if (!v.note.empty()) v.note += "; ";
    v.note += text;
}

bool naturalLess(const std::string& a, const std::string& b) {
    std::size_t i = 0, j = 0;
    while (i < a.size() && j < b.size()) {
        unsigned char ca = a[i], cb = b[j];
        if (std::isdigit(ca) && std::isdigit(cb)) {
            std::size_t ie = i, je = j;
            while (ie < a.size() && std::isdigit(static_cast<unsigned char>(a[ie]))) ++ie;
            while (je < b.size() && std::isdigit(static_cast<unsigned char>(b[je]))) ++je;
            // Compare the digit runs by value: skip leading zeros, then length, then text.
            std::size_t is = i, js = j;
            while (is + 1 < ie && a[is] == '0') ++is;
            while (js + 1 < je && b[js] == '0') ++js;
            if (ie - is != je - js) return ie - is < je - js;
            int c = a.compare(is, ie - is, b, js, je - js);
            if (c != 0) return c < 0;
            i = ie;
            j = je;
        } else {
            int la = std::tolower(ca), lb = std::tolower(cb);
            if (la != lb) return la < lb;
            ++i;
            ++j;
        }
    }
    if (a.size() - i != b.size() - j) return a.size() - i < b.size() - j;
    return a < b;
}

}  // namespace splat::detail
