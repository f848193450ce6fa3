// Classification: voxels -> splat list, keeping only the voxels the scene needs.
#include "splat/classify.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "model/clip_region.h"
#include "model/shading_model.h"
#include "splat/error.h"

namespace splat {

namespace {

constexpr int kBrick = 8;
constexpr std::size_t kPaletteSize = 65536;  // entries a 16-bit emission index can address

// Post-classification and the transfer-function-free modes need every non-zero voxel
// whose neighbourhood can become visible. A brick is needed when the transfer function
// is visible somewhere in the value range of the brick widened by the kernel radius
// (and by the background value b, since near the border the field tends to b).
std::vector<char> neededBricks(const Volume& v, const TransferFunction& tf, int pad,
                               glm::ivec3& bricks) {
    bricks = (v.dims + kBrick - 1) / kBrick;
    std::vector<char> need(std::size_t(bricks.x) * bricks.y * bricks.z, 0);
    tbb::parallel_for(0, bricks.z, [&](int bz) {
        for (int by = 0; by < bricks.y; ++by)
            for (int bx = 0; bx < bricks.x; ++bx) {
                const glm::ivec3 b(bx, by, bz);
                const glm::ivec3 lo = glm::max(b * kBrick - pad, glm::ivec3(0));
                const glm::ivec3 hi = glm::min((b + 1) * kBrick + pad, v.dims);
                float mn = v.background, mx = v.background;
                for (int k = lo.z; k < hi.z; ++k)
                    for (int j = lo.y; j < hi.y; ++j)
                        for (int i = lo.x; i < hi.x; ++i) {
                            const float d = v.at(i, j, k);
                            mn = std::min(mn, d);
                            mx = std::max(mx, d);
                        }
                need[(std::size_t(bz) * bricks.y + by) * bricks.x + bx] = !tf.invisibleOver(mn, mx);
            }
    });
    return need;
}

// grad d by central differences in world units. Beyond the border the field is the
// background value b (f -> b outside the data), so a face voxel's missing neighbour is b:
// tissue cut by a face has a surface there, as the reference sees in the field.
glm::dvec3 gradientAt(const Volume& v, int i, int j, int k) {
    glm::dvec3 g(0.0);
    const int p[3] = {i, j, k};
    const double b = v.background;
    for (int a = 0; a < 3; ++a) {
        int lo[3] = {i, j, k}, hi[3] = {i, j, k};
        lo[a] = p[a] - 1;
        hi[a] = p[a] + 1;
        const double dlo = lo[a] >= 0 ? double(v.at(lo[0], lo[1], lo[2])) : b;
        const double dhi = hi[a] < v.dims[a] ? double(v.at(hi[0], hi[1], hi[2])) : b;
        g[a] = (dhi - dlo) / (2.0 * v.spacing[a]);
    }
    return g;
}

glm::dvec3 normalAt(const Volume& v, int i, int j, int k) {
    const glm::dvec3 g = gradientAt(v, i, j, k);
    const double len = glm::length(g);
    return len > 0 ? -g / len : glm::dvec3(0.0);
}

}  // namespace

void shadeEmission(const SplatList& s, const Shading& sh, const glm::dvec3& view,
                   std::vector<float>& r, std::vector<float>& g, std::vector<float>& b) {
    const std::size_t n = s.size();
    r.resize(n);
    g.resize(n);
    b.resize(n);
    const LightFrame light = lightFrame(sh, view);
    const bool hasNormals = s.nx.size() == n;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 8192),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                          for (std::size_t q = range.begin(); q != range.end(); ++q) {
                              const LightTerms t =
                                  hasNormals ? blinnPhong(sh, light, s.nx[q], s.ny[q], s.nz[q])
                                             : LightTerms{sh.ambient + sh.diffuse, sh.specular};
                              const glm::vec4 e = s.emission(q);
                              const float spec = t.specular * e.x;
                              r[q] = e.y * t.diffuse + spec;
                              g[q] = e.z * t.diffuse + spec;
                              b[q] = e.w * t.diffuse + spec;
                          }
                      });
}

std::vector<std::uint16_t> shownLabels(const Volume& volume, const Labels& labels) {
    const Volume& lv = labels.volume ? *labels.volume : volume;
    if (lv.dims != volume.dims || !lv.hasSamples())
        throw Error("the label volume's dimensions differ from the volume's");
    std::vector<std::uint16_t> out(lv.voxelCount(), 0);
    for (std::size_t n = 0; n < out.size(); ++n) {
        const float d = lv.value(n);
        const int label = d >= 0.0f && d < 65536.0f ? int(std::lround(d)) : 0;
        if (labels.shown(label).a > 0.0f) out[n] = std::uint16_t(label);
    }
    return out;
}

