// NRRD (.nrrd with attached data, .nhdr with a detached data file).
//
// Format (http://teem.sourceforge.net/nrrd/format.html): a first line "NRRD000N", then
// "field: value" lines ("#" starts a comment, "key:=value" is a key/value pair we
// ignore). In a .nrrd the header ends at the first blank line and the data follows; a
// .nhdr names its data with "data file:" (relative to the header's folder). Fields we
// use: type, dimension (2 or 3; 4 for a time series along the last axis, whose kind is time
// or domain and which has no space direction), sizes, kinds, encoding (all five: raw,
// gzip/gz, bzip2/bz2, text/txt/ascii, hex), endian, spacings or space (or space dimension)
// with space directions and space origin, byte skip, line skip. LoadOptions::time picks the
// time step (the first by default). Geometry in a named space is turned
// into splat's world frame, RAS (docs/design.md "World frame").
#include <algorithm>
#include <cctype>
#include <cmath>
#include <initializer_list>
#include <map>
#include <optional>
#include <sstream>

#include "sample_layout.h"
#include "splat/error.h"
#include "volume_detail.h"

namespace fs = std::filesystem;

namespace splat::detail {
namespace {

// Parses "(a,b,c)" vectors of `n` components separated by spaces; "none" entries become
// nullopt.
std::vector<std::optional<std::vector<double>>> parseVectors(const std::string& s, std::size_t n,
                                                             const std::string& what) {
    std::vector<std::optional<std::vector<double>>> out;
    std::size_t i = 0;
    while (i < s.size()) {
        if (std::isspace(static_cast<unsigned char>(s[i]))) {
            ++i;
            continue;
        }
        if (s.compare(i, 4, "none") == 0) {
            out.push_back(std::nullopt);
            i += 4;
            continue;
        }
        if (s[i] != '(') throw Error(what + ": cannot parse vector list '" + s + "'");
        std::size_t close = s.find(')', i);
        if (close == std::string::npos)
            throw Error(what + ": cannot parse vector list '" + s + "'");
        std::string inner = s.substr(i + 1, close - i - 1);
        for (char& c : inner)
            if (c == ',') c = ' ';
        std::istringstream in(inner);
        std::vector<double> v;
        std::string word;
        while (in >> word) {
            char* end = nullptr;
            const double d = std::strtod(word.c_str(), &end);
            if (end == word.c_str() || *end)
                throw Error(what + ": cannot parse vector '" + inner + "'");
            v.push_back(d);
        }
        if (v.size() != n)
            throw Error(what + ": vector '(" + s.substr(i + 1, close - i - 1) + ")' has " +
                        std::to_string(v.size()) + " components, the space has " +
                        std::to_string(n));
        out.push_back(v);
        i = close + 1;
    }
    return out;
}

/// A NRRD space (format spec, "space"): its dimension and the signs that take its first
/// three coordinates to RAS. Spaces without anatomy (scanner-xyz, 3D-right-handed) are
/// taken as RAS; 3D-left-handed has its x negated so that the picture is not mirrored.
struct NrrdSpace {
    std::size_t dimension = 3;
    glm::dvec3 toRas{1.0};
    const char* note = nullptr;  ///< warning for a space without anatomical meaning
};

std::optional<NrrdSpace> nrrdSpace(const std::string& name) {
    const std::string n = toLower(name);
    auto is = [&](std::initializer_list<const char*> names) {
        for (const char* c : names)
            if (n == toLower(c)) return true;
        return false;
    };
    const glm::dvec3 ras(1, 1, 1), las(-1, 1, 1), lps(-1, -1, 1);
    if (is({"right-anterior-superior", "RAS"})) return NrrdSpace{3, ras, nullptr};
    if (is({"left-anterior-superior", "LAS"})) return NrrdSpace{3, las, nullptr};
    if (is({"left-posterior-superior", "LPS"})) return NrrdSpace{3, lps, nullptr};
    if (is({"right-anterior-superior-time", "RAST"})) return NrrdSpace{4, ras, nullptr};
    if (is({"left-anterior-superior-time", "LAST"})) return NrrdSpace{4, las, nullptr};
    if (is({"left-posterior-superior-time", "LPST"})) return NrrdSpace{4, lps, nullptr};
    const char* none = "NRRD space has no anatomical orientation: its axes are taken as RAS";
    const char* left =
        "NRRD space 3D-left-handed has no anatomical orientation: its x axis is negated to "
        "give a right-handed RAS frame";
    if (is({"scanner-xyz"})) return NrrdSpace{3, ras, none};
    if (is({"scanner-xyz-time"})) return NrrdSpace{4, ras, none};
    if (is({"3D-right-handed"})) return NrrdSpace{3, ras, none};
    if (is({"3D-right-handed-time"})) return NrrdSpace{4, ras, none};
    if (is({"3D-left-handed"})) return NrrdSpace{3, las, left};
    if (is({"3D-left-handed-time"})) return NrrdSpace{4, las, left};
    return std::nullopt;
}

/// The spatial part of a space vector: its first three components in RAS (a time space's
/// fourth component must be 0 for a spatial axis or the origin).
glm::dvec3 spatial(const std::vector<double>& v, const NrrdSpace& space, const std::string& what,
                   const std::string& field) {
    if (v.size() == 4 && v[3] != 0)
        throw Error(what + ": NRRD " + field + " has a time component (" + std::to_string(v[3]) +
                    ") on a spatial axis");
    glm::dvec3 out(0.0);
    for (std::size_t c = 0; c < std::min<std::size_t>(3, v.size()); ++c)
        out[int(c)] = v[c] * space.toRas[int(c)];
    return out;
}

/// NRRD hex encoding: two hex digits per byte (either case), whitespace anywhere between
/// bytes; exactly `expected` bytes, in the file's byte order.
std::vector<unsigned char> decodeHex(const unsigned char* data, std::size_t size,
                                     std::size_t expected, const std::string& what) {
    // Two characters per byte at least: a shorter text is refused before allocating.
    if (size / 2 < expected)
        throw Error(what + ": truncated data: " + std::to_string(expected) +
                    " bytes need at least " + std::to_string(2 * expected) +
                    " hex digits, the file holds " + std::to_string(size) + " characters");
    std::vector<unsigned char> out;
    out.reserve(expected);
    int high = -1;
    for (std::size_t i = 0; i < size; ++i) {
        const unsigned char c = data[i];
        if (std::isspace(c)) {
            if (high >= 0) throw Error(what + ": NRRD hex data splits a byte with white space");
            continue;
        }
        int d;
        if (c >= '0' && c <= '9')
            d = c - '0';
        else if (c >= 'a' && c <= 'f')
            d = c - 'a' + 10;
        else if (c >= 'A' && c <= 'F')
            d = c - 'A' + 10;
        else
            throw Error(what + ": NRRD hex data has a character that is not a hex digit at byte " +
                        std::to_string(i));
        if (high < 0) {
            high = d;
            continue;
        }
        if (out.size() == expected)
            throw Error(what + ": hex data holds more than the " + std::to_string(expected) +
                        " bytes the header describes");
        out.push_back((unsigned char)(high * 16 + d));
        high = -1;
    }
    if (high >= 0 || out.size() != expected)
        throw Error(what + ": truncated data: expected " + std::to_string(expected) +
                    " bytes of hex data, found " + std::to_string(out.size()));
    return out;
}

std::vector<double> parseNumbers(const std::string& s, const std::string& what,
                                 const std::string& field) {
    std::istringstream in(s);
    std::vector<double> out;
    std::string word;
    while (in >> word) {
        std::string w = toLower(word);
        if (w == "nan") {
            out.push_back(std::nan(""));
            continue;
        }
        char* end = nullptr;
        double d = std::strtod(word.c_str(), &end);
        if (end == word.c_str() || *end) throw Error(what + ": bad " + field + " '" + s + "'");
        out.push_back(d);
    }
    return out;
}

}  // namespace

namespace {

/// The header's fields, up to the first blank line (or the end of a detached header).
struct NrrdHeader {
    std::map<std::string, std::string> fields;
    std::size_t pos = 0;  ///< first byte after the header
    bool blankSeen = false;
};

NrrdHeader parseNrrdHeader(const std::vector<unsigned char>& file, const std::string& name) {
    const std::string magic(file.begin(), file.begin() + std::min<std::size_t>(file.size(), 7));
    if (magic.size() < 7 || magic.compare(0, 4, "NRRD") != 0)
        throw Error(name + ": not a NRRD file (missing NRRD000N magic line)");
    NrrdHeader h;
    std::size_t& pos = h.pos;
    bool first = true;
    while (pos < file.size()) {
        std::size_t eol = pos;
        while (eol < file.size() && file[eol] != '\n') ++eol;
        std::string line(file.begin() + std::ptrdiff_t(pos), file.begin() + std::ptrdiff_t(eol));
        if (!line.empty() && line.back() == '\r') line.pop_back();
        pos = std::min(eol + 1, file.size());
        if (first) {
            first = false;
            continue;
        }
        if (line.empty()) {
            h.blankSeen = true;
            break;
        }
        if (line[0] == '#') continue;
        if (line.find(":=") != std::string::npos) continue;  // key/value pair
        std::size_t colon = line.find(": ");
        if (colon == std::string::npos) throw Error(name + ": bad NRRD header line '" + line + "'");
        h.fields[toLower(trim(line.substr(0, colon)))] = trim(line.substr(colon + 2));
    }
    return h;
}

/// What the header says: the samples' type, size, orientation, encoding and where they are.
struct NrrdParsed {
    SampleLayout layout;  ///< file, start and codec not set
    std::size_t expected = 0;  ///< bytes of one time step
    std::size_t total = 0;     ///< bytes of every time step
    std::uint64_t step = 0;    ///< the time step to load
    bool gzip = false, bzip2 = false, text = false, hex = false;
    std::string encoding;
    long long byteSkip = 0, lineSkip = 0;
    std::optional<fs::path> dataFile;  ///< detached data
};

/// A header's fields by key, for the steps of nrrdParse.
struct NrrdFields {
    const std::map<std::string, std::string>& fields;
    const std::string& name;

