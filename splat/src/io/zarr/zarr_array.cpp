// Zarr v2 arrays: `.zarray` parsing and box reads chunk by chunk (zarr_array.h).
#include "io/zarr/zarr_array.h"

#include <blosc.h>
#include <tbb/parallel_for.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "io/volume_detail.h"
#include "splat/error.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace splat::detail::zarr {
namespace {

/// Largest decompressed chunk read (2 GiB): a header asking for more is refused before any
/// allocation.
constexpr std::uint64_t kMaxChunkBytes = std::uint64_t(1) << 31;

void parseDtype(Array& a, const json& dt) {
    if (!dt.is_string())
        throw Error(a.name + ": structured dtype " + dt.dump() +
                    " is not supported (splat reads one scalar per element)");
    const std::string s = dt.get<std::string>();
    a.dtype = s;
    const auto bad = [&](const std::string& why) {
        return Error(a.name + ": dtype '" + s + "' is not supported (" + why + ")");
    };
    if (s.size() < 3) throw bad("unknown dtype");
    const char order = s[0];
    if (order != '<' && order != '>' && order != '|' && order != '=') throw bad("unknown dtype");
    a.bigEndian = order == '>' || (order == '=' && std::endian::native == std::endian::big);
    a.kind = s[1];
    const std::string size = s.substr(2);
    if (size.find_first_not_of("0123456789") != std::string::npos) throw bad("unknown dtype");
    if (a.kind == 'c') throw bad("complex samples; splat renders real scalars");
    const int n = size.size() <= 2 ? std::stoi(size) : 0;
    const bool ok = (a.kind == 'i' || a.kind == 'u') ? (n == 1 || n == 2 || n == 4 || n == 8)
                    : a.kind == 'f'                  ? (n == 4 || n == 8)
                    : a.kind == 'b'                  ? n == 1
                                                     : false;
    if (!ok)
        throw bad("splat reads int8 to int64, uint8 to uint64, float32, float64 and bool samples");
    a.itemBytes = n;
}

void parseCompressor(Array& a, const json& c) {
    if (c.is_null()) return;
    if (!c.is_object() || !c.contains("id") || !c["id"].is_string())
        throw Error(a.name + ": compressor " + c.dump() + " has no id");
    a.compressor = c["id"].get<std::string>();
    if (a.compressor == "blosc")
        a.codec = Codec::Blosc;
    else if (a.compressor == "zlib" || a.compressor == "gzip")
        a.codec = Codec::Zlib;
    else
        throw Error(a.name + ": compressor '" + a.compressor +
                    "' is not supported (splat reads blosc, zlib, gzip and uncompressed chunks)");
}

double parseFill(const Array& a, const json& f) {
    if (f.is_number()) return f.get<double>();
    if (f.is_boolean()) return f.get<bool>() ? 1.0 : 0.0;
    if (f.is_string()) {
        const std::string s = f.get<std::string>();
        if (s == "NaN") return std::numeric_limits<double>::quiet_NaN();
        if (s == "Infinity") return std::numeric_limits<double>::infinity();
        if (s == "-Infinity") return -std::numeric_limits<double>::infinity();
    }
    throw Error(a.name + ": fill_value " + f.dump() + " is not a number");
}

std::vector<std::int64_t> sizes(const Array& a, const json& j, const char* field, bool positive) {
    if (!j.contains(field) || !j[field].is_array() || j[field].empty())
        throw Error(a.name + ": '" + field + "' is missing or not a list of sizes");
    std::vector<std::int64_t> out;
    for (const json& n : j[field]) {
        if (!n.is_number_integer() || n.get<std::int64_t>() < (positive ? 1 : 0) ||
            n.get<std::int64_t>() > (std::int64_t(1) << 40))
            throw Error(a.name + ": '" + field + "' holds an invalid size " + n.dump());
        out.push_back(n.get<std::int64_t>());
    }
    return out;
}

// ---- decoding ---------------------------------------------------------------------

template <typename T>
T load(const unsigned char* p, bool swap) {
    T v;
    if (swap) {
        unsigned char b[sizeof(T)];
        for (std::size_t i = 0; i < sizeof(T); ++i) b[i] = p[sizeof(T) - 1 - i];
        std::memcpy(&v, b, sizeof(T));
    } else {
        std::memcpy(&v, p, sizeof(T));
    }
    return v;
}

/// `count` elements from `src` (every `srcStep` elements) into dst (every `dstStep`).
template <typename T>
void decodeRun(const unsigned char* src, std::int64_t srcStep, std::int64_t count, bool swap,
               float* dst, std::int64_t dstStep) {
    for (std::int64_t n = 0; n < count; ++n)
        dst[n * dstStep] = float(load<T>(src + std::size_t(n * srcStep) * sizeof(T), swap));
}

using RunDecoder = void (*)(const unsigned char*, std::int64_t, std::int64_t, bool, float*,
                            std::int64_t);

RunDecoder decoderOf(const Array& a) {
    switch (a.kind) {
        case 'b':
        case 'u':
            return a.itemBytes == 1   ? decodeRun<std::uint8_t>
                   : a.itemBytes == 2 ? decodeRun<std::uint16_t>
                   : a.itemBytes == 4 ? decodeRun<std::uint32_t>
                                      : decodeRun<std::uint64_t>;
        case 'i':
            return a.itemBytes == 1   ? decodeRun<std::int8_t>
                   : a.itemBytes == 2 ? decodeRun<std::int16_t>
                   : a.itemBytes == 4 ? decodeRun<std::int32_t>
                                      : decodeRun<std::int64_t>;
        default:
            return a.itemBytes == 4 ? decodeRun<float> : decodeRun<double>;
    }
}

std::string chunkKey(const std::vector<std::int64_t>& c, char separator) {
    std::string key;
    for (std::size_t d = 0; d < c.size(); ++d) {
        if (d) key += separator;
        key += std::to_string(c[d]);
    }
    return key;
}

/// The decompressed bytes of the chunk file `p` (exactly `bytes` of them).
std::vector<unsigned char> readChunk(const Array& a, const fs::path& p, std::uint64_t bytes) {
    const std::string what = displayName(p);
    if (a.codec == Codec::None) {
        const std::uint64_t size = regularFileSize(p);
        if (size != bytes)
            throw Error(what + ": uncompressed chunk holds " + std::to_string(size) +
                        " bytes, expected " + std::to_string(bytes));
        return readFileRange(p, 0, bytes);
    }
    const std::vector<unsigned char> packed = readFileBytes(p);
    std::vector<unsigned char> out;
    if (a.codec == Codec::Zlib) {
        out = inflateAll(packed.data(), packed.size(), what, std::size_t(bytes));
    } else {
        std::size_t nbytes = 0;
        if (blosc_cbuffer_validate(packed.data(), packed.size(), &nbytes) < 0)
            throw Error(what + ": corrupt blosc data (invalid header or truncated)");
        if (nbytes != bytes)
            throw Error(what + ": chunk decompresses to " + std::to_string(nbytes) +
                        " bytes, expected " + std::to_string(bytes) + " (chunk shape x " + a.dtype +
                        ")");
        out.resize(std::size_t(bytes));
        const int got = blosc_decompress_ctx(packed.data(), out.data(), out.size(), 1);
        if (got < 0 || std::uint64_t(got) != bytes)
            throw Error(what + ": corrupt blosc data (decompression failed)");
    }
    if (out.size() != bytes)
        throw Error(what + ": chunk decompresses to " + std::to_string(out.size()) +
                    " bytes, expected " + std::to_string(bytes) + " (chunk shape x " + a.dtype +
                    ")");
    return out;
}

}  // namespace

