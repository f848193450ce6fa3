#pragma once
// The shared compositing stage. A sheet becomes one compositing sample per pixel; samples
// are composited back-to-front with `over` (I = C + (1 - a) I) or front-to-back with
// `under` (I += (1 - b) C; b += (1 - b) a), colour premultiplied. Each screen tile owns one
// TileAccumulator, so no pixel is ever shared between threads.
#include <cmath>
#include <cstdint>
#include <type_traits>
#include <vector>

#include "frame/clip_cut.h"
#include "model/shading_model.h"
#include "model/transfer_table.h"
#include "splat/image.h"
#include "splat/settings.h"

namespace splat {

/// Opacity and premultiplied colour of a sheet pixel from its optical depth tau and
/// emission E: a = 1 - exp(-tau), C = E a / tau, with the tau -> 0 limit C -> E.
struct Sample {
    float alpha, r, g, b;
};
inline Sample sampleFromOpticalDepth(float tau, float er, float eg, float eb) {
    const float alpha = -std::expm1(-tau);
    // a / tau = 1 - tau/2 + tau^2/6 - ... ; the series is exact to float for tau < 1e-3.
    const float k = tau > 1e-3f ? alpha / tau : 1.0f - 0.5f * tau + tau * tau * (1.0f / 6.0f);
    return {alpha, er * k, eg * k, eb * k};
}

/// Composites n pixels of a row held in plain arrays (premultiplied r, g, b and opacity a) with
/// the samples of optical depths tau and emissions er, eg, eb in `order`: the lanes of
/// TileAccumulator::compositeOpticalDepths for accumulators that are not tiles (the
/// factorised sheets' intermediate image).
void compositeOpticalDepthRow(float* r, float* g, float* b, float* a, CompositeOrder order, int n,
                              const float* tau, const float* er, const float* eg,
                              const float* eb);

/// compositeOpticalDepthRow for samples interleaved in one array, (tau, er, eg, eb) per pixel,
/// which it then sets to zero (a sheet buffer ready for the next sheet).
void compositeInterleavedRowAndClear(float* r, float* g, float* b, float* a, CompositeOrder order,
                                     int n, float* samples);

/// Compositing state of one tile: premultiplied colour and opacity (b in docs/design.md) for
/// dvr; for mip the running maximum and for xray the running sum, both in r.
class TileAccumulator {
  public:
    /// `surface`: iso compositing, which keeps the previous sample and the hit position.
    TileAccumulator(int width, int height, CompositeOrder order, double earlyTermination,
                    bool surface = false);

    int width() const { return w_; }
    int height() const { return h_; }
    int size() const { return w_ * h_; }

    /// Where the tile lies in an image `imageWidth` pixels wide (per-pixel frame data: the
    /// clip cut); imageIndex maps a tile pixel to its image pixel.
    void setOrigin(int ox, int oy, int imageWidth) {
        ox_ = ox;
        oy_ = oy;
        imageWidth_ = imageWidth;
    }
    std::size_t imageIndex(int p) const {
        return std::size_t(oy_ + p / w_) * std::size_t(imageWidth_) + std::size_t(ox_ + p % w_);
    }

    void composite(int p, const Sample& s) {
        if (order_ == CompositeOrder::FrontToBack) {
            const float t = 1.0f - a_[p];
            r_[p] += t * s.r;
            g_[p] += t * s.g;
            b_[p] += t * s.b;
            a_[p] += t * s.alpha;
        } else {
            const float t = 1.0f - s.alpha;
            r_[p] = s.r + t * r_[p];
            g_[p] = s.g + t * g_[p];
            b_[p] = s.b + t * b_[p];
            a_[p] = s.alpha + t * a_[p];
        }
    }
    /// Pre-classified dvr: composites the n pixels p, p + 1, ... (one tile row) from their
    /// optical depths and emissions as composite(p + i, sampleFromOpticalDepth(tau[i], ...)),
    /// eight pixels at a time where the CPU has AVX2 (to float rounding: the lanes use their
    /// own exp).
    void compositeOpticalDepths(int p, int n, const float* tau, const float* er, const float* eg,
                                const float* eb);
    void maximum(int p, float v) { r_[p] = std::max(r_[p], v); }
    void add(int p, float v) { r_[p] += v; }