namespace {
// Voxels within `r` (box) of a shown label: separable dilation of the label mask.
std::vector<std::uint8_t> nearLabels(const Volume& v, const std::vector<std::uint16_t>& shown,
                                     int r) {
    std::vector<std::uint8_t> m(shown.size()), t(shown.size());
    for (std::size_t n = 0; n < shown.size(); ++n) m[n] = shown[n] != 0;
    const glm::ivec3 d = v.dims;
    for (int axis = 0; axis < 3; ++axis) {
        const std::size_t stride =
            axis == 0 ? 1 : (axis == 1 ? std::size_t(d.x) : std::size_t(d.x) * d.y);
        tbb::parallel_for(0, d.z, [&](int k) {
            for (int j = 0; j < d.y; ++j)
                for (int i = 0; i < d.x; ++i) {
                    const int p[3] = {i, j, k};
                    const std::size_t n = v.index(i, j, k);
                    std::uint8_t any = 0;
                    for (int o = -r; o <= r && !any; ++o) {
                        const int q = p[axis] + o;
                        if (q < 0 || q >= d[axis]) continue;
                        any = m[std::size_t(std::int64_t(n) +
                                            std::int64_t(o) * std::int64_t(stride))];
                    }
                    t[n] = any;
                }
        });
        std::swap(m, t);
    }
    return m;
}
}  // namespace

float maxGradientMagnitude(const Volume& v) {
    return tbb::parallel_reduce(
        tbb::blocked_range<int>(0, v.dims.z), 0.0f,
        [&](const tbb::blocked_range<int>& ks, float m) {
            for (int k = ks.begin(); k != ks.end(); ++k)
                for (int j = 0; j < v.dims.y; ++j)
                    for (int i = 0; i < v.dims.x; ++i)
                        m = std::max(m, float(glm::length(gradientAt(v, i, j, k))));
            return m;
        },
        [](float a, float b) { return std::max(a, b); });
}

void SplatList::expandEmission() {
    if (!paletted()) return;
    const std::size_t n = size();
    for (auto* a : {&density, &extinction, &r, &g, &b}) a->resize(n);
    for (std::size_t q = 0; q < n; ++q) {
        density[q] = paletteDensity[emissionIndex[q]];
        const glm::vec4 e = palette[emissionIndex[q]];
        extinction[q] = e.x;
        r[q] = e.y;
        g[q] = e.z;
        b[q] = e.w;
    }
    palette.clear();
    paletteDensity.clear();
    std::vector<std::uint16_t>().swap(emissionIndex);
}

std::size_t SplatList::bytes() const {
    std::size_t total = 0;
    for (const auto* a : {&i, &j, &k, &emissionIndex}) total += a->size() * sizeof(std::uint16_t);
    total += palette.size() * sizeof(glm::vec4) + paletteDensity.size() * sizeof(float);
    for (const auto* a : {&density, &extinction, &r, &g, &b, &nx, &ny, &nz, &gx, &gy, &gz, &label})
        total += a->size() * sizeof(float);
    return total;
}

SplatList classify(const Volume& volume, const TransferFunction& tf, RenderMode mode,
                   Classification classification, double radius, bool normals) {
    ClassifyOptions o;
    o.normals = normals;
    return classify(volume, tf, mode, classification, radius, o);
}

namespace {

/// Which voxels classify keeps and what each carries: the options resolved for one volume.
struct VoxelRule {
    const Volume& volume;
    const TransferFunction& tf;
    const ClassifyOptions& options;
    bool usesTf, pre, edges, gradients, clips, labelled, intensity;
    glm::ivec3 bricks{0};
    std::vector<char> need;  ///< per brick of kBrick^3 (post-classification only)
    float maxGradient = 0, invMaxGradient = 0;
    glm::dvec3 clipMargin;
    std::vector<std::uint16_t> shown;  ///< labels: the shown label of every voxel
    std::vector<std::uint8_t> near;    ///< labels: voxels within the radius of a shown label

    VoxelRule(const Volume& v, const TransferFunction& t, RenderMode mode,
              Classification classification, double radius, const ClassifyOptions& o)
        : volume(v), tf(t), options(o) {
        usesTf = mode == RenderMode::Dvr;
        pre = usesTf && classification == Classification::Pre;
        if (usesTf && !pre) need = neededBricks(volume, tf, int(std::ceil(radius)), bricks);
        edges = pre && options.edges.enabled();
        gradients = options.gradients;
        maxGradient = edges || gradients ? maxGradientMagnitude(volume) : 0.0f;
        invMaxGradient = maxGradient > 0.0f ? 1.0f / maxGradient : 0.0f;
        clips = options.clipping.enabled();
        clipMargin = (options.clipMargin > 0 ? options.clipMargin : radius) * volume.spacing;
        labelled = options.labels && options.labels->enabled;
        intensity = !labelled || options.labels->volume != nullptr;
        if (labelled) {
            shown = shownLabels(volume, *options.labels);
            near = nearLabels(volume, shown, int(std::ceil(radius)));
        }
    }

