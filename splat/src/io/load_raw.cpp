// Headerless .raw (and gzip-compressed .raw.gz) files: the caller says dims/type/spacing/
// byte order (RawOptions), or the name does, as in skull_256x256x256_uint8.raw
// ("NAME_XxYxZ_TYPE.raw"). Sizes are checked in 64-bit arithmetic against the file before
// anything is allocated; a .raw.gz is inflated no further than the size it must hold.
#include <regex>

#include "splat/error.h"
#include "volume_detail.h"

namespace fs = std::filesystem;

namespace splat::detail {

RawLayout rawLayout(const fs::path& p, const RawOptions& options) {
    const std::string name = displayName(p);

    std::optional<glm::ivec3> dims = options.dims;
    std::string typeName = options.type;
    // Name convention: ..._<X>x<Y>x<Z>_<type>.raw (type may be omitted if given).
    static const std::regex pattern(R"(.*?(\d+)x(\d+)x(\d+)(?:_([A-Za-z0-9]+))?\.raw(\.gz)?$)",
                                    std::regex::icase);
    std::smatch m;
    const std::string file = p.filename().string();
    if (std::regex_match(file, m, pattern)) {
        if (!dims) {
            glm::ivec3 d;
            for (int a = 0; a < 3; ++a) {
                long long n = std::atoll(m[std::size_t(a + 1)].str().c_str());
                if (n > 2147483647LL)
                    throw Error(name + ": dimension " + m[std::size_t(a + 1)].str() + " too large");
                d[a] = int(n);
            }
            dims = d;
        }
        if (typeName.empty() && m[4].matched) typeName = m[4].str();
    }
    if (!dims || typeName.empty())
        throw Error(name +
                    ": raw data needs --dims and --type (or a name like "
                    "skull_256x256x256_uint8.raw)");
    auto type = parseSampleType(typeName);
    if (!type)
        throw Error(name + ": unsupported sample type '" + typeName +
                    "' (uint8, int8, uint16, int16, uint32, int32, float32, float64)");
    (void)volumeBytes(*dims, *type, name);  // dimensions and count checked
    return {*dims, *type, options.headerBytes};
}

Volume loadRaw(const fs::path& p, const RawOptions& options) {
    const std::string name = displayName(p);
    const std::uint64_t fileSize = regularFileSize(p);
    const bool gz = lowerExtension(p) == ".raw.gz";
    const RawLayout L = rawLayout(p, options);
    const std::optional<glm::ivec3> dims = L.dims;
    const std::optional<SampleType> type = L.type;
    const std::string file = p.filename().string();
    const std::size_t dataBytes = volumeBytes(*dims, *type, name);
    const std::uint64_t expected = checkedAdd(options.headerBytes, dataBytes, name);
    std::vector<unsigned char> bytes;
    if (gz) {
        std::vector<unsigned char> packed = readFileBytes(p);
        bytes = inflateAll(packed.data(), packed.size(), name, std::size_t(expected));
        checkDataLength(std::size_t(expected), bytes.size(), name, true);
    } else {
        checkDataLength(std::size_t(expected), std::size_t(fileSize), name, true);
        bytes = readFileRange(p, options.headerBytes, dataBytes);
    }
    const unsigned char* data = bytes.data() + (gz ? options.headerBytes : 0);
    Volume v = makeVolume(*dims, options.spacing.value_or(glm::dvec3(1.0)), name);
    decodeSamples(data, v.voxelCount(), *type, options.bigEndian, v.data.data());
    v.source =
        std::string("raw ") + sampleTypeName(*type) +
        (sampleSize(*type) > 1 ? (options.bigEndian ? " big-endian" : " little-endian") : "") +
        (gz ? " gzip" : "") + " (" + file + ")";
    return v;
}

}  // namespace splat::detail