    /// The sheet being flushed, in visiting order (set by the tile sweep).
    void setSheet(std::uint32_t k) { sheet_ = k; }
    std::uint32_t sheet() const { return sheet_; }
    /// Iso: hit already? the previous sheet's value; record a hit (shaded colour, opaque) at
    /// the fractional sheet position `position` (sheet centres at integers).
    bool hit(int p) const { return a_[p] >= 1.0f; }
    float previous(int p) const { return prev_[p]; }
    void setPrevious(int p, float v) { prev_[p] = v; }
    void surfaceHit(int p, const glm::vec3& c, float position) {
        r_[p] = c.r;
        g_[p] = c.g;
        b_[p] = c.b;
        a_[p] = 1.0f;
        pos_[p] = position;
    }
    float hitPosition(int p) const { return pos_[p]; }
    void setHitPosition(int p, float position) { pos_[p] = position; }
    /// Iso: writes the hit positions (r; alpha 1 where hit, 0 where not) at (ox, oy).
    void resolvePositions(Image& image, int ox, int oy) const;

    /// Early termination (front-to-back dvr only): true when every pixel of the tile, or
    /// of the 4x4 blocks overlapping the tile-local inclusive rectangle, is opaque.
    bool terminates() const { return terminates_; }
    bool allOpaque() const { return terminates_ && opaqueBlocks_ == allBlocks_; }
    bool rectOpaque(int x0, int y0, int x1, int y1) const;
    /// Re-evaluates the opaque blocks inside the tile-local rectangle (after a sheet).
    void updateOpacity(int x0, int y0, int x1, int y1);

    /// Writes the tile's partial image into `image` at (ox, oy): premultiplied colour and
    /// opacity for dvr, the value in r, g, b with alpha 1 for mip and xray. The background
    /// is applied to the whole image afterwards (applyBackground).
    void resolve(Image& image, int ox, int oy, RenderMode mode) const;

