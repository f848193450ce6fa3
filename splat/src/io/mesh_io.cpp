// Mesh files: binary PLY, OBJ and binary STL, each written whole through the atomic writer.
#include <cstdint>
#include <cstring>
#include <sstream>
#include <string>

#include "splat/atomic_file.h"
#include "splat/error.h"
#include "splat/surface.h"

namespace splat {

namespace {

template <class T>
void put(std::string& out, T value) {
    char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));  // little-endian hosts (x86-64, arm64)
    out.append(bytes, sizeof(T));
}

std::string ply(const Mesh& m) {
    std::ostringstream h;
    h << "ply\nformat binary_little_endian 1.0\ncomment splat iso surface\n"
      << "element vertex " << m.vertices.size() << "\n"
      << "property float x\nproperty float y\nproperty float z\n"
      << "property float nx\nproperty float ny\nproperty float nz\n"
      << "element face " << m.triangles.size() << "\n"
      << "property list uchar int vertex_indices\nend_header\n";
    std::string out = h.str();
    out.reserve(out.size() + m.vertices.size() * 24 + m.triangles.size() * 13);
    for (std::size_t n = 0; n < m.vertices.size(); ++n) {
        for (int c = 0; c < 3; ++c) put(out, m.vertices[n][c]);
        for (int c = 0; c < 3; ++c) put(out, m.normals[n][c]);
    }
    for (const glm::uvec3& t : m.triangles) {
        put(out, std::uint8_t(3));
        for (int c = 0; c < 3; ++c) put(out, std::int32_t(t[c]));
    }
    return out;
}

std::string obj(const Mesh& m) {
    std::ostringstream o;
    o.precision(9);
    o << "# splat iso surface: " << m.vertices.size() << " vertices, " << m.triangles.size()
      << " triangles\n";
    for (const glm::vec3& v : m.vertices) o << "v " << v.x << ' ' << v.y << ' ' << v.z << '\n';
    for (const glm::vec3& n : m.normals) o << "vn " << n.x << ' ' << n.y << ' ' << n.z << '\n';
    for (const glm::uvec3& t : m.triangles)
        o << "f " << t.x + 1 << "//" << t.x + 1 << ' ' << t.y + 1 << "//" << t.y + 1 << ' '
          << t.z + 1 << "//" << t.z + 1 << '\n';
    return o.str();
}

std::string stl(const Mesh& m) {
    std::string out(80, ' ');
    out.replace(0, 22, "splat iso surface, STL");
    put(out, std::uint32_t(m.triangles.size()));
    for (const glm::uvec3& t : m.triangles) {
        const glm::vec3 a = m.vertices[t.x], b = m.vertices[t.y], c = m.vertices[t.z];
        glm::vec3 n = glm::cross(b - a, c - a);
        const float len = glm::length(n);
        n = len > 0 ? n / len : glm::vec3(0.0f);
        for (const glm::vec3& v : {n, a, b, c})
            for (int k = 0; k < 3; ++k) put(out, v[k]);
        put(out, std::uint16_t(0));
    }
    return out;
}

}  // namespace

void writeMesh(const std::string& path, const Mesh& mesh) {
    const std::string ext = lowerExtension(path);
    std::string bytes;
    if (ext == ".ply")
        bytes = ply(mesh);
    else if (ext == ".obj")
        bytes = obj(mesh);
    else if (ext == ".stl")
        bytes = stl(mesh);
    else
        throw Error(path + ": unknown mesh format '" + ext + "' (expected .ply, .obj or .stl)");
    writeFileAtomic(path, bytes.data(), bytes.size());
}

}  // namespace splat