    /// Edge enhancement of pre-classified opacity: the factor of voxel (i, j, k).
    float edgeOf(int i, int j, int k) const {
        return edgeFactor(options.edges,
                          float(glm::length(gradientAt(volume, i, j, k))) * invMaxGradient);
    }

    bool keep(int i, int j, int k, float value) const {
        // Clipping keeps every voxel whose kernel reaches the kept region: the renderers cut
        // the reconstructed field at the planes and box (model/clip_region.h). Tested last:
        // most voxels of a sparse volume fail the value test first.
        return keepsValue(i, j, k, value) &&
               (!clips ||
                keepsNear(options.clipping, volume.world(glm::dvec3(i, j, k)), clipMargin));
    }

    bool keepsValue(int i, int j, int k, float value) const {
        if (labelled) {
            if (near[volume.index(i, j, k)]) return true;
            if (!intensity) return false;
        }
        if (pre) return tf.extinction(value) > 0.0f && (!edges || edgeOf(i, j, k) > 0.0f);
        if (value == volume.background &&
            !(gradients && glm::length(gradientAt(volume, i, j, k)) > 0.0))
            return false;
        if (need.empty()) return true;
        return need[(std::size_t(k / kBrick) * bricks.y + j / kBrick) * bricks.x + i / kBrick] != 0;
    }

