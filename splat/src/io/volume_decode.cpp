// Typed sample decoding shared by every loader: the element types volume files use,
// their many spellings, and conversion of either byte order to float.
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <sstream>
#include <utility>

#include "splat/error.h"
#include "volume_detail.h"

namespace splat::detail {

std::size_t sampleSize(SampleType t) {
    switch (t) {
        case SampleType::U8:
        case SampleType::I8:
            return 1;
        case SampleType::U16:
        case SampleType::I16:
            return 2;
        case SampleType::U32:
        case SampleType::I32:
        case SampleType::F32:
            return 4;
        case SampleType::F64:
            return 8;
    }
    return 1;
}

const char* sampleTypeName(SampleType t) {
    switch (t) {
        case SampleType::U8:
            return "uint8";
        case SampleType::I8:
            return "int8";
        case SampleType::U16:
            return "uint16";
        case SampleType::I16:
            return "int16";
        case SampleType::U32:
            return "uint32";
        case SampleType::I32:
            return "int32";
        case SampleType::F32:
            return "float32";
        case SampleType::F64:
            return "float64";
    }
    return "?";
}

std::optional<SampleType> parseSampleType(const std::string& name) {
    // Normalise: lower case, single spaces, so "Unsigned  Short Int" matches.
    std::istringstream in(toLower(name));
    std::string word, s;
    while (in >> word) s += (s.empty() ? "" : " ") + word;
    struct Alias {
        const char* name;
        SampleType type;
    };
    static const Alias aliases[] = {
        // canonical, short and C names
        {"uint8", SampleType::U8},
        {"u8", SampleType::U8},
        {"uchar", SampleType::U8},
        {"int8", SampleType::I8},
        {"i8", SampleType::I8},
        {"char", SampleType::I8},
        {"uint16", SampleType::U16},
        {"u16", SampleType::U16},
        {"ushort", SampleType::U16},
        {"int16", SampleType::I16},
        {"i16", SampleType::I16},
        {"short", SampleType::I16},
        {"uint32", SampleType::U32},
        {"u32", SampleType::U32},
        {"uint", SampleType::U32},
        {"int32", SampleType::I32},
        {"i32", SampleType::I32},
        {"int", SampleType::I32},
        {"float32", SampleType::F32},
        {"f32", SampleType::F32},
        {"float", SampleType::F32},
        {"float64", SampleType::F64},
        {"f64", SampleType::F64},
        {"double", SampleType::F64},
        // NRRD spellings (http://teem.sourceforge.net/nrrd/format.html#type)
        {"signed char", SampleType::I8},
        {"int8_t", SampleType::I8},
        {"unsigned char", SampleType::U8},
        {"uint8_t", SampleType::U8},
        {"short int", SampleType::I16},
        {"signed short", SampleType::I16},
        {"signed short int", SampleType::I16},
        {"int16_t", SampleType::I16},
        {"unsigned short", SampleType::U16},
        {"unsigned short int", SampleType::U16},
        {"uint16_t", SampleType::U16},
        {"signed int", SampleType::I32},
        {"int32_t", SampleType::I32},
        {"unsigned int", SampleType::U32},
        {"uint32_t", SampleType::U32},
    };
    for (const Alias& a : aliases)
        if (s == a.name) return a.type;
    return std::nullopt;
}

namespace {

// Reads one sample of N bytes in the requested byte order as the unsigned integer of
// that width, then reinterprets the bits as T.
template <typename T>
T loadSample(const unsigned char* p, bool bigEndian) {
    unsigned char b[sizeof(T)];
    if (bigEndian)
        for (std::size_t i = 0; i < sizeof(T); ++i) b[i] = p[sizeof(T) - 1 - i];
    else
        std::memcpy(b, p, sizeof(T));
    // The decoded buffer is in little-endian order; this project targets little-endian
    // hosts (x86-64, AArch64), as does every platform OpenImageIO and TBB support here.
    T value;
    std::memcpy(&value, b, sizeof(T));
    return value;
}

template <typename T>
void decodeAs(const unsigned char* bytes, std::size_t count, bool bigEndian, float* out) {
    for (std::size_t i = 0; i < count; ++i)
        out[i] = static_cast<float>(loadSample<T>(bytes + i * sizeof(T), bigEndian));
}

}  // namespace

void decodeSamples(const unsigned char* bytes, std::size_t count, SampleType t, bool bigEndian,
                   float* out) {
    switch (t) {
        case SampleType::U8:
            decodeAs<std::uint8_t>(bytes, count, false, out);
            break;
        case SampleType::I8:
            decodeAs<std::int8_t>(bytes, count, false, out);
            break;
        case SampleType::U16:
            decodeAs<std::uint16_t>(bytes, count, bigEndian, out);
            break;
        case SampleType::I16:
            decodeAs<std::int16_t>(bytes, count, bigEndian, out);
            break;
        case SampleType::U32:
            decodeAs<std::uint32_t>(bytes, count, bigEndian, out);
            break;
        case SampleType::I32:
            decodeAs<std::int32_t>(bytes, count, bigEndian, out);
            break;
        case SampleType::F32:
            decodeAs<float>(bytes, count, bigEndian, out);
            break;
        case SampleType::F64:
            decodeAs<double>(bytes, count, bigEndian, out);
            break;
    }
}

namespace {
// The value range of an integer sample type; nullopt for floating-point types.
std::optional<std::pair<double, double>> integerRange(SampleType t) {
    switch (t) {
        case SampleType::U8:
            return std::pair(0.0, 255.0);
        case SampleType::I8:
            return std::pair(-128.0, 127.0);
        case SampleType::U16:
            return std::pair(0.0, 65535.0);
        case SampleType::I16:
            return std::pair(-32768.0, 32767.0);
        case SampleType::U32:
            return std::pair(0.0, 4294967295.0);
        case SampleType::I32:
            return std::pair(-2147483648.0, 2147483647.0);
        default:
            return std::nullopt;
    }
}
}  // namespace

void decodeText(const std::string& text, std::size_t count, SampleType t, float* out,
                const std::string& what) {
    const auto range = integerRange(t);
    const char* p = text.c_str();
    for (std::size_t i = 0; i < count; ++i) {
        while (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r' || *p == ',') ++p;
        if (!*p)
            throw Error(what + ": truncated data: expected " + std::to_string(count) +
                        " numbers, found " + std::to_string(i));
        char* end = nullptr;
        double value = std::strtod(p, &end);
        if (end == p)
            throw Error(what + ": text data: cannot parse sample " + std::to_string(i) + " ('" +
                        std::string(p, std::min<std::size_t>(16, std::strlen(p))) + "')");
        if (range &&
            !(value >= range->first && value <= range->second && value == std::floor(value)))
            throw Error(what + ": text sample " + std::to_string(i) + " ('" +
                        std::string(p, std::size_t(end - p)) + "') is not a " + sampleTypeName(t) +
                        " value");
        // A float32 number in text is in range when it rounds to a finite float: teem prints
        // FLT_MAX as 3.4028235e+38, a little above it, which rounds to FLT_MAX.
        if (!range && t == SampleType::F32 && std::isfinite(value) &&
            !std::isfinite(std::strtof(p, nullptr)))
            throw Error(what + ": text sample " + std::to_string(i) + " ('" +
                        std::string(p, std::size_t(end - p)) + "') is out of the float32 range");
        // float32 rounded once, from the text (not through double).
        out[i] = t == SampleType::F32 ? std::strtof(p, nullptr) : static_cast<float>(value);
        p = end;
    }
}

void checkDataLength(std::size_t expected, std::size_t found, const std::string& what, bool exact) {
    if (found < expected)
        throw Error(what + ": truncated data: expected " + std::to_string(expected) +
                    " bytes, found " + std::to_string(found));
    if (exact && found > expected)
        throw Error(what + ": header sizes disagree with the data: expected " +
                    std::to_string(expected) + " bytes, found " + std::to_string(found));
}

}  // namespace splat::detail