std::uint64_t Array::chunkElements() const {
    std::uint64_t n = 1;
    for (std::int64_t c : chunks) n = checkedMul(n, std::uint64_t(c), name);
    return n;
}

std::vector<std::int64_t> Array::chunkGrid() const {
    std::vector<std::int64_t> g(dims());
    for (std::size_t d = 0; d < dims(); ++d) g[d] = (shape[d] + chunks[d] - 1) / chunks[d];
    return g;
}

fs::path Array::chunkPath(const std::vector<std::int64_t>& c) const {
    return dir / chunkKey(c, separator);
}

Array readArray(const fs::path& dir, const std::string& name) {
    Array a;
    a.dir = dir;
    a.name = name;
    const fs::path meta = dir / ".zarray";
    json j;
    {
        const std::vector<unsigned char> text = readFileBytes(meta);
        j = json::parse(text.begin(), text.end(), nullptr, false);
        if (j.is_discarded() || !j.is_object()) throw Error(displayName(meta) + ": not valid JSON");
    }
    if (!j.contains("zarr_format") || j["zarr_format"] != 2)
        throw Error(displayName(meta) + ": zarr_format is not 2 (splat reads Zarr v2 arrays)");
    a.shape = sizes(a, j, "shape", false);
    a.chunks = sizes(a, j, "chunks", true);
    if (a.chunks.size() != a.shape.size())
        throw Error(name + ": 'chunks' has " + std::to_string(a.chunks.size()) +
                    " sizes for a shape of " + std::to_string(a.shape.size()));
    parseDtype(a, j.value("dtype", json()));
    parseCompressor(a, j.value("compressor", json()));
    const json filters = j.value("filters", json());
    if (!filters.is_null() && !(filters.is_array() && filters.empty()))
        throw Error(name + ": filters " + filters.dump() + " are not supported");
    const std::string order = j.value("order", std::string("C"));
    if (order != "C" && order != "F") throw Error(name + ": order '" + order + "' is not C or F");
    a.fortran = order == "F";
    const std::string sep = j.value("dimension_separator", std::string("."));
    if (sep != "." && sep != "/")
        throw Error(name + ": dimension_separator '" + sep + "' is not '.' or '/'");
    a.separator = sep[0];
    const json fill = j.value("fill_value", json());
    a.fillNull = fill.is_null();
    if (!a.fillNull) a.fill = parseFill(a, fill);
    const std::uint64_t bytes = checkedMul(a.chunkElements(), std::uint64_t(a.itemBytes), name);
    if (bytes > kMaxChunkBytes)
        throw Error(name + ": chunks of " + std::to_string(bytes) +
                    " bytes are larger than splat reads (2 GiB)");
    return a;
}

