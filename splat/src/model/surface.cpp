// Iso surface extraction by marching tetrahedra over the reconstructed field (see
// splat/surface.h for the method and its sources).
#include "splat/surface.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>

#include "splat/error.h"
#include "splat/views.h"

namespace splat {

namespace {

/// f sampled at the index points of a grid that pads the volume by `pad` voxels per side.
struct SampledField {
    glm::ivec3 lo{0}, size{0};  ///< index of grid point (0, 0, 0); points per axis
    std::vector<double> f;
    std::size_t id(int i, int j, int k) const {
        return (std::size_t(k) * std::size_t(size.y) + std::size_t(j)) * std::size_t(size.x) +
               std::size_t(i);
    }
    glm::dvec3 index(std::size_t id) const {
        const std::size_t sx = std::size_t(size.x), sy = std::size_t(size.y);
        return glm::dvec3(lo) +
               glm::dvec3(double(id % sx), double((id / sx) % sy), double(id / (sx * sy)));
    }
};

SampledField sample(const FieldView& field, const Volume& v, int pad) {
    SampledField g;
    g.lo = glm::ivec3(-pad);
    g.size = v.dims + 2 * pad;
    g.f.resize(std::size_t(g.size.x) * std::size_t(g.size.y) * std::size_t(g.size.z));
    tbb::parallel_for(0, g.size.z, [&](int k) {
        for (int j = 0; j < g.size.y; ++j)
            for (int i = 0; i < g.size.x; ++i)
                g.f[g.id(i, j, k)] = field(v.world(glm::dvec3(g.lo) + glm::dvec3(i, j, k)));
    });
    return g;
}

// Kuhn's six tetrahedra of the unit cube: corner bits x = 1, y = 2, z = 4; each runs from
// corner 0 to corner 7 along one order of the axes.
constexpr int kTets[6][4] = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7},
                             {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};

/// Builds the triangles and the (unrefined) vertices, one per crossed grid edge.
class Marcher {
  public:
    Marcher(const SampledField& g, const Volume& v, double level, Mesh& mesh)
        : g_(g), v_(v), level_(level), mesh_(mesh) {}

    std::vector<std::array<std::size_t, 2>> edges;  ///< per vertex: inside, outside grid point

    void run() {
        const glm::ivec3 s = g_.size;
        for (int k = 0; k + 1 < s.z; ++k)
            for (int j = 0; j + 1 < s.y; ++j)
                for (int i = 0; i + 1 < s.x; ++i) cube(i, j, k);
    }

  private:
    void cube(int i, int j, int k) {
        std::size_t id[8];
        int inside = 0;
        for (int c = 0; c < 8; ++c) {
            id[c] = g_.id(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
            inside += g_.f[id[c]] >= level_;
        }
        if (inside == 0 || inside == 8) return;
        for (const auto& t : kTets) tet({id[t[0]], id[t[1]], id[t[2]], id[t[3]]});
    }

    void tet(const std::array<std::size_t, 4>& id) {
        std::array<std::size_t, 4> in, out;
        int ni = 0, no = 0;
        for (std::size_t p : id) (g_.f[p] >= level_ ? in[ni++] : out[no++]) = p;
        if (ni == 0 || no == 0) return;
        if (ni == 1) {
            triangle(vertex(in[0], out[0]), vertex(in[0], out[1]), vertex(in[0], out[2]), in, ni,
                     out, no);
        } else if (ni == 3) {
            triangle(vertex(in[0], out[0]), vertex(in[1], out[0]), vertex(in[2], out[0]), in, ni,
                     out, no);
        } else {
            const std::uint32_t a = vertex(in[0], out[0]), b = vertex(in[0], out[1]),
                                c = vertex(in[1], out[1]), d = vertex(in[1], out[0]);
            triangle(a, b, c, in, ni, out, no);
            triangle(a, c, d, in, ni, out, no);
        }
    }

    std::uint32_t vertex(std::size_t in, std::size_t out) {
        const std::uint64_t key =
            std::uint64_t(std::min(in, out)) * g_.f.size() + std::max(in, out);
        auto [it, fresh] = ids_.try_emplace(key, std::uint32_t(edges.size()));
        if (fresh) {
            edges.push_back({in, out});
            const double t = (level_ - g_.f[in]) / (g_.f[out] - g_.f[in]);
            const glm::dvec3 p = g_.index(in) + t * (g_.index(out) - g_.index(in));
            mesh_.vertices.push_back(glm::vec3(v_.world(p)));
        }
        return it->second;
    }

    // Counter-clockwise seen from outside (where f < level).
    void triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c,
                  const std::array<std::size_t, 4>& in, int ni,
                  const std::array<std::size_t, 4>& out, int no) {
        glm::dvec3 ci(0.0), co(0.0);
        for (int n = 0; n < ni; ++n) ci += g_.index(in[n]);
        for (int n = 0; n < no; ++n) co += g_.index(out[n]);
        const glm::dvec3 outward = v_.spacing * (co / double(no) - ci / double(ni));
        const glm::dvec3 pa(mesh_.vertices[a]), pb(mesh_.vertices[b]), pc(mesh_.vertices[c]);
        if (glm::dot(glm::cross(pb - pa, pc - pa), outward) < 0) std::swap(b, c);
        mesh_.triangles.push_back({a, b, c});
    }

