#pragma once
// One Zarr v2 array (https://zarr-specs.readthedocs.io/en/latest/v2/v2.0.html): its
// `.zarray` metadata and the reading of an axis-aligned box of it, chunk by chunk, into
// float samples (private, not installed). Only the chunks that intersect the box are read;
// a chunk file that does not exist holds the array's fill_value everywhere. Chunks are
// uncompressed, blosc (libblosc) or zlib/gzip; dtypes are the integers of 1 to 8 bytes,
// float32, float64 and bool, in either byte order; chunks in C or Fortran order.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace splat::detail::zarr {

enum class Codec { None, Blosc, Zlib };  ///< Zlib: zlib or gzip streams, auto-detected

struct Array {
    std::filesystem::path dir;  ///< the folder holding `.zarray` and the chunk files
    std::string name;           ///< its name in messages
    std::vector<std::int64_t> shape, chunks;
    std::string dtype;  ///< as written, e.g. "<u2"
    char kind = 'u';    ///< 'i', 'u', 'f' or 'b'
    int itemBytes = 1;  ///< 1, 2, 4 or 8
    bool bigEndian = false;
    bool fortran = false;  ///< "order": "F"
    char separator = '.';  ///< dimension_separator: '.' or '/'
    Codec codec = Codec::None;
    std::string compressor = "none";  ///< the compressor's id, for `splat info`
    double fill = 0.0;                ///< fill_value (null: 0)
    bool fillNull = true;             ///< fill_value was null

    std::size_t dims() const { return shape.size(); }
    /// Elements of one (full-size) chunk; edge chunks are stored at full size too.
    std::uint64_t chunkElements() const;
    /// Number of chunks along each axis.
    std::vector<std::int64_t> chunkGrid() const;
    /// The file of the chunk with grid index `c` (whether or not it exists).
    std::filesystem::path chunkPath(const std::vector<std::int64_t>& c) const;
};

/// Reads and checks `dir/.zarray`; throws splat::Error naming `name` and the problem (a
/// complex, structured or unknown dtype, an unsupported compressor or filter, a shape or
/// chunk size that does not fit 64-bit arithmetic or is not positive).
Array readArray(const std::filesystem::path& dir, const std::string& name);

/// Reads the box [lo, hi) of `a` (one bound per array axis) into `out`: the element at
/// array index p goes to out[sum over axes of (p[d] - lo[d]) * stride[d]]. Chunks are read
/// in parallel (each writes its own part of `out`, so the result does not depend on the
/// order). Throws splat::Error for a chunk that is unreadable, decompresses to the wrong
/// size or is truncated.
void readBox(const Array& a, const std::vector<std::int64_t>& lo,
             const std::vector<std::int64_t>& hi, const std::vector<std::int64_t>& stride,
             float* out);

/// True when every chunk of `a` that intersects [lo, hi) has a file (stat only).
bool allChunksStored(const Array& a, const std::vector<std::int64_t>& lo,
                     const std::vector<std::int64_t>& hi);

}  // namespace splat::detail::zarr
