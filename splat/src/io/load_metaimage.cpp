// MetaImage (ITK/VTK): .mhd header with a separate data file, or .mha with the data
// after the header ("ElementDataFile = LOCAL").
//
// The header is "Key = Value" lines; ElementDataFile is the last one. Keys we use:
// NDims (2 or 3), DimSize, ElementType (MET_UCHAR, MET_CHAR, MET_SHORT, MET_USHORT,
// MET_INT, MET_UINT, MET_FLOAT, MET_DOUBLE), ElementSpacing, Offset (alias Origin,
// Position), TransformMatrix (row a = direction of index axis a, as ITK writes it),
// BinaryDataByteOrderMSB (alias ElementByteOrderMSB), CompressedData (zlib stream),
// HeaderSize (bytes to skip in the data file, -1 = data at the end).
//
// Its physical space is LPS, as ITK (and so SimpleITK, 3D Slicer, elastix) writes it:
// TransformMatrix and Offset are LPS and AnatomicalOrientation only names the matrix's
// axes; both are turned into splat's world frame, RAS (docs/design.md "World frame").
#include <cmath>
#include <map>
#include <sstream>

#include "sample_layout.h"
#include "splat/error.h"
#include "volume_detail.h"

namespace fs = std::filesystem;

namespace splat::detail {
namespace {

std::optional<SampleType> metaType(const std::string& s) {
    static const std::map<std::string, SampleType> types = {
        {"MET_UCHAR", SampleType::U8},   {"MET_CHAR", SampleType::I8},
        {"MET_USHORT", SampleType::U16}, {"MET_SHORT", SampleType::I16},
        {"MET_UINT", SampleType::U32},   {"MET_INT", SampleType::I32},
        {"MET_ULONG", SampleType::U32},  {"MET_LONG", SampleType::I32},
        {"MET_FLOAT", SampleType::F32},  {"MET_DOUBLE", SampleType::F64}};
    auto it = types.find(s);
    if (it == types.end()) return std::nullopt;
    return it->second;
}

std::vector<double> numbers(const std::string& s, const std::string& what, const std::string& key) {
    std::istringstream in(s);
    std::vector<double> out;
    double d;
    while (in >> d) out.push_back(d);
    if (!in.eof()) throw Error(what + ": bad MetaImage " + key + " '" + s + "'");
    return out;
}

// ITK's orientation code of a direction matrix: per index axis the letter of the side it
// comes FROM in LPS space (+x runs from R, +y from A, +z from I), so the identity is "RAI".
std::string impliedOrientation(const glm::dmat3& dirs, int ndims) {
    static const char from[3][2] = {{'R', 'L'}, {'A', 'P'}, {'I', 'S'}};
    std::string code;
    for (int a = 0; a < ndims; ++a) {
        int best = 0;
        for (int r = 1; r < 3; ++r)
            if (std::abs(dirs[a][r]) > std::abs(dirs[a][best])) best = r;
        code += from[best][dirs[a][best] < 0 ? 1 : 0];
    }
    return code;
}

bool isTrue(const std::string& s) {
    std::string l = toLower(s);
    return l == "true" || l == "1" || l == "yes";
}

/// The header's keys (lower case) up to ElementDataFile, the last one.
struct MetaHeader {
    std::map<std::string, std::string> keys;
    std::size_t pos = 0;  ///< first byte after the header
    bool sawDataFile = false;
};

MetaHeader parseMetaHeader(const std::vector<unsigned char>& file, const std::string& name) {
    MetaHeader h;
    std::size_t& pos = h.pos;
    while (pos < file.size() && !h.sawDataFile) {
        std::size_t eol = pos;
        while (eol < file.size() && file[eol] != '\n') ++eol;
        std::string line(file.begin() + std::ptrdiff_t(pos), file.begin() + std::ptrdiff_t(eol));
        pos = std::min(eol + 1, file.size());
        line = trim(line);
        if (line.empty()) continue;
        std::size_t eq = line.find('=');
        if (eq == std::string::npos)
            throw Error(name + ": bad MetaImage header line '" + line.substr(0, 60) + "'");
        std::string key = toLower(trim(line.substr(0, eq)));
        h.keys[key] = trim(line.substr(eq + 1));
        if (key == "elementdatafile") h.sawDataFile = true;
    }
    return h;
}

/// What the header says, and where the data is (`dataFile` empty: LOCAL, after the header).
struct MetaParsed {
    SampleLayout layout;  ///< file, start and codec not set
    std::size_t expected = 0;
    bool compressed = false;
    std::optional<fs::path> dataFile;
    long long headerSize = 0;
    std::optional<std::size_t> compressedSize;
};

MetaParsed metaParse(const fs::path& p, const LoadOptions& options, const MetaHeader& header) {
    const std::string name = displayName(p);
    const std::map<std::string, std::string>& keys = header.keys;
    const bool sawDataFile = header.sawDataFile;
    auto get = [&](const char* k) {
        auto it = keys.find(k);
        return it == keys.end() ? std::string() : it->second;
    };
    if (!sawDataFile) throw Error(name + ": MetaImage header has no ElementDataFile");
    if (get("ndims").empty() || get("dimsize").empty() || get("elementtype").empty())
        throw Error(name + ": MetaImage header lacks NDims, DimSize or ElementType");

    int ndims = std::atoi(get("ndims").c_str());
    if (ndims != 2 && ndims != 3)
        throw Error(name + ": MetaImage NDims " + get("ndims") + " not supported (need 2 or 3)");
    if (!get("elementnumberofchannels").empty() &&
        std::atoi(get("elementnumberofchannels").c_str()) != 1)
        throw Error(name + ": MetaImage with " + get("elementnumberofchannels") +
                    " channels per voxel not supported (need scalar data)");
    auto type = metaType(get("elementtype"));
    if (!type)
        throw Error(name + ": unsupported MetaImage ElementType '" + get("elementtype") + "'");
    std::vector<double> size = numbers(get("dimsize"), name, "DimSize");
    if (int(size.size()) != ndims)
        throw Error(name + ": DimSize has " + std::to_string(size.size()) + " entries, NDims is " +
                    std::to_string(ndims));
    glm::ivec3 dims(1);
    for (int a = 0; a < ndims; ++a)
        dims[a] = dimensionFrom(size[a], name, "MetaImage DimSize", get("dimsize"));
    // Every size check before anything is allocated (64-bit, no wrap).
    const std::size_t expected = volumeBytes(dims, *type, name);
    std::vector<std::string> notes;

    // Geometry.
    glm::dvec3 spacing(1.0), origin(0.0);
    std::string sp = get("elementspacing");
    if (sp.empty()) sp = get("elementsize");
    if (!sp.empty()) {
        auto s = numbers(sp, name, "ElementSpacing");
        if (int(s.size()) != ndims)
            throw Error(name + ": ElementSpacing has " + std::to_string(s.size()) +
                        " entries, NDims is " + std::to_string(ndims));
        for (int a = 0; a < ndims; ++a) spacing[a] = s[std::size_t(a)];
    }
    for (const char* k : {"offset", "origin", "position"})
        if (!get(k).empty()) {
            auto o = numbers(get(k), name, k);
            if (int(o.size()) != ndims)
                throw Error(name + ": MetaImage " + k + " has " + std::to_string(o.size()) +
                            " entries, NDims is " + std::to_string(ndims));
            for (int a = 0; a < ndims; ++a) origin[a] = o[std::size_t(a)];
            break;
        }
    for (int a = 0; a < 3; ++a)
        if (!std::isfinite(origin[a])) throw Error(name + ": MetaImage Offset is not finite");
    glm::dmat3 dirs(1.0);
    bool haveMatrix = false;
    for (const char* k : {"transformmatrix", "rotation", "orientation"})
        if (!get(k).empty()) {
            auto m = numbers(get(k), name, k);
            if (int(m.size()) != ndims * ndims)
                throw Error(name + ": MetaImage TransformMatrix has " + std::to_string(m.size()) +
                            " entries, NDims " + std::to_string(ndims) + " needs " +
                            std::to_string(ndims * ndims));
            for (int a = 0; a < ndims; ++a)
                for (int r = 0; r < ndims; ++r) dirs[a][r] = m[std::size_t(a * ndims + r)];
            haveMatrix = true;
            break;
        }
    for (int a = 0; a < 3; ++a)
        if (!std::isfinite(spacing[a]) || spacing[a] <= 0)
            throw Error(name + ": invalid MetaImage ElementSpacing '" + sp + "'");
    // LPS -> RAS: x and y negated.
    const glm::dvec3 lpsToRas(-1.0, -1.0, 1.0);
    glm::dmat3 M;
    for (int a = 0; a < 3; ++a) M[a] = lpsToRas * dirs[a] * spacing[a];
    // AnatomicalOrientation repeats what the matrix says (ITK's "from" letters, identity =
    // RAI); the matrix decides. A disagreement is worth a warning, an invalid code an error.
    const std::string anat = toLower(get("anatomicalorientation"));
    if (!anat.empty() && anat != "?" && anat != "???") {
        const std::string implied = impliedOrientation(dirs, ndims);
        std::string code = anat;
        for (char& c : code) c = char(std::toupper(static_cast<unsigned char>(c)));
        if (code.size() == 3 && ndims == 2) code.pop_back();  // some writers add a 3rd letter
        if (code.size() != std::size_t(ndims) ||
            code.find_first_not_of("RLAPSI") != std::string::npos)
            throw Error(name + ": invalid MetaImage AnatomicalOrientation '" +
                        get("anatomicalorientation") + "'");
        if (code != implied)
            notes.push_back("MetaImage AnatomicalOrientation " + code + " disagrees with " +
                            (haveMatrix ? "the TransformMatrix" : "the identity orientation") +
                            " (" + implied + "); the matrix was used");
    }

    // Data.
    MetaParsed P;
    std::string byteOrder = get("binarydatabyteordermsb");
    if (byteOrder.empty()) byteOrder = get("elementbyteordermsb");
    const bool bigEndian = isTrue(byteOrder);
    P.compressed = isTrue(get("compresseddata"));
    std::string dataFile = get("elementdatafile");
    if (toLower(dataFile) != "local") {
        if (toLower(dataFile).rfind("list", 0) == 0 || dataFile.find('%') != std::string::npos)
            throw Error(name + ": multi-file MetaImage data ('" + dataFile + "') is not supported");
        P.dataFile = resolveDataFile(p, dataFile, options.allowOutsideDataFiles);
        if (!get("headersize").empty()) {
            auto h = numbers(get("headersize"), name, "HeaderSize");
            if (h.size() != 1 || !(h[0] >= -1 && h[0] <= 9.0e15) || h[0] != std::floor(h[0]))
                throw Error(name + ": bad MetaImage HeaderSize '" + get("headersize") + "'");
            P.headerSize = (long long)h[0];
        }
    }
    if (P.compressed) {
        std::string csize = get("compresseddatasize");
        if (!csize.empty()) {
            auto c = numbers(csize, name, "CompressedDataSize");
            if (c.size() != 1 || !(c[0] >= 0 && c[0] <= 9.0e15) || c[0] != std::floor(c[0]))
                throw Error(name + ": bad MetaImage CompressedDataSize '" + csize + "'");
            P.compressedSize = std::size_t(c[0]);
        }
    }
    P.expected = expected;
    SampleLayout& L = P.layout;
    L.dims = dims;
    L.type = *type;
    L.bigEndian = bigEndian;
    L.exact = true;
    L.M = M;
    L.t = lpsToRas * origin;
    L.orientation = "TransformMatrix";
    L.name = name;
    L.source = std::string("MetaImage ") + sampleTypeName(*type) +
               (P.compressed ? " compressed" : "") + " (" + p.filename().string() + ")";
    L.notes = notes;
    return P;
}

/// The header of `p` (read whole: a .mhd is small, a .mha's data follows it).
MetaHeader readMetaHeader(const fs::path& p, const std::vector<unsigned char>* whole) {
    const std::string name = displayName(p);
    if (whole) return parseMetaHeader(*whole, name);
    const std::uint64_t size = regularFileSize(p);
    for (std::uint64_t n = std::min<std::uint64_t>(size, 1 << 16);; n = std::min(size, 4 * n)) {
        std::vector<unsigned char> prefix = readFileRange(p, 0, n);
        if (n < size) {  // whole lines only
            std::size_t end = prefix.size();
            while (end > 0 && prefix[end - 1] != '\n') --end;
            prefix.resize(end);
        }
        MetaHeader h = parseMetaHeader(prefix, name);
        if (h.sawDataFile || n == size) return h;
    }
}

}  // namespace

std::optional<SampleLayout> metaImageLayout(const fs::path& p, const LoadOptions& options) {
    const MetaHeader header = readMetaHeader(p, nullptr);
    const MetaParsed P = metaParse(p, options, header);
    SampleLayout L = P.layout;
    L.file = P.dataFile ? *P.dataFile : p;
    L.fileName = displayName(L.file);
    const std::uint64_t size = regularFileSize(L.file);
    const std::uint64_t dataStart = P.dataFile ? 0 : header.pos;
    const std::uint64_t available = size - std::min(size, dataStart);
    if (P.compressed) {
        L.codec = SampleLayout::Codec::Gzip;
        L.start = dataStart;
        if (P.compressedSize) {
            checkDataLength(*P.compressedSize, std::size_t(available), L.fileName, false);
            L.streamBytes = *P.compressedSize;
        }
    } else if (P.headerSize > 0) {
        checkDataLength(std::size_t(P.headerSize), std::size_t(available), L.fileName, false);
        L.start = dataStart + std::uint64_t(P.headerSize);
    } else if (P.headerSize == -1) {
        checkDataLength(P.expected, std::size_t(available), L.fileName, false);
        L.start = size - P.expected;
    } else {
        L.start = dataStart;
    }
    return L;
}

Volume loadMetaImage(const fs::path& p, const LoadOptions& options) {
    const std::string name = displayName(p);
    std::vector<unsigned char> file = readFileBytes(p);
    const MetaHeader header = readMetaHeader(p, &file);
    const MetaParsed P = metaParse(p, options, header);
    const std::size_t expected = P.expected;
    const bool compressed = P.compressed;
    const SampleLayout& L = P.layout;
    std::vector<unsigned char> separate;
    const unsigned char* data;
    std::size_t dataSize;
    std::string dataName = name;
    if (!P.dataFile) {
        data = file.data() + header.pos;
        dataSize = file.size() - header.pos;
    } else {
        dataName = displayName(*P.dataFile);
        separate = readFileBytes(*P.dataFile);
        data = separate.data();
        dataSize = separate.size();
        const long long headerSize = P.headerSize;
        if (headerSize > 0 && !compressed) {
            checkDataLength(std::size_t(headerSize), dataSize, dataName, false);
            data += headerSize;
            dataSize -= std::size_t(headerSize);
        } else if (headerSize == -1 && !compressed) {
            checkDataLength(expected, dataSize, dataName, false);
            data += dataSize - expected;
            dataSize = expected;
        }
    }
    std::vector<unsigned char> inflated;
    if (compressed) {
        if (P.compressedSize) {
            checkDataLength(*P.compressedSize, dataSize, dataName, false);
            dataSize = *P.compressedSize;
        }
        inflated = inflateAll(data, dataSize, dataName, expected);
        data = inflated.data();
        dataSize = inflated.size();
    }
    checkDataLength(expected, dataSize, dataName, true);
    Volume v = makeVolume(L.dims, glm::dvec3(1.0), name);
    decodeSamples(data, v.voxelCount(), L.type, L.bigEndian, v.data.data());
    v.source = L.source;
    applyOrientation(v, L.M, L.t, L.orientation);
    for (const std::string& n : L.notes) addNote(v, n);
    return v;
}

}  // namespace splat::detail
