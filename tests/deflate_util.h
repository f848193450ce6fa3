#pragma once
// gzip (or zlib) compression of test data, for the loader tests and the fuzzing seeds.
#include <zlib.h>

#include <string>

namespace splat::test {

/// `in` compressed as one gzip member (gzip = true) or a zlib stream.
inline std::string deflateBytes(const std::string& in, bool gzip) {
    z_stream zs{};
    deflateInit2(&zs, Z_DEFAULT_COMPRESSION, Z_DEFLATED, gzip ? 15 + 16 : 15, 8,
                 Z_DEFAULT_STRATEGY);
    std::string out(deflateBound(&zs, uLong(in.size())) + 32, '\0');
    zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(in.data()));
    zs.avail_in = uInt(in.size());
    zs.next_out = reinterpret_cast<Bytef*>(out.data());
    zs.avail_out = uInt(out.size());
    deflate(&zs, Z_FINISH);
    out.resize(zs.total_out);
    deflateEnd(&zs);
    return out;
}

}  // namespace splat::test
