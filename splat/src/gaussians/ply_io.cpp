// The .ply files of 3D Gaussian Splatting's reference implementation: binary_little_endian,
// one `element vertex N` of scalar properties read by name (splat/gaussians.h).
#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "splat/atomic_file.h"
#include "splat/error.h"
#include "splat/gaussians.h"

namespace splat {

namespace {

static_assert(std::endian::native == std::endian::little,
              "3DGS PLY files are little-endian; the reader copies their floats as they are");

// Bytes of a PLY scalar type, 0 for an unknown one.
int typeBytes(const std::string& t) {
    if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
    if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
    if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" ||
        t == "float32")
        return 4;
    if (t == "double" || t == "float64") return 8;
    return 0;
}

struct Property {
    std::size_t offset = 0;
    bool isFloat = false;
};

struct Header {
    std::uint64_t count = 0;
    std::size_t stride = 0;
    std::map<std::string, Property> properties;
    std::uint64_t dataStart = 0;  // file offset of the vertex block
};

[[noreturn]] void fail(const std::string& path, const std::string& why) {
    throw Error(path + ": " + why);
}

Header readHeader(std::istream& in, const std::string& path) {
    std::string line;
    if (!std::getline(in, line) || line.substr(0, 3) != "ply") fail(path, "not a PLY file");
    Header h;
    bool format = false, inVertex = false, seenVertex = false;
    std::uint64_t before = 0;  // bytes of elements declared before the vertex element
    for (int lines = 0; std::getline(in, line); ++lines) {
        if (lines > 100000) fail(path, "PLY header does not end");
        if (!line.empty() && line.back() == '\r') line.pop_back();
        std::istringstream words(line);
        std::string key;
        words >> key;
        if (key == "end_header") {
            if (!format) fail(path, "PLY header has no format line");
            if (!seenVertex) fail(path, "PLY file has no vertex element (no Gaussians)");
            h.dataStart = std::uint64_t(in.tellg()) + before;
            return h;
        }
        if (key == "comment" || key == "obj_info" || key.empty()) continue;
        if (key == "format") {
            std::string f;
            words >> f;
            if (f == "ascii")
                fail(path,
                     "ASCII PLY is not a 3DGS scene (3DGS writes binary_little_endian); convert "
                     "it to binary");
            if (f != "binary_little_endian")
                fail(path, "PLY format '" + f + "' is not supported (binary_little_endian only)");
            format = true;
        } else if (key == "element") {
            std::string name;
            std::string n;
            words >> name >> n;
            char* end = nullptr;
            errno = 0;
            const unsigned long long count = std::strtoull(n.c_str(), &end, 10);
            if (n.empty() || *end || errno || n[0] == '-')
                fail(path, "PLY element '" + name + "' has a bad count '" + n + "'");
            inVertex = name == "vertex";
            if (inVertex) {
                if (seenVertex) fail(path, "PLY file has two vertex elements");
                seenVertex = true;
                h.count = count;
            } else if (!seenVertex && count > 0) {
                fail(path, "PLY element '" + name + "' before the vertices is not supported");
            }
        } else if (key == "property") {
            std::string type, name;
            words >> type;
            if (type == "list") {
                if (inVertex) fail(path, "PLY vertex element has a list property");
                continue;
            }
            words >> name;
            const int bytes = typeBytes(type);
            if (bytes == 0)
                fail(path, "PLY property '" + name + "' has unknown type '" + type + "'");
            if (inVertex) {
                if (h.properties.count(name)) fail(path, "PLY property '" + name + "' repeats");
                h.properties[name] = {h.stride, type == "float" || type == "float32"};
                h.stride += std::size_t(bytes);
            }
        } else {
            fail(path, "PLY header line '" + line.substr(0, 60) + "' is not understood");
        }
    }
    fail(path, "PLY header has no end_header");
}

float sigmoid(float x) { return float(1.0 / (1.0 + std::exp(-double(x)))); }

}  // namespace

bool isGaussianScene(const std::string& path) {
    if (path.rfind("gaussians:", 0) == 0) return true;
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
    return ext == ".ply";
}

GaussianScene openGaussians(const std::string& path) {
    return path.rfind("gaussians:", 0) == 0 ? syntheticGaussians(path) : loadGaussians(path);
}