    /// (rho, e) of a voxel of value `value` (its edge factor, if any, applied by the caller).
    glm::vec4 emissionOf(float value) const {
        if (!(usesTf && intensity)) return glm::vec4(0.0f);
        const glm::vec4 c = tf.sample(value);
        const float rho = tf.extinctionFromOpacity(c.a);
        return glm::vec4(rho, c.r * rho, c.g * rho, c.b * rho);
    }
};

/// The kept voxels per z-slice: slice k's splats are list positions [start[k], start[k + 1]).
/// With `byValue`, also the distinct kept values, sorted (gathered only while they may fit
/// a palette: more than kPaletteSize of them means no palette).
struct KeptVoxels {
    std::vector<std::size_t> start;
    std::vector<float> distinct;
};

/// Step "count": the first of two passes over z-slices (count, then fill), which keep the
/// list in (k, j, i) order for any thread count.
KeptVoxels countKept(const VoxelRule& rule, bool byValue) {
    const glm::ivec3 d = rule.volume.dims;
    KeptVoxels kept;
    std::vector<std::vector<float>> sliceValues(byValue ? std::size_t(d.z) : 0);
    std::vector<std::size_t>& count = kept.start;
    count.assign(std::size_t(d.z) + 1, 0);
    tbb::parallel_for(0, d.z, [&](int k) {
        std::size_t n = 0;
        std::vector<float> values;
        for (int j = 0; j < d.y; ++j)
            for (int i = 0; i < d.x; ++i) {
                const float value = rule.volume.at(i, j, k);
                if (!rule.keep(i, j, k, value)) continue;
                ++n;
                if (byValue && (values.empty() || values.back() != value)) values.push_back(value);
            }
        if (byValue) {
            std::sort(values.begin(), values.end());
            values.erase(std::unique(values.begin(), values.end()), values.end());
            sliceValues[std::size_t(k)] = std::move(values);
        }
        count[std::size_t(k) + 1] = n;
    });
    for (int k = 0; k < d.z; ++k) count[std::size_t(k) + 1] += count[std::size_t(k)];
    std::vector<float>& distinct = kept.distinct;
    for (auto& v : sliceValues) {
        distinct.insert(distinct.end(), v.begin(), v.end());
        std::vector<float>().swap(v);
        if (distinct.size() > (std::size_t(1) << 20)) {  // keep the merge small
            std::sort(distinct.begin(), distinct.end());
            distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
            if (distinct.size() > kPaletteSize) break;
        }
    }
    std::sort(distinct.begin(), distinct.end());
    distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
    return kept;
}

/// Step "allocate": a list of `n` splats with the arrays the rule asks for, emission by
/// palette index when `paletted` (the palette made here from `distinct`).
SplatList allocateList(const VoxelRule& rule, std::size_t n, bool paletted, bool normals,
                       const std::vector<float>& distinct) {
    const Volume& volume = rule.volume;
    SplatList s;
    const float b = volume.background;
    s.background = b;
    s.gradientScale = rule.maxGradient;
    s.voxels = volume.voxelCount();
    s.origin = volume.origin;
    s.spacing = volume.spacing;
    if (paletted) {
        s.palette.resize(distinct.size());
        for (std::size_t q = 0; q < distinct.size(); ++q)
            s.palette[q] = rule.emissionOf(distinct[q]);
        s.paletteDensity = distinct;
        for (float& v : s.paletteDensity) v -= b;
        s.emissionIndex.resize(n);
    } else {
        s.density.resize(n);
        // Only what the mode needs: mip, x-ray and iso read the density alone, so their
        // splats carry no emission (16 bytes a splat less).
        if (rule.usesTf)
            for (auto* a : {&s.extinction, &s.r, &s.g, &s.b}) a->resize(n);
    }
    for (auto* a : {&s.i, &s.j, &s.k}) a->resize(n);
    if (normals)
        for (auto* a : {&s.nx, &s.ny, &s.nz}) a->resize(n);
    if (rule.gradients)
        for (auto* a : {&s.gx, &s.gy, &s.gz}) a->resize(n);
    if (rule.labelled) s.label.resize(n);
    return s;
}

/// Step "fill": the second pass, every kept voxel of slice k written at positions from
/// kept.start[k] on.
void fillList(const VoxelRule& rule, const KeptVoxels& kept, bool paletted, bool normals,
              SplatList& s) {
    const Volume& volume = rule.volume;
    const glm::ivec3 d = volume.dims;
    const float b = volume.background;
    const std::vector<float>& distinct = kept.distinct;
    tbb::parallel_for(0, d.z, [&](int k) {
        std::size_t o = kept.start[std::size_t(k)];
        for (int j = 0; j < d.y; ++j)
            for (int i = 0; i < d.x; ++i) {
                const float value = volume.at(i, j, k);
                if (!rule.keep(i, j, k, value)) continue;
                s.i[o] = std::uint16_t(i);
                s.j[o] = std::uint16_t(j);
                s.k[o] = std::uint16_t(k);
                if (!paletted) s.density[o] = value - b;
                if (rule.labelled) s.label[o] = float(rule.shown[volume.index(i, j, k)]);
                if (paletted) {
                    s.emissionIndex[o] =
                        std::uint16_t(std::lower_bound(distinct.begin(), distinct.end(), value) -
                                      distinct.begin());
                } else if (rule.usesTf) {
                    glm::vec4 e = rule.emissionOf(value);
                    if (rule.edges && e.x != 0.0f) {
                        const float f = rule.edgeOf(i, j, k);
                        const glm::vec4 c = rule.tf.sample(value);
                        e.x *= f;
                        e = glm::vec4(e.x, c.r * e.x, c.g * e.x, c.b * e.x);
                    }
                    s.extinction[o] = e.x;
                    s.r[o] = e.y;
                    s.g[o] = e.z;
                    s.b[o] = e.w;
                }
                if (normals) {
                    const glm::dvec3 n = normalAt(volume, i, j, k);
                    s.nx[o] = float(n.x);
                    s.ny[o] = float(n.y);
                    s.nz[o] = float(n.z);
                }
                if (rule.gradients) {
                    const glm::dvec3 g = gradientAt(volume, i, j, k);
                    s.gx[o] = float(g.x);
                    s.gy[o] = float(g.y);
                    s.gz[o] = float(g.z);
                }
                ++o;
            }
    });
}

}  // namespace

SplatList classify(const Volume& volume, const TransferFunction& tf, RenderMode mode,
                   Classification classification, double radius, const ClassifyOptions& options) {
    const glm::ivec3 d = volume.dims;
    if (d.x > 65535 || d.y > 65535 || d.z > 65535)
        throw Error("volume dimension above 65535 is not supported by the splat list");
    if (tf.normalized)
        throw Error("internal: transfer function must be resolved before classification");
    const VoxelRule rule(volume, tf, mode, classification, radius, options);
    // Emission depends on the value alone unless edge enhancement scales it per voxel: then
    // the distinct kept values (gathered by the count pass) may index a palette.
    const bool byValue = options.compactEmission && !rule.edges;
    const KeptVoxels kept = countKept(rule, byValue);
    const std::size_t n = kept.start.back();
    const bool paletted = byValue && n > 0 && kept.distinct.size() <= kPaletteSize;
    SplatList s = allocateList(rule, n, paletted, options.normals, kept.distinct);
    fillList(rule, kept, paletted, options.normals, s);
    return s;
}

}  // namespace splat
