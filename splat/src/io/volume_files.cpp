// File helpers shared by the loaders and writers: whole-file reads with clear errors,
// gzip/zlib inflation, atomic writes, extensions and natural sort order.
#include <zlib.h>

#include <algorithm>
#include <cctype>
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

std::vector<unsigned char> readFileBytes(const fs::path& p) {
    std::error_code ec;
    if (!fs::exists(p, ec)) throw Error(displayName(p) + ": no such file");
    if (fs::is_directory(p, ec)) throw Error(displayName(p) + ": is a folder, expected a file");
    std::ifstream in(p, std::ios::binary);
    if (!in) throw Error(displayName(p) + ": cannot open for reading");
    in.seekg(0, std::ios::end);
    std::streamoff size = in.tellg();
    if (size < 0) throw Error(displayName(p) + ": cannot read");
    in.seekg(0);
    std::vector<unsigned char> bytes(static_cast<std::size_t>(size));
    if (size > 0 && !in.read(reinterpret_cast<char*>(bytes.data()), size))
        throw Error(displayName(p) + ": cannot read");
    return bytes;
}

std::vector<unsigned char> inflateAll(const unsigned char* data, std::size_t size,
                                      const std::string& what) {
    z_stream zs{};
    // 15 + 32: accept both gzip and zlib headers.
    if (inflateInit2(&zs, 15 + 32) != Z_OK) throw Error(what + ": cannot initialise zlib");
    std::vector<unsigned char> out;
    out.resize(std::max<std::size_t>(size * 4, 1 << 16));
    std::size_t inPos = 0;
    int ret = Z_OK;
    while (true) {
        if (zs.avail_in == 0 && inPos < size) {
            std::size_t chunk = std::min<std::size_t>(size - inPos, 1u << 30);
            zs.next_in = const_cast<unsigned char*>(data + inPos);
            zs.avail_in = static_cast<uInt>(chunk);
            inPos += chunk;
        }
        if (zs.total_out == out.size()) out.resize(out.size() * 2);
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
    if (ret != Z_STREAM_END) throw Error(what + ": corrupt gzip data (" + reason + ")");
    out.resize(produced);
    return out;
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
