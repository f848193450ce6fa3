#pragma once
// 3D Gaussian Splatting scenes (Kerbl et al. 2023) and four renderers of them.
//
// A scene is N anisotropic Gaussians: mean mu_i, covariance Sigma_i = R_i S_i^2 R_i^T (R_i
// from a unit quaternion (w, x, y, z), S_i = diag(scale_i)), opacity o_i in [0, 1] and
// view-dependent colour from real spherical harmonics of degree 0..3 (the 3DGS basis, the
// colour 0.5 + sum_k sh_k Y_k(dir) clamped at 0). Memory is proportional to N.
//
// Renderers (premultiplied RGBA, as every splat image):
//   Rasterizer  `3dgs`: the reference rasterizer — global sort by the view depth of the means,
//               EWA-projected 2D covariance + 0.3 px^2 on the diagonal, alpha = min(0.99, o G),
//               alpha < 1/255 skipped, front to back, stop where the transmittance would fall
//               below 1e-4; 16 x 16 pixel tiles, deterministic for any thread count.
//   PixelSorted `3dgs-pixel`: the same alphas, sorted per pixel by each Gaussian's depth of
//               maximum response along the ray, t* = d^T P (mu - o) / d^T P d, P = Sigma^-1
//               (StopThePop, Radl et al. 2024).
//   Sheet       `sheet`: image-aligned slabs of thickness `slab` (view depth); each Gaussian's
//               density integrated exactly over each slab (erf), slabs composited front to
//               back as splat's sheets are (alpha = 1 - exp(-tau), C = E alpha / tau).
//   Reference   `reference`: the exact volume rendering integral of the density field below,
//               adaptive along each ray to `tolerance` per channel.
//
// The volumetric model of `sheet` and `reference`: extinction sigma(x) = sum_i c_i G_i(x),
// G_i(x) = exp(-(x - mu_i)^T P_i (x - mu_i) / 2), emission e(x) = sum_i k_i c_i G_i(x), with
// k_i the Gaussian's SH colour toward the eye, and
//     c_i = -ln(1 - min(o_i, 0.99)) sqrt(d_i^T P_i d_i / (2 pi)),
// d_i the unit direction from the eye to mu_i (the view direction in orthographic views): the
// optical depth of the ray through the projected centre of a lone Gaussian is
// -ln(1 - min(o, 0.99)), so its opacity there equals the rasterizer's peak alpha. c_i depends
// on the view (as 3DGS's alpha does): within one frame the field is fixed.
#include <cstddef>
#include <glm/glm.hpp>
#include <initializer_list>
#include <memory>
#include <string>
#include <vector>

#include "splat/camera.h"
#include "splat/image.h"
#include "splat/volume.h"

namespace splat {

/// Largest number of Gaussians a scene may hold (2^28; 1.6 GiB at SH degree 3).
inline constexpr std::size_t kMaxGaussians = std::size_t(1) << 28;

/// One per-Gaussian array of a scene: owned (a std::vector), or borrowed — memory of the
/// caller's (e.g. NumPy arrays behind splat.Gaussians) kept alive by an owner handle. Reading
/// never copies; the first write to a borrowed array copies it into an owned one. Copies of a
/// scene share borrowed memory and copy owned arrays.
template <class T>
class GaussianArray {
  public:
    GaussianArray() = default;
    GaussianArray(std::initializer_list<T> v) : own_(v) {}
    GaussianArray(const GaussianArray& o) : own_(o.own_), owner_(o.owner_) {
        borrowedData_ = o.borrowedData_;
        borrowedSize_ = o.borrowedSize_;
    }
    GaussianArray(GaussianArray&& o) noexcept = default;
    GaussianArray& operator=(const GaussianArray& o) {
        if (this != &o) *this = GaussianArray(o);
        return *this;
    }
    GaussianArray& operator=(GaussianArray&& o) noexcept = default;
    GaussianArray& operator=(std::initializer_list<T> v) {
        release();
        own_ = v;
        return *this;
    }

    /// Borrows `count` values at `data`, which `owner` keeps alive and unchanged while this
    /// array (or a copy of it) reads them.
    void borrow(const T* data, std::size_t count, std::shared_ptr<const void> owner) {
        own_.clear();
        own_.shrink_to_fit();
        borrowedData_ = data;
        borrowedSize_ = count;
        owner_ = std::move(owner);
    }
    bool borrowed() const { return owner_ != nullptr; }

    std::size_t size() const { return borrowed() ? borrowedSize_ : own_.size(); }
    bool empty() const { return size() == 0; }
    const T* data() const { return borrowed() ? borrowedData_ : own_.data(); }
    const T& operator[](std::size_t i) const { return data()[i]; }
    const T* begin() const { return data(); }
    const T* end() const { return data() + size(); }
    const T& front() const { return data()[0]; }
    const T& back() const { return data()[size() - 1]; }

    /// Writing access: the owned vector (a borrowed array is copied first).
    std::vector<T>& vector() {
        release();
        return own_;
    }
    T* data() { return vector().data(); }
    T& operator[](std::size_t i) { return vector()[i]; }
    T* begin() { return data(); }
    T* end() { return data() + size(); }
    void resize(std::size_t n, const T& v = T()) { vector().resize(n, v); }
    void reserve(std::size_t n) { vector().reserve(n); }
    void push_back(const T& v) { vector().push_back(v); }
    void assign(std::size_t n, const T& v) { vector().assign(n, v); }
    template <class It>
    void assign(It first, It last) {
        vector().assign(first, last);
    }
    /// Inserts [first, last) before `at` (a position of this array).
    template <class It>
    void insert(const T* at, It first, It last) {
        const std::ptrdiff_t offset = at - static_cast<const GaussianArray&>(*this).data();
        std::vector<T>& v = vector();
        v.insert(v.begin() + offset, first, last);
    }
    void clear() { vector().clear(); }