GaussianScene loadGaussians(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) fail(path, "cannot open");
    const Header h = readHeader(in, path);
    std::error_code ec;
    const std::uint64_t fileSize = std::filesystem::file_size(path, ec);
    if (ec) fail(path, "cannot read its size");
    if (h.count == 0) fail(path, "PLY file has no Gaussians (vertex count 0)");
    if (h.count > kMaxGaussians)
        fail(path, "vertex count " + std::to_string(h.count) + " exceeds the limit of " +
                       std::to_string(kMaxGaussians) + " Gaussians");
    const std::uint64_t need = h.count * h.stride;
    if (fileSize < h.dataStart || fileSize - h.dataStart < need)
        fail(path, "truncated vertex block: " + std::to_string(h.count) + " Gaussians need " +
                       std::to_string(need) + " bytes, the file has " +
                       std::to_string(fileSize > h.dataStart ? fileSize - h.dataStart : 0));

    auto find = [&](const std::string& name) -> std::size_t {
        const auto it = h.properties.find(name);
        if (it == h.properties.end())
            fail(path, "missing property '" + name + "' (not a 3DGS scene)");
        if (!it->second.isFloat) fail(path, "property '" + name + "' is not float");
        return it->second.offset;
    };
    const char* required[] = {"x",      "y",       "z",       "f_dc_0",  "f_dc_1",
                              "f_dc_2", "opacity", "scale_0", "scale_1", "scale_2",
                              "rot_0",  "rot_1",   "rot_2",   "rot_3"};
    std::size_t off[14];
    for (int k = 0; k < 14; ++k) off[k] = find(required[k]);
    int rest = 0;
    while (h.properties.count("f_rest_" + std::to_string(rest))) ++rest;
    int degree = -1;
    for (int d = 0; d <= 3; ++d)
        if (rest == 3 * ((d + 1) * (d + 1) - 1)) degree = d;
    if (degree < 0)
        fail(path, std::to_string(rest) +
                       " f_rest properties do not make an SH degree 0..3 (0, 9, 24 or 45)");
    std::vector<std::size_t> restOff(static_cast<std::size_t>(rest));
    for (int j = 0; j < rest; ++j) restOff[std::size_t(j)] = find("f_rest_" + std::to_string(j));

    GaussianScene s;
    s.shDegree = degree;
    s.source = "3DGS PLY (" + std::filesystem::path(path).filename().string() + ")";
    const std::size_t n = std::size_t(h.count), k = std::size_t(s.shCount());
    s.means.resize(n);
    s.scales.resize(n);
    s.rotations.resize(n);
    s.opacities.resize(n);
    s.sh.resize(n * k * 3);
    in.seekg(std::streamoff(h.dataStart));
    const std::size_t chunk = std::max<std::size_t>(1, (std::size_t(1) << 22) / h.stride);
    std::vector<char> buf(chunk * h.stride);
    for (std::size_t first = 0; first < n; first += chunk) {
        const std::size_t m = std::min(chunk, n - first);
        if (!in.read(buf.data(), std::streamsize(m * h.stride)))
            fail(path,
                 "truncated vertex block (read failed at Gaussian " + std::to_string(first) + ")");
        for (std::size_t j = 0; j < m; ++j) {
            const char* v = buf.data() + j * h.stride;
            auto f = [v](std::size_t o) {
                float x;
                std::memcpy(&x, v + o, 4);
                return x;
            };
            const std::size_t i = first + j;
            s.means[i] = {f(off[0]), f(off[1]), f(off[2])};
            float* sh = s.sh.data() + i * k * 3;
            for (int c = 0; c < 3; ++c) {
                sh[c] = f(off[3 + c]);
                // f_rest is channel-major: channel c's coefficients 1..k-1, then the next.
                for (std::size_t q = 1; q < k; ++q)
                    sh[q * 3 + std::size_t(c)] = f(restOff[std::size_t(c) * (k - 1) + q - 1]);
            }
            s.opacities[i] = sigmoid(f(off[6]));
            s.scales[i] = {std::exp(f(off[7])), std::exp(f(off[8])), std::exp(f(off[9]))};
            glm::vec4 q(f(off[10]), f(off[11]), f(off[12]), f(off[13]));
            const float len = glm::length(q);
            if (!(len > 0) || !std::isfinite(len))
                fail(path, "Gaussian " + std::to_string(i) + " has a zero or non-finite rotation");
            s.rotations[i] = q / len;
        }
    }
    try {
        s.validate();
    } catch (const Error& e) {
        fail(path, e.what());
    }
    return s;
}

void writeGaussians(const GaussianScene& scene, const std::string& path) {
    scene.validate();
    const std::size_t n = scene.size(), k = std::size_t(scene.shCount());
    std::vector<std::string> names = {"x",  "y",      "z",      "nx",    "ny",
                                      "nz", "f_dc_0", "f_dc_1", "f_dc_2"};
    for (std::size_t j = 0; j < 3 * (k - 1); ++j) names.push_back("f_rest_" + std::to_string(j));
    for (const char* p :
         {"opacity", "scale_0", "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"})
        names.push_back(p);
    std::string header = "ply\nformat binary_little_endian 1.0\ncomment written by splat\n";
    header += "element vertex " + std::to_string(n) + "\n";
    for (const auto& p : names) header += "property float " + p + "\n";
    header += "end_header\n";
    AtomicFile file(path);
    file.write(header.data(), header.size());
    const std::size_t stride = names.size();
    const std::size_t chunk = 1 << 14;
    std::vector<float> buf(chunk * stride);
    for (std::size_t first = 0; first < n; first += chunk) {
        const std::size_t m = std::min(chunk, n - first);
        for (std::size_t j = 0; j < m; ++j) {
            const std::size_t i = first + j;
            float* v = buf.data() + j * stride;
            const float* sh = scene.sh.data() + i * k * 3;
            std::size_t w = 0;
            for (int a = 0; a < 3; ++a) v[w++] = scene.means[i][a];
            for (int a = 0; a < 3; ++a) v[w++] = 0.0f;
            for (int c = 0; c < 3; ++c) v[w++] = sh[c];
            for (int c = 0; c < 3; ++c)
                for (std::size_t q = 1; q < k; ++q) v[w++] = sh[q * 3 + std::size_t(c)];
            const double o = scene.opacities[i];
            v[w++] = float(std::clamp(std::log(o / (1.0 - o)), -40.0, 40.0));
            for (int a = 0; a < 3; ++a) v[w++] = std::log(scene.scales[i][a]);
            for (int a = 0; a < 4; ++a) v[w++] = scene.rotations[i][a];
        }
        // PLY binary_little_endian: the host's float layout on the little-endian machines
        // splat builds on.
        file.write(buf.data(), m * stride * sizeof(float));
    }
    file.commit();
}

}  // namespace splat