  private:
    int w_, h_;
    int ox_ = 0, oy_ = 0, imageWidth_ = 0;
    CompositeOrder order_;
    bool terminates_;
    float threshold_;
    int blocksX_, blocksY_;
    std::uint64_t opaqueBlocks_ = 0, allBlocks_ = 0;
    std::uint32_t sheet_ = 0;
    std::vector<float> r_, g_, b_, a_;
    std::vector<float> prev_, pos_;  // iso only
};

/// The last step of a frame: dvr and iso pixels are composited over the background,
/// I = C + (1 - a) I_bg; mip pixels, the maximum of f - b along the ray (at least 0: every
/// ray sees b outside the volume), get the field's background value b added back; x-ray,
/// the integral of f - b, is left as it is.
void applyBackground(Image& image, RenderMode mode, const glm::vec4& background,
                     float fieldBackground);

// ---- compositing policies: one home per render mode -------------------------------
// A policy says how many channels a sheet pixel holds and where they come from (kSource),
// how a sheet pixel becomes a compositing sample (sheet -> sample) and how it is
// accumulated. `v` points at the pixel's first channel, channels `plane` floats apart;
// `len` is the world length of the pixel's ray through the sheet.

/// What a splat contributes to a sheet's channels.
enum class SheetSource {
    Emission,         ///< (rho, e_r, e_g, e_b): pre-classified dvr
    Density,          ///< (d): post-classified dvr, mip, xray
    DensityGradient,  ///< (d, g_x, g_y, g_z): post-classified shading / edges, iso
    Labels,  ///< (rho, e_r, e_g, e_b) of the intensity, then (weight, label) selected by max
};

/// Sheets of the label policy: four additive channels, then the largest kernel weight seen at
/// the pixel and its label (a select, not a sum: labels are never interpolated).
inline constexpr int kLabelChannels = 6;

/// Everything a policy may need of the frame (built once per frame: frame/policy_context.h).
struct PolicyContext {
    RenderMode mode = RenderMode::Dvr;
    Classification classification = Classification::Pre;
    const TransferTable* transfer = nullptr;
    /// Post-classified dvr carries gradient channels (shading or edges on).
    bool gradients = false;
    bool shade = false;  ///< post-classified dvr: shade each sample
    Shading shading;
    LightFrame light;
    EdgeEnhancement edges;
    float invGradientScale = 0;  ///< 1 / G (edge enhancement)
    float isoLevel = 0.5f;
    glm::vec3 isoColour{1.0f};
    /// Labels: colour and extinction (in a) per shown label; null without labels.
    const std::vector<glm::vec4>* labelTable = nullptr;
    /// Clipping: the per-pixel cut of the sheets; null when nothing is clipped.
    const ClipCut* cut = nullptr;
};

/// Pre-classified dvr: optical depth and emission, alpha = 1 - exp(-tau), C = E a / tau.
struct DvrPrePolicy {
    static constexpr int kChannels = 4;
    static constexpr bool kTerminates = true;
    static constexpr SheetSource kSource = SheetSource::Emission;
    void operator()(TileAccumulator& acc, int p, const float* v, std::size_t plane, float) const {
        acc.composite(p, sampleFromOpticalDepth(v[0], v[plane], v[2 * plane], v[3 * plane]));
    }
};

/// Post-classified dvr: the mean density over the ray's path through the sheet is
/// classified per pixel; alpha = 1 - exp(-rho len).
struct DvrPostPolicy {
    static constexpr int kChannels = 1;
    static constexpr bool kTerminates = true;
    static constexpr SheetSource kSource = SheetSource::Density;
    const TransferTable* transfer;
    void operator()(TileAccumulator& acc, int p, const float* v, std::size_t, float len) const {
        float rho, r, g, b;
        transfer->lookup(v[0] / len, rho, r, g, b);
        const float alpha = -std::expm1(-rho * len);
        acc.composite(p, {alpha, r * alpha, g * alpha, b * alpha});
    }
};

/// Post-classified dvr with gradient channels: the mean density is classified, its opacity
/// scaled by the edge factor of the mean gradient's magnitude and its colour shaded with the
/// mean gradient as the normal (the one model of model/shading_model.h).
struct DvrPostGradientPolicy {
    static constexpr int kChannels = 4;
    static constexpr bool kTerminates = true;
    static constexpr SheetSource kSource = SheetSource::DensityGradient;
    const PolicyContext* ctx;
    void operator()(TileAccumulator& acc, int p, const float* v, std::size_t plane,
                    float len) const {
        const float inv = 1.0f / len;
        float rho, r, g, b;
        ctx->transfer->lookup(v[0] * inv, rho, r, g, b);
        const float gx = v[plane] * inv, gy = v[2 * plane] * inv, gz = v[3 * plane] * inv;
        if (ctx->edges.enabled())
            rho *= edgeFactor(ctx->edges,
                              std::sqrt(gx * gx + gy * gy + gz * gz) * ctx->invGradientScale);
        if (ctx->shade) {
            const LightTerms t = blinnPhongGradient(ctx->shading, ctx->light, gx, gy, gz);
            r = r * t.diffuse + t.specular;
            g = g * t.diffuse + t.specular;
            b = b * t.diffuse + t.specular;
        }
        const float alpha = -std::expm1(-rho * len);
        acc.composite(p, {alpha, r * alpha, g * alpha, b * alpha});
    }
};

/// Iso surface through the sheets (front to back): the first sheet whose mean density
/// reaches the level after one below it is the hit; its position is interpolated linearly
/// between the two sheet centres and the surface is shaded with the sheet's mean gradient.
struct IsoPolicy {
    static constexpr int kChannels = 4;
    static constexpr bool kTerminates = true;
    static constexpr SheetSource kSource = SheetSource::DensityGradient;
    const PolicyContext* ctx;
    void operator()(TileAccumulator& acc, int p, const float* v, std::size_t plane,
                    float len) const {
        if (acc.hit(p)) return;
        const float inv = 1.0f / len;
        const float f = v[0] * inv, prev = acc.previous(p), level = ctx->isoLevel;
        if (f >= level && prev < level) {
            const float t = (level - prev) / (f - prev);
            const LightTerms l = blinnPhongGradient(ctx->shading, ctx->light, v[plane] * inv,
                                                    v[2 * plane] * inv, v[3 * plane] * inv);
            const float spec = ctx->shading.enabled ? l.specular : 0.0f;
            acc.surfaceHit(p, ctx->isoColour * l.diffuse + spec, float(acc.sheet()) - 1.0f + t);
        } else {
            acc.setPrevious(p, f);
        }
    }
};

/// Segmentation labels (nearest-label classification per sheet pixel): the label whose kernel
/// weighs most at the pixel fills the ray's path through the sheet with its colour and
/// extinction, added to the intensity's pre-classified optical depth and emission.
struct LabelPolicy {
    static constexpr int kChannels = kLabelChannels;
    static constexpr bool kTerminates = true;
    static constexpr SheetSource kSource = SheetSource::Labels;
    const PolicyContext* ctx;
    void operator()(TileAccumulator& acc, int p, const float* v, std::size_t plane,
                    float len) const {
        float tau = v[0], er = v[plane], eg = v[2 * plane], eb = v[3 * plane];
        if (v[4 * plane] > 0.0f) {
            const std::size_t label = std::size_t(v[5 * plane]);
            const std::vector<glm::vec4>& table = *ctx->labelTable;
            if (label < table.size() && table[label].a > 0.0f) {
                const glm::vec4 c = table[label];
                const float t = c.a * len;
                tau += t;
                er += c.r * t;
                eg += c.g * t;
                eb += c.b * t;
            }
        }
        if (tau > 0.0f) acc.composite(p, sampleFromOpticalDepth(tau, er, eg, eb));
    }
};

/// MIP: the maximum over sheets of the mean of f - b over the ray's path through each (b is
/// added to the image by applyBackground).
struct MipPolicy {
    static constexpr int kChannels = 1;
    static constexpr bool kTerminates = false;
    static constexpr SheetSource kSource = SheetSource::Density;
    void operator()(TileAccumulator& acc, int p, const float* v, std::size_t, float len) const {
        acc.maximum(p, v[0] / len);
    }
};

/// X-ray: the line integral of f - b, the sum over sheets.
struct XrayPolicy {
    static constexpr int kChannels = 1;
    static constexpr bool kTerminates = false;
    static constexpr SheetSource kSource = SheetSource::Density;
    void operator()(TileAccumulator& acc, int p, const float* v, std::size_t, float) const {
        acc.add(p, v[0]);
    }
};

/// Clipping (frame/clip_cut.h): the part of a sheet pixel's path outside the kept region is
/// cut off. The sheet's additive channels (integrals along the path) and its path length are
/// scaled by the kept fraction, so means (density, gradient) are unchanged and optical depth,
/// emission and line integrals shrink with the path; a sheet wholly outside is skipped (mip
/// never sees it, iso keeps the previous sheet's value), one wholly inside is untouched.
template <class Inner>
struct ClippedPolicy {
    static constexpr int kChannels = Inner::kChannels;
    static constexpr bool kTerminates = Inner::kTerminates;
    static constexpr SheetSource kSource = Inner::kSource;
    Inner inner;
    const ClipCut* cut;
    void operator()(TileAccumulator& acc, int p, const float* v, std::size_t plane,
                    float len) const {
        const std::size_t q = acc.imageIndex(p);
        const float f = cut->fraction(q, acc.sheet());
        if (!(f > 0.0f)) return;
        constexpr bool surface = std::is_same_v<Inner, IsoPolicy>;
        const bool before = surface && acc.hit(p);
        if (f >= 1.0f) {
            inner(acc, p, v, plane, len);
        } else {
            // Labels: the (weight, label) select channels are not integrals.
            constexpr int kAdditive = kSource == SheetSource::Labels ? 4 : kChannels;
            float c[kChannels];
            for (int i = 0; i < kChannels; ++i)
                c[i] = v[std::size_t(i) * plane] * (i < kAdditive ? f : 1.0f);
            inner(acc, p, c, 1, len * f);
        }
        // Iso (front to back): nothing lies in front of the kept region, so a surface found
        // in the sheet holding its entry is no nearer than the entry (the cap of the cut).
        if (surface && !before && acc.hit(p))
            acc.setHitPosition(p, std::max(acc.hitPosition(p), cut->entry(q)));
    }
};

/// Iso compositing (the accumulator keeps hit positions), also when cut by clipping.
template <class P>
inline constexpr bool kSurfacePolicy = std::is_same_v<P, IsoPolicy>;
template <class P>
inline constexpr bool kSurfacePolicy<ClippedPolicy<P>> = kSurfacePolicy<P>;

/// Calls f(policy) with the compositing policy of the frame's mode and classification (cut
/// by the clipping when the frame clips).
template <class F>
decltype(auto) withPolicy(const PolicyContext& ctx, F&& f) {
    auto run = [&](auto policy) {
        using P = decltype(policy);
        if (ctx.cut) return f(ClippedPolicy<P>{policy, ctx.cut});
        return f(policy);
    };
    switch (ctx.mode) {
        case RenderMode::Mip:
            return run(MipPolicy{});
        case RenderMode::Xray:
            return run(XrayPolicy{});
        case RenderMode::Iso:
            return run(IsoPolicy{&ctx});
        default:
            if (ctx.labelTable) return run(LabelPolicy{&ctx});
            if (ctx.classification == Classification::Pre) return run(DvrPrePolicy{});
            if (ctx.gradients) return run(DvrPostGradientPolicy{&ctx});
            return run(DvrPostPolicy{ctx.transfer});
    }
}

}  // namespace splat
