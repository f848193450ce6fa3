#pragma once
// Surface export: the iso surface f(x) = level of the same reconstructed field the
// renderers draw, f(x) = b + sum_i (d_i - b) h(S^-1 (x - x_i)) (background value b included),
// as a triangle mesh in world coordinates. The splatted `--mode iso` image is the first hit of
// this surface along each pixel ray.
//
// Method: marching tetrahedra (Doi & Koide 1991, "An efficient method of triangulating
// equi-valued surfaces by using tetrahedral cells") on f sampled at the voxel centres of a grid
// padded by the kernel's support (outside the data f tends to b, so a surface that does not
// pass through b closes). Every cube is cut into the six tetrahedra of Kuhn's (Freudenthal's)
// triangulation around its main diagonal; neighbouring cubes then share each face's diagonal,
// so the mesh has no cracks and needs no ambiguity tables. A vertex lies on a grid edge, found
// by linear interpolation and refined by regula falsi on the field itself.
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "splat/volume.h"

namespace splat {

struct Mesh {
    std::vector<glm::vec3> vertices;    ///< world positions
    std::vector<glm::vec3> normals;     ///< unit, pointing towards decreasing f (outward)
    std::vector<glm::uvec3> triangles;  ///< counter-clockwise seen from outside
    /// The largest |f(vertex) - level| over the vertices (the refinement's residual).
    double maxResidual = 0;
};

struct SurfaceOptions {
    std::string kernel = "gaussian";  ///< as RenderSettings::kernel
    double kernelSigma = 0, kernelRadius = 0;
    int threads = 0;  ///< 0: all cores
    int refineSteps = 24;  ///< regula falsi steps per vertex on the true field (0: linear only)
};

/// The iso surface f = level. Throws splat::Error for a non-finite level; an empty mesh when
/// f never crosses the level.
Mesh extractIsosurface(const Volume& volume, double level, const SurfaceOptions& options = {});

/// Writes `.ply` (binary little-endian, with normals), `.obj` (text, with normals) or `.stl`
/// (binary, facet normals) atomically (splat/atomic_file.h); throws splat::Error naming the
/// file on an unknown extension or a failed write.
void writeMesh(const std::string& path, const Mesh& mesh);

}  // namespace splat
