#pragma once
// Classification: turns the voxels that the scene needs into a splat list (structure of
// arrays). Only what is visible is modelled: with pre-classification a voxel becomes a
// splat only if its extinction is > 0; with post-classification (and for xray/mip) only
// voxels with d != 0 in bricks whose value range, widened by the kernel radius, can be
// made visible by the transfer function.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "splat/settings.h"
#include "splat/transfer.h"
#include "splat/volume.h"

namespace splat {

struct SplatList {
    std::vector<std::uint16_t> i, j, k;  ///< index position
    /// The volume's grid: a splat's world position is origin + spacing (i, j, k), computed
    /// when needed (world()) rather than stored beside the index position.
    glm::dvec3 origin{0.0}, spacing{1.0};
    /// The volume's background value b (docs/design.md "Reconstructed fields"): density
    /// holds d_i - b, so that sum (d_i - b) h is the field minus b and a voxel equal to b
    /// needs no splat; whoever reads the field adds b back (x-ray integrates f - b).
    float background = 0.0f;
    std::vector<float> density;     ///< d_i - b (empty when paletted: read densityOf(n))
    std::vector<float> extinction;  ///< rho_i = f_rho(d_i), per world unit (pre)
    std::vector<float> r, g, b;     ///< premultiplied emission e_i = colour * rho_i (pre)
    /// Emission by value (ClassifyOptions::compactEmission): when rho_i and e_i depend on d_i
    /// alone and the splats take at most 65536 distinct values, `palette` holds
    /// (rho, e_r, e_g, e_b) per distinct value and `paletteDensity` the value itself,
    /// `emissionIndex` each splat's entry, and density, extinction, r, g, b stay empty
    /// (2 bytes per splat instead of 20). Read emission(n) and densityOf(n).
    std::vector<glm::vec4> palette;
    std::vector<float> paletteDensity;
    std::vector<std::uint16_t> emissionIndex;
    bool paletted() const { return !palette.empty(); }
    /// d_n, from the palette or the array.
    float densityOf(std::size_t n) const {
        return paletted() ? paletteDensity[emissionIndex[n]] : density[n];
    }
    /// (rho_n, e_r, e_g, e_b) of splat n, from the palette or the arrays.
    glm::vec4 emission(std::size_t n) const {
        return paletted() ? palette[emissionIndex[n]] : glm::vec4(extinction[n], r[n], g[n], b[n]);
    }
    /// Fills density, extinction, r, g, b from the palette and drops it (for code that needs
    /// arrays).
    void expandEmission();
    /// Unit normals -grad d / |grad d| (central differences in world units), only when
    /// classify() was asked for them (shading); empty otherwise.
    std::vector<float> nx, ny, nz;
    /// World gradient of d (central differences), only when asked for (post-classified
    /// shading or edges, iso in the splatters): the sheets splat it with the same kernel.
    std::vector<float> gx, gy, gz;
    /// Largest central-difference gradient magnitude of the volume (edge enhancement's G);
    /// 0 when not computed.
    float gradientScale = 0;
    /// Segmentation labels: the shown label of each splat's voxel (0: background, or not
    /// shown), only when the scene has labels.
    std::vector<float> label;
    std::size_t voxels = 0;  ///< voxels considered
    std::size_t size() const { return i.size(); }
    /// World position of splat n.
    glm::dvec3 world(std::size_t n) const {
        return origin + spacing * glm::dvec3(double(i[n]), double(j[n]), double(k[n]));
    }
    /// Bytes held per splat by the arrays in use, times the splat count.
    std::size_t bytes() const;
};

/// What a scene asks of classification beyond the transfer function.
struct ClassifyOptions {
    bool normals = false;    ///< unit normals (pre-classified shading)
    bool gradients = false;  ///< gx, gy, gz; voxels with d == 0 but a gradient are kept
    EdgeEnhancement edges;   ///< pre-classified dvr: rho and e scaled per voxel
    Clipping clipping;       ///< voxels outside are dropped
    /// Voxels farther than this (index units) from the kept region are dropped; 0: the
    /// kernel radius (what a renderer that cuts the field along the ray needs). The
    /// axis-aligned splatter, whose sheets hold whole kernels, needs clipReach(radius)
    /// (model/clip_region.h).
    double clipMargin = 0;
    /// Labels (enabled): voxels within the kernel radius of a shown label become splats
    /// carrying their label (so the background competes at region borders); without a label
    /// volume the scene volume holds the labels and has no intensity part.
    const Labels* labels = nullptr;
    /// Store emission by value (SplatList::palette) where it can be: a Scene's own list.
    bool compactEmission = false;
};

/// The shown label (Labels::shown) of every voxel of the label volume, 0 elsewhere.
std::vector<std::uint16_t> shownLabels(const Volume& volume, const Labels& labels);

/// Builds the splat list. `tf` must be resolved (absolute densities). For `Xray` and
/// `Mip` the transfer function is not used: every voxel with d != 0 is a splat. `radius`
/// is the kernel radius in voxels (for the brick dilation of post-classification).
/// Throws splat::Error if a dimension exceeds 65535.
SplatList classify(const Volume& volume, const TransferFunction& tf, RenderMode mode,
                   Classification classification, double radius, bool normals = false);
SplatList classify(const Volume& volume, const TransferFunction& tf, RenderMode mode,
                   Classification classification, double radius, const ClassifyOptions& options);

/// Largest central-difference gradient magnitude (world units) over the volume.
float maxGradientMagnitude(const Volume& volume);

/// Shaded emission of every splat for a view direction (needs normals): the Blinn-Phong model
/// of splat/settings.h, e' = e (ambient + diffuse |n.l|) + specular |n.h|^shininess rho.
void shadeEmission(const SplatList& splats, const Shading& shading, const glm::dvec3& view,
                   std::vector<float>& r, std::vector<float>& g, std::vector<float>& b);

}  // namespace splat