    friend bool operator==(const GaussianArray& a, const GaussianArray& b) {
        if (a.size() != b.size()) return false;
        for (std::size_t i = 0; i < a.size(); ++i)
            if (!(a[i] == b[i])) return false;
        return true;
    }

  private:
    /// A borrowed array becomes an owned copy.
    void release() {
        if (!borrowed()) return;
        own_.assign(borrowedData_, borrowedData_ + borrowedSize_);
        owner_.reset();
        borrowedData_ = nullptr;
        borrowedSize_ = 0;
    }
    std::vector<T> own_;
    const T* borrowedData_ = nullptr;
    std::size_t borrowedSize_ = 0;
    std::shared_ptr<const void> owner_;
};

struct GaussianScene {
    GaussianArray<glm::vec3> means;      ///< world positions
    GaussianArray<glm::vec3> scales;     ///< standard deviations along the local axes (> 0)
    GaussianArray<glm::vec4> rotations;  ///< unit quaternions (w, x, y, z)
    GaussianArray<float> opacities;      ///< in [0, 1]
    int shDegree = 0;                  ///< 0..3
    /// SH coefficients, shCount() x 3 floats per Gaussian: coefficient k of channel c of
    /// Gaussian i at sh[(i * shCount() + k) * 3 + c] (k = 0 is the file's f_dc).
    GaussianArray<float> sh;
    std::string source;  ///< how it was obtained, e.g. "3DGS PLY (scene.ply)"

    std::size_t size() const { return means.size(); }
    int shCount() const { return (shDegree + 1) * (shDegree + 1); }
    /// Throws splat::Error unless the arrays agree in size and every value is valid (finite
    /// means, scales > 0, unit quaternions to 1e-3, opacities in [0, 1], degree 0..3).
    void validate() const;
    /// Axis-aligned box of the means widened by three standard deviations of each Gaussian
    /// (its largest scale); empty scene: the unit box about the origin.
    void bounds(glm::dvec3& lo, glm::dvec3& hi) const;
    /// A volume without samples whose centre is the box's centre and whose bounding sphere is
    /// the box's: the geometry the Camera (orbit, fit) and the popping analysis take.
    Volume geometry() const;
};

/// Reads a 3DGS .ply (binary_little_endian; float properties by name: x y z, f_dc_0..2,
/// f_rest_* channel-major, opacity (logit), scale_0..2 (log), rot_0..3 (w, x, y, z; normalised
/// on load); other properties skipped). Throws splat::Error with one line on malformed files
/// (ASCII or big-endian PLY, missing properties, a truncated vertex block, a vertex count
/// larger than the file can hold — refused before anything is allocated).
GaussianScene loadGaussians(const std::string& path);
/// Writes `scene` as a 3DGS .ply (the properties above, normals 0), atomically. Opacities
/// 0 and 1 are written as logits of +-40 (sigmoid gives them back to float precision).
void writeGaussians(const GaussianScene& scene, const std::string& path);
/// True when `path` names a Gaussian scene: ends in .ply or starts with "gaussians:".
bool isGaussianScene(const std::string& path);
/// A generated scene: "gaussians:pop" (two overlapping isotropic Gaussians, red at x = -0.6,
/// blue at x = +0.6, sigma 1, opacity 0.8: their centre depths swap at azimuth 0 and 180),
/// "gaussians:random:N[:SEED]" (N Gaussians in the unit cube, random shape, colour, opacity,
/// SH degree 3). Throws splat::Error on an unknown name.
GaussianScene syntheticGaussians(const std::string& name);
/// loadGaussians or syntheticGaussians by the name's form.
GaussianScene openGaussians(const std::string& path);

/// A volume's pre-classified splats (dvr, `settings`' transfer function and Gaussian kernel)
/// as a 3DGS scene: one Gaussian per splat at its world position, scales sigma * spacing,
/// colour e / rho, opacity 1 - exp(-rho s / (2 pi sigma^2)) (s the voxel size): the density of
/// the volumetric model below is then the kernel's rho h (exact for isotropic spacing, up to
/// the kernel's truncation and the 0.99 clamp). Throws splat::Error for other kernels and
/// for oblique volumes of anisotropic spacing.
struct RenderSettings;
GaussianScene gaussiansFromVolume(const Volume& volume, const RenderSettings& settings);

/// The 3DGS colour of Gaussian i seen along unit direction `dir` (from the eye towards it):
/// 0.5 + sum_k sh_k Y_k(dir), clamped below at 0.
glm::vec3 gaussianColour(const GaussianScene& scene, std::size_t i, const glm::vec3& dir);

enum class GaussianRenderer { Rasterizer, PixelSorted, Sheet, Reference };
/// "3dgs", "3dgs-pixel", "sheet", "reference".
const char* gaussianRendererName(GaussianRenderer renderer);
/// The renderer of a name above; throws splat::Error listing them otherwise.
GaussianRenderer parseGaussianRenderer(const std::string& name);

struct GaussianRenderOptions {
    GaussianRenderer renderer = GaussianRenderer::Rasterizer;
    /// Sheet: slab thickness in world units along the view (0: 1/256 of the bounding
    /// sphere's diameter).
    double slab = 0;
    /// Reference: largest error per pixel and channel (premultiplied colour and alpha).
    double tolerance = 1e-5;
    int threads = 0;  ///< 0: all
};

/// Renders `scene` from `camera` (orbit about the scene's centre, free camera, perspective or
/// orthographic; splat/camera.h). Throws splat::Error on bad options.
Image renderGaussians(const GaussianScene& scene, const CameraParams& camera,
                      const GaussianRenderOptions& options = {});

}  // namespace splat
