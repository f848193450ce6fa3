#pragma once
// The stages every Gaussian renderer shares (splat/gaussians.h):
//   project     Gaussians -> per Gaussian: pixel centre, 2D conic, view depth, footprint
//               radius, SH colour toward the eye, and for the ray renderers the 3D precision
//               matrix and the density scale c_i;
//   binToTiles  global sort by view depth of the means, then each Gaussian's index appended
//               to the 16 x 16 pixel tiles its footprint rectangle covers (front to back);
//   forEachTile tiles in parallel, each owning its pixels: the image is the same for any
//               thread count.
#include <array>
#include <cstdint>
#include <functional>
#include <glm/glm.hpp>
#include <vector>

#include "splat/camera.h"
#include "splat/gaussians.h"

namespace splat::gaussians {

constexpr int kTile = 16;

/// The camera as the projection uses it: view-space axes right, down (image y grows
/// downwards), view; pixels per world unit at depth 1 (perspective) or per world unit
/// (orthographic).
struct ViewFrame {
    glm::dvec3 eye, right, down, view;
    bool perspective = false;
    double focalPixels = 1;         ///< perspective: focal / pixelSize; orthographic: 1 / pixelSize
    double limitX = 0, limitY = 0;  ///< perspective: 1.3 tan(half field of view) per axis
    int width = 0, height = 0;
};
ViewFrame viewFrame(const Camera& camera);

/// Which footprint bounds a Gaussian's pixels: the rasterizers' (3 standard deviations of the
/// dilated 2D covariance, as 3DGS), or the volume model's (where the Gaussian's optical depth
/// along a ray falls below `epsilon`).
enum class Footprint { Splat, Volume };

/// Per-Gaussian results in scene order; radius 0 means not drawn (behind the near plane at
/// depth 0.2, a degenerate covariance, or below epsilon).
struct Projected {
    std::vector<glm::vec2> centre;  ///< pixel position of the mean (pixel centres at +0.5)
    std::vector<glm::vec3> conic;   ///< inverse of the dilated 2D covariance (xx, xy, yy), px
    std::vector<float> depth;       ///< view depth of the mean
    std::vector<int> radius;        ///< footprint radius, pixels
    std::vector<glm::vec3> colour;  ///< SH colour toward the eye
    std::vector<float> opacity;     ///< the scene's opacities
    /// Ray renderers (empty otherwise): P = Sigma^-1 (xx, xy, xz, yy, yz, zz, volume frame)
    /// and the density scale c_i of splat/gaussians.h's volumetric model.
    std::vector<std::array<double, 6>> precision;
    std::vector<double> density;
};
/// `rays`: also the precision matrices and densities (the per-pixel sorted and ray renderers).
Projected project(const GaussianScene& scene, const ViewFrame& frame, Footprint footprint,
                  double epsilon, bool rays);

/// Per tile, the indices of the Gaussians whose footprint rectangle covers it, sorted by view
/// depth of the means (ties by index).
struct TileLists {
    int tilesX = 0, tilesY = 0;
    std::vector<std::uint64_t> offsets;  ///< tilesX * tilesY + 1
    std::vector<std::uint32_t> ids;
    const std::uint32_t* begin(int tile) const { return ids.data() + offsets[std::size_t(tile)]; }
    const std::uint32_t* end(int tile) const { return ids.data() + offsets[std::size_t(tile) + 1]; }
};
TileLists binToTiles(const Projected& projected, int width, int height);

/// Calls fn(tileX, tileY) for every tile, in parallel (in the caller's task arena).
void forEachTile(const TileLists& tiles, const std::function<void(int, int)>& fn);

/// One Gaussian along a ray o + t d (|d| = 1): its density c exp(-m/2) exp(-a (t - t*)^2 / 2).
struct RayGaussian {
    double tStar;      ///< depth of maximum response, d^T P (mu - o) / d^T P d
    double s;          ///< sqrt(a / 2): erf's argument per unit t
    double amplitude;  ///< c exp(-m / 2) sqrt(pi / (2 a)): the optical depth is 2 amplitude
    glm::vec3 colour;
};
RayGaussian alongRay(const Projected& projected, const glm::vec3& mean, std::size_t i,
                     const Ray& ray);

/// The Gaussians of splat/gaussians.h's volumetric model along one ray whose optical depth
/// exceeds `epsilon`, from a tile's list.
std::vector<RayGaussian>& gaussiansOnRay(const GaussianScene& scene, const Projected& projected,
                                         const std::uint32_t* begin, const std::uint32_t* end,
                                         const Ray& ray, double epsilon,
                                         std::vector<RayGaussian>& out);

/// Calls fn(x, y, gaussians) for every pixel whose centre ray meets a Gaussian of optical
/// depth above `epsilon` (gaussiansOnRay over its tile's list), tiles in parallel: the
/// per-ray loop of the exact reference and of its depth image.
void forEachPixelRay(const GaussianScene& scene, const Projected& projected,
                     const TileLists& tiles, const Camera& camera, double epsilon,
                     const std::function<void(int, int, const std::vector<RayGaussian>&)>& fn);

}  // namespace splat::gaussians