void readBox(const Array& a, const std::vector<std::int64_t>& lo,
             const std::vector<std::int64_t>& hi, const std::vector<std::int64_t>& stride,
             float* out) {
    const std::size_t n = a.dims();
    // The chunks intersecting the box, as a list (read in parallel).
    std::vector<std::int64_t> c0(n), c1(n);
    std::uint64_t count = 1;
    for (std::size_t d = 0; d < n; ++d) {
        if (lo[d] >= hi[d]) return;
        c0[d] = lo[d] / a.chunks[d];
        c1[d] = (hi[d] - 1) / a.chunks[d] + 1;
        count *= std::uint64_t(c1[d] - c0[d]);
    }
    // Element strides within a chunk.
    std::vector<std::int64_t> cs(n, 1);
    if (a.fortran)
        for (std::size_t d = 1; d < n; ++d) cs[d] = cs[d - 1] * a.chunks[d - 1];
    else
        for (std::size_t d = n - 1; d-- > 0;) cs[d] = cs[d + 1] * a.chunks[d + 1];
    const std::uint64_t chunkBytes = a.chunkElements() * std::uint64_t(a.itemBytes);
    const RunDecoder decode = decoderOf(a);
    const bool swap = a.bigEndian != (std::endian::native == std::endian::big) && a.itemBytes > 1;
    const float fill = float(a.fill);

    tbb::parallel_for(std::uint64_t(0), count, [&](std::uint64_t index) {
        std::vector<std::int64_t> c(n), ilo(n), ihi(n);
        for (std::size_t d = n; d-- > 0;) {
            const std::uint64_t span = std::uint64_t(c1[d] - c0[d]);
            c[d] = c0[d] + std::int64_t(index % span);
            index /= span;
            ilo[d] = std::max(lo[d], c[d] * a.chunks[d]);
            ihi[d] = std::min(hi[d], (c[d] + 1) * a.chunks[d]);
        }
        const fs::path p = a.chunkPath(c);
        std::error_code ec;
        const bool stored = fs::exists(p, ec);
        std::vector<unsigned char> bytes;
        if (stored) bytes = readChunk(a, p, chunkBytes);
        // Every run along the last axis of the intersection.
        const std::size_t last = n - 1;
        const std::int64_t run = ihi[last] - ilo[last];
        std::vector<std::int64_t> p0(ilo);
        while (true) {
            std::int64_t at = 0, src = 0;
            for (std::size_t d = 0; d < n; ++d) {
                at += (p0[d] - lo[d]) * stride[d];
                src += (p0[d] - c[d] * a.chunks[d]) * cs[d];
            }
            float* dst = out + at;
            if (stored)
                decode(bytes.data() + std::size_t(src) * std::size_t(a.itemBytes), cs[last], run,
                       swap, dst, stride[last]);
            else
                for (std::int64_t m = 0; m < run; ++m) dst[m * stride[last]] = fill;
            std::size_t d = last;
            while (d-- > 0) {
                if (++p0[d] < ihi[d]) break;
                p0[d] = ilo[d];
            }
            if (d == std::size_t(-1)) break;
        }
    });
}

bool allChunksStored(const Array& a, const std::vector<std::int64_t>& lo,
                     const std::vector<std::int64_t>& hi) {
    const std::size_t n = a.dims();
    std::vector<std::int64_t> c0(n), c1(n), c(n);
    for (std::size_t d = 0; d < n; ++d) {
        if (lo[d] >= hi[d]) return true;
        c0[d] = lo[d] / a.chunks[d];
        c1[d] = (hi[d] - 1) / a.chunks[d] + 1;
    }
    c = c0;
    while (true) {
        std::error_code ec;
        if (!fs::exists(a.chunkPath(c), ec)) return false;
        std::size_t d = n;
        while (d-- > 0) {
            if (++c[d] < c1[d]) break;
            c[d] = c0[d];
        }
        if (d == std::size_t(-1)) return true;
    }
}

}  // namespace splat::detail::zarr