    const SampledField& g_;
    const Volume& v_;
    double level_;
    Mesh& mesh_;
    std::unordered_map<std::uint64_t, std::uint32_t> ids_;
};

}  // namespace

Mesh extractIsosurface(const Volume& volume, double level, const SurfaceOptions& options) {
    if (!std::isfinite(level)) throw Error("iso surface: the level must be a finite number");
    if (options.refineSteps < 0 || options.refineSteps > 64)
        throw Error("iso surface: refinement steps must be between 0 and 64");
    Mesh mesh;
    auto work = [&] {
        const FieldView field(volume, options.kernel, options.kernelSigma, options.kernelRadius,
                              options.threads);
        const int pad = int(std::ceil(field.kernelRadius())) + 1;
        const SampledField g = sample(field, volume, pad);
        Marcher m(g, volume, level, mesh);
        m.run();
        // Each vertex onto the level set of the true field along its grid edge (regula falsi,
        // Illinois variant), then the normal from the field's gradient there.
        const std::size_t n = mesh.vertices.size();
        mesh.normals.resize(n);
        std::vector<double> residual(n, 0.0);
        const double h = 1e-3 * volume.minSpacing();
        tbb::parallel_for(std::size_t(0), n, [&](std::size_t q) {
            const glm::dvec3 a = volume.world(g.index(m.edges[q][0]));
            const glm::dvec3 b = volume.world(g.index(m.edges[q][1]));
            double ta = 0, tb = 1, fa = g.f[m.edges[q][0]] - level, fb = g.f[m.edges[q][1]] - level;
            double t = fa / (fa - fb);
            int side = 0;
            for (int s = 0; s < options.refineSteps; ++s) {
                const double ft = field(a + t * (b - a)) - level;
                if (ft == 0) break;
                if ((ft > 0) == (fa > 0)) {
                    ta = t;
                    fa = ft;
                    if (side == -1) fb *= 0.5;
                    side = -1;
                } else {
                    tb = t;
                    fb = ft;
                    if (side == 1) fa *= 0.5;
                    side = 1;
                }
                t = ta + fa * (tb - ta) / (fa - fb);
            }
            const glm::dvec3 x = a + t * (b - a);
            // The mesh is in the world frame (an oblique volume's rotation applied).
            mesh.vertices[q] = glm::vec3(volume.direction * x);
            residual[q] = std::abs(field(x) - level);
            glm::dvec3 grad;
            for (int k = 0; k < 3; ++k) {
                glm::dvec3 d(0.0);
                d[k] = h;
                grad[k] = (field(x + d) - field(x - d)) / (2 * h);
            }
            const double len = glm::length(grad);
            mesh.normals[q] =
                len > 0 ? glm::vec3(volume.direction * (-grad / len)) : glm::vec3(0.0f);
        });
        for (double r : residual) mesh.maxResidual = std::max(mesh.maxResidual, r);
    };
    if (options.threads > 0) {
        tbb::task_arena arena(options.threads);
        arena.execute(work);
    } else {
        work();
    }
    return mesh;
}

}  // namespace splat