    std::string operator()(const char* key) const {
        auto it = fields.find(key);
        return it == fields.end() ? std::string() : it->second;
    }
    std::string required(const char* key) const {
        std::string v = (*this)(key);
        if (v.empty()) throw Error(name + ": NRRD header has no '" + key + "' field");
        return v;
    }
};

/// The geometry of the header: space directions (with optional space origin) or per-axis
/// spacings, in RAS; `oriented` when space directions gave it.
void nrrdGeometry(const NrrdFields& field, int dimension, std::vector<std::string>& notes,
                  SampleLayout& L, bool& oriented) {
    const std::string& name = field.name;
    const int spatialAxes = std::min(dimension, 3);
    glm::dmat3 M(1.0);
    glm::dvec3 t(0.0);
    if (!field("space directions").empty() && !field("spacings").empty())
        throw Error(name +
                    ": NRRD header has both 'spacings' and 'space directions' (the format "
                    "forbids it: the two could disagree); keep one");
    // The space: a named one (converted to RAS) or "space dimension" (taken as RAS).
    NrrdSpace space;
    const bool haveSpace = !field("space").empty() || !field("space dimension").empty();
    if (!field("space").empty() && !field("space dimension").empty())
        throw Error(name +
                    ": NRRD header has both 'space' and 'space dimension' (the format "
                    "forbids it)");
    if (!field("space").empty()) {
        auto named = nrrdSpace(field("space"));
        if (!named) throw Error(name + ": unknown NRRD space '" + field("space") + "'");
        space = *named;
        if (space.note) notes.push_back(space.note);
    } else if (!field("space dimension").empty()) {
        const std::string sd = field("space dimension");
        if (sd != "2" && sd != "3")
            throw Error(name + ": NRRD space dimension " + sd + " not supported (need 2 or 3)");
        space.dimension = std::size_t(sd[0] - '0');
        if (!field("space directions").empty())
            notes.push_back("NRRD space has no anatomical orientation: its axes are taken as RAS");
    }
    if (!field("space directions").empty()) {
        if (!haveSpace)
            notes.push_back("NRRD 'space directions' without 'space': its axes are taken as RAS");
        auto dirs = parseVectors(field("space directions"), space.dimension, name);
        if (int(dirs.size()) != dimension)
            throw Error(name + ": 'space directions' has " + std::to_string(dirs.size()) +
                        " entries, dimension is " + std::to_string(dimension));
        if (dimension == 4 && dirs[3])
            throw Error(name +
                        ": NRRD 'space directions' gives the time axis (axis 3) a "
                        "direction; a time axis has 'none'");
        for (int a = 0; a < spatialAxes; ++a) {
            if (!dirs[a]) throw Error(name + ": 'space directions' is 'none' for a spatial axis");
            for (double c : *dirs[a])
                if (!std::isfinite(c))
                    throw Error(name + ": 'space directions' has a NaN or Inf vector for axis " +
                                std::to_string(a));
            M[a] = spatial(*dirs[a], space, name, "space directions");
            if (!(glm::length(M[a]) > 0))
                throw Error(name + ": 'space directions' has a zero vector for axis " +
                            std::to_string(a));
        }
        if (dimension == 2) M[2] = glm::normalize(glm::cross(M[0], M[1])) * glm::length(M[0]);
        oriented = true;
    } else if (!field("spacings").empty()) {
        auto sp = parseNumbers(field("spacings"), name, "spacings");
        if (int(sp.size()) != dimension)
            throw Error(name + ": 'spacings' has " + std::to_string(sp.size()) +
                        " entries, dimension is " + std::to_string(dimension));
        for (int a = 0; a < spatialAxes; ++a) {
            if (std::isnan(sp[a])) {
                // NRRD's own way to say "unknown spacing".
                notes.push_back("NRRD spacing of axis " + std::to_string(a) +
                                " is NaN (unknown): 1 assumed");
                continue;
            }
            if (!std::isfinite(sp[a]) || sp[a] == 0)
                throw Error(name + ": invalid NRRD spacings '" + field("spacings") +
                            "' (each must be finite and non-zero, or NaN for unknown)");
            M[a][a] = sp[a];  // a negative spacing is a flip, applied by applyOrientation
        }
    }
    if (!field("space origin").empty()) {
        auto o = parseVectors(field("space origin"), space.dimension, name);
        if (o.size() != 1 || !o[0])
            throw Error(name + ": bad NRRD space origin '" + field("space origin") + "'");
        for (double c : *o[0])
            if (!std::isfinite(c))
                throw Error(name + ": NRRD space origin '" + field("space origin") +
                            "' is not finite");
        t = spatial(*o[0], space, name, "space origin");
    }
    L.M = M;
    L.t = t;
}

/// A whole number of bytes or lines (NRRD byte skip, line skip) in [lo, 9e15].
long long nrrdSkip(const NrrdFields& field, const char* key, double lo) {
    if (field(key).empty()) return 0;
    std::vector<double> v = parseNumbers(field(key), field.name, key);
    if (v.size() != 1 || !(v[0] >= lo && v[0] <= 9.0e15) || v[0] != std::floor(v[0]))
        throw Error(field.name + ": bad NRRD " + key + " '" + field(key) + "'");
    return (long long)v[0];
}

/// The encoding, byte order and skips of the samples.
void nrrdEncoding(const NrrdFields& field, SampleType type, std::vector<std::string>& notes,
                  NrrdParsed& P) {
    const std::string& name = field.name;
    std::string encoding = toLower(field("encoding"));
    if (encoding.empty()) encoding = "raw";
    P.gzip = encoding == "gzip" || encoding == "gz";
    P.bzip2 = encoding == "bzip2" || encoding == "bz2";
    P.text = encoding == "text" || encoding == "txt" || encoding == "ascii";
    P.hex = encoding == "hex";
    if (!P.gzip && !P.bzip2 && !P.text && !P.hex && encoding != "raw")
        throw Error(name + ": unsupported NRRD encoding '" + encoding +
                    "' (the format's five: raw, gzip, bzip2, text, hex)");
    P.encoding = encoding;
    std::string endian = toLower(field("endian"));
    if (!endian.empty() && endian != "big" && endian != "little")
        throw Error(name + ": bad NRRD endian '" + endian + "'");
    if (endian.empty() && !P.text && sampleSize(type) > 1)
        notes.push_back("NRRD header has no 'endian' field: little-endian assumed for its " +
                        std::to_string(sampleSize(type)) + "-byte samples");
    P.layout.bigEndian = endian == "big";
    P.byteSkip = nrrdSkip(field, "byte skip", -1);
    if (P.byteSkip == -1 && !(encoding == "raw"))
        throw Error(name + ": NRRD byte skip -1 is only allowed with raw encoding");
    P.lineSkip = nrrdSkip(field, "line skip", 0);
}

/// Where the data is: a detached data file, or after the header's blank line.
void nrrdDataFile(const fs::path& p, const LoadOptions& options, const NrrdHeader& header,
                  const NrrdFields& field, NrrdParsed& P) {
    std::string dataFile = field("data file");
    if (dataFile.empty()) dataFile = field("datafile");
    if (!dataFile.empty()) {
        if (dataFile.rfind("LIST", 0) == 0 || dataFile.find('%') != std::string::npos)
            throw Error(field.name + ": multi-file NRRD data ('data file: " + dataFile +
                        "') is not supported");
        P.dataFile = resolveDataFile(p, dataFile, options.allowOutsideDataFiles);
    } else if (!header.blankSeen) {
        throw Error(field.name + ": NRRD header has no data (no blank line, no 'data file')");
    }
}

/// The number of time steps: a 4D NRRD is a time series along its last (slowest) axis, each
/// step a contiguous 3D volume. A vector or list axis (kind list, vector, RGB-color, ...) is
/// not one.
std::uint64_t nrrdSteps(const NrrdFields& field, int dimension, const std::vector<double>& sizes) {
    if (dimension != 4) return 1;
    std::istringstream kinds(field("kinds"));
    std::vector<std::string> kind;
    for (std::string k; kinds >> k;) kind.push_back(toLower(k));
    if (!kind.empty() && (kind.size() != 4 || (kind[3] != "time" && kind[3] != "domain" &&
                                               kind[3] != "none" && kind[3] != "???")))
        throw Error(field.name + ": NRRD 4D data whose last axis is of kind '" +
                    (kind.size() == 4 ? kind[3] : field("kinds")) +
                    "': only a time series along the last axis (kind time) is read");
    return std::uint64_t(dimensionFrom(sizes[3], field.name, "NRRD sizes", field("sizes")));
}

NrrdParsed nrrdParse(const fs::path& p, const LoadOptions& options, const NrrdHeader& header) {
    const std::string name = displayName(p);
    const NrrdFields field{header.fields, name};
    auto type = parseSampleType(field.required("type"));
    if (!type) throw Error(name + ": unsupported NRRD type '" + field("type") + "'");
    int dimension = std::atoi(field.required("dimension").c_str());
    if (dimension != 2 && dimension != 3 && dimension != 4)
        throw Error(name + ": NRRD dimension " + field("dimension") +
                    " not supported (need a 2D or 3D scalar volume, or a 3D time series)");
    const int spatialAxes = std::min(dimension, 3);
    std::vector<double> sizes = parseNumbers(field.required("sizes"), name, "sizes");
    if (int(sizes.size()) != dimension)
        throw Error(name + ": 'sizes' has " + std::to_string(sizes.size()) + " entries, " +
                    "dimension is " + std::to_string(dimension));
    glm::ivec3 dims(1);
    for (int a = 0; a < spatialAxes; ++a)
        dims[a] = dimensionFrom(sizes[a], name, "NRRD sizes", field("sizes"));
    // Every size check before anything is allocated (64-bit, no wrap).
    NrrdParsed P;
    P.expected = volumeBytes(dims, *type, name);
    std::vector<std::string> notes;
    const std::uint64_t steps = nrrdSteps(field, dimension, sizes);
    P.total = std::size_t(checkedMul(P.expected, steps, name));
    P.step = timeStep(name, options, steps);
    if (!options.time && steps > 1)
        notes.push_back("4D NRRD: only the first of " + std::to_string(steps) +
                        " time steps was loaded (--time T loads another)");
    bool oriented = false;
    nrrdGeometry(field, dimension, notes, P.layout, oriented);
    nrrdEncoding(field, *type, notes, P);
    nrrdDataFile(p, options, header, field, P);
    SampleLayout& L = P.layout;
    L.dims = dims;
    L.type = *type;
    L.orientation = oriented ? "space directions" : "spacings";
    L.name = name;
    L.source = std::string("NRRD ") + sampleTypeName(*type) + " " + P.encoding + " (" +
               p.filename().string() + ")";
    if (steps > 1 && options.time)
        L.source += ", time step " + std::to_string(P.step) + " of " + std::to_string(steps);
    L.exact = steps == 1;  // a step before the last is followed by the others
    L.notes = notes;
    return P;
}

/// The first byte after `lines` lines of `p` from byte `from` (NRRD line skip), read in chunks.
std::uint64_t afterLines(const fs::path& p, std::uint64_t from, long long lines) {
    if (lines <= 0) return from;
    const std::uint64_t size = regularFileSize(p);
    std::uint64_t at = from;
    long long seen = 0;
    while (at < size) {
        const std::uint64_t n = std::min<std::uint64_t>(size - at, 1 << 16);
        const std::vector<unsigned char> chunk = readFileRange(p, at, n);
        for (std::size_t i = 0; i < chunk.size(); ++i)
            if (chunk[i] == '\n' && ++seen == lines) return at + i + 1;
        at += n;
    }
    return size;
}

}  // namespace

std::optional<SampleLayout> nrrdLayout(const fs::path& p, const LoadOptions& options) {
    const std::string name = displayName(p);
    // The header alone: read until its blank line (a detached header is read whole).
    const std::uint64_t headerFileSize = regularFileSize(p);
    NrrdHeader header;
    for (std::uint64_t n = std::min<std::uint64_t>(headerFileSize, 1 << 16);;
         n = std::min(headerFileSize, 4 * n)) {
        std::vector<unsigned char> prefix = readFileRange(p, 0, n);
        if (n < headerFileSize) {  // whole lines only
            std::size_t end = prefix.size();
            while (end > 0 && prefix[end - 1] != '\n') --end;
            prefix.resize(end);
        }
        header = parseNrrdHeader(prefix, name);
        if (header.blankSeen || n == headerFileSize) break;
    }
    NrrdParsed P = nrrdParse(p, options, header);
    if (P.text || P.hex) return std::nullopt;
    SampleLayout L = P.layout;
    L.file = P.dataFile ? *P.dataFile : p;
    L.fileName = displayName(L.file);
    const std::uint64_t dataStart = afterLines(L.file, P.dataFile ? 0 : header.pos, P.lineSkip);
    const std::uint64_t size = regularFileSize(L.file);
    const std::uint64_t before = P.step * P.expected;  // the time steps before this one
    if (P.gzip || P.bzip2) {
        L.codec = P.gzip ? SampleLayout::Codec::Gzip : SampleLayout::Codec::Bzip2;
        L.start = dataStart;
        L.skip = std::uint64_t(std::max(0LL, P.byteSkip)) + before;
    } else if (P.byteSkip == -1) {
        // "-1": the data is the last `total` bytes of the file.
        checkDataLength(P.total, std::size_t(size - std::min(size, dataStart)), L.fileName, false);
        L.start = size - P.total + before;
    } else {
        checkDataLength(std::size_t(P.byteSkip), std::size_t(size - std::min(size, dataStart)),
                        L.fileName, false);
        L.start = dataStart + std::uint64_t(P.byteSkip) + before;
    }
    return L;
}

Volume loadNrrd(const fs::path& p, const LoadOptions& options) {
    const std::string name = displayName(p);
    std::vector<unsigned char> file = readFileBytes(p);
    const NrrdHeader header = parseNrrdHeader(file, name);
    const NrrdParsed P = nrrdParse(p, options, header);
    const std::size_t expected = P.total;  // every time step: the data must hold them all
    const std::size_t before = std::size_t(P.step) * P.expected;
    const bool gzip = P.gzip, bzip2 = P.bzip2, text = P.text, hex = P.hex;
    const std::string& encoding = P.encoding;
    const long long byteSkip = P.byteSkip, lineSkip = P.lineSkip;
    const SampleLayout& L = P.layout;
    std::vector<unsigned char> detached;
    const unsigned char* data = nullptr;
    std::size_t dataSize = 0;
    std::string dataName = name;
    if (P.dataFile) {
        dataName = displayName(*P.dataFile);
        detached = readFileBytes(*P.dataFile);
        data = detached.data();
        dataSize = detached.size();
    } else {
        data = file.data() + header.pos;
        dataSize = file.size() - header.pos;
    }
    // line skip: lines of text to skip before byte skip.
    std::size_t skipPos = 0;
    for (long long l = 0; l < lineSkip && skipPos < dataSize; ++l) {
        while (skipPos < dataSize && data[skipPos] != '\n') ++skipPos;
        if (skipPos < dataSize) ++skipPos;
    }
    data += skipPos;
    dataSize -= skipPos;

    // byte skip counts bytes of the decompressed stream for gzip and bzip2 (as teem reads
    // it), of the file otherwise; -1 (data at the end) only with raw.
    const bool compressed = gzip || bzip2;
    if (byteSkip > 0 && !compressed) {
        checkDataLength(std::size_t(byteSkip), dataSize, dataName, false);
        data += byteSkip;
        dataSize -= std::size_t(byteSkip);
    }
    std::vector<unsigned char> decoded;
    if (compressed) {
        const std::size_t skip = std::size_t(std::max(0LL, byteSkip));
        const std::size_t limit = checkedAdd(expected, skip, dataName);
        decoded = gzip ? inflateAll(data, dataSize, dataName, limit)
                       : bunzip2All(data, dataSize, dataName, limit);
        checkDataLength(limit, decoded.size(), dataName, true);
        data = decoded.data() + skip;
        dataSize = expected;
    } else if (encoding == "raw") {
        if (byteSkip == -1) {
            // "-1": the data is the last `expected` bytes of the file.
            checkDataLength(expected, dataSize, dataName, false);
            data += dataSize - expected;
            dataSize = expected;
        }
        checkDataLength(expected, dataSize, dataName, true);
    } else if (hex) {
        decoded = decodeHex(data, dataSize, expected, dataName);
        data = decoded.data();
        dataSize = decoded.size();
    } else {
        // Text: n numbers take at least 2n - 1 characters (digits and separators).
        const std::size_t count = expected / sampleSize(L.type);
        if (dataSize < 2 * count - 1)
            throw Error(dataName + ": truncated data: " + std::to_string(count) +
                        " numbers need at least " + std::to_string(2 * count - 1) +
                        " characters of text, found " + std::to_string(dataSize));
    }
    Volume v = makeVolume(L.dims, glm::dvec3(1.0), name);
    if (text && expected == P.expected) {
        decodeText(std::string(data, data + dataSize), v.voxelCount(), L.type, v.data.data(),
                   dataName);
    } else if (text) {  // every step's numbers are checked, one step's kept
        std::vector<float> all(expected / sampleSize(L.type));
        decodeText(std::string(data, data + dataSize), all.size(), L.type, all.data(), dataName);
        std::copy_n(all.begin() + std::ptrdiff_t(before / sampleSize(L.type)), v.voxelCount(),
                    v.data.begin());
    } else {
        decodeSamples(data + before, v.voxelCount(), L.type, L.bigEndian, v.data.data());
    }

    v.source = L.source;
    applyOrientation(v, L.M, L.t, L.orientation);
    for (const std::string& n : L.notes) addNote(v, n);
    return v;
}

}  // namespace splat::detail
