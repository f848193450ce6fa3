// The reference ray caster (docs/design.md "The model"): one ray per pixel through the
// continuous fields f(x) = b + sum_i (d_i - b) h(|S^-1 (x - x_i)|) (b the volume's background
// value; the grids hold f - b) and rho, e for pre-classification,
// integrated with error control.
//
// Acceleration (exact, no change of the model):
//  - the splat list is scattered into a dense per-voxel grid (absent splats are 0), so a
//    field sample visits only the (2R + 1)^3 lattice points around it;
//  - a brick grid (4^3 voxels) marks bricks whose points lie within R of a non-zero voxel;
//    each ray is clipped to the volume bounds padded by R and cut into the segments that
//    cross marked bricks (3D DDA); the fields are exactly 0 elsewhere;
//  - h is tabulated in u^2 (65536 entries, linear interpolation; its error is far below
//    1e-6 of the peak, see tests/test_reference.cpp); the default tapered Gaussian is
//    evaluated separably, four lattice points a vector (field.h, SeparableGaussian);
//  - dvr rays stop where what follows cannot move the pixel by 1% of the tolerance (below).
//
// Error control, per ray (each pixel is computed independently, so the image does not
// depend on the thread count): each segment is integrated with composite Simpson at sample
// spacing s = settings.referenceStep voxels (one voxel = the smallest spacing), then s/2,
// s/4, ... reusing the samples of the coarser pass, until the pixel's RGBA changes by at
// most settings.referenceTolerance (for xray: tolerance * max(1, |value|), the values being
// world lengths) or kMaxLevels halvings were made. The result of the finest pass is used.
// stats->referenceStep is the finest spacing any ray needed. First step: settings'
// referenceStep, or when it is 0 referenceStepFor() (dvr with panel adaptivity: 1.75 kernel
// deviations in [0.25, 1], i.e. 1 voxel for the default Gaussian; else 0.25).
//
// Panel adaptivity (dvr with the automatic first step, referenceStep = 0, and
// ReferenceAcceleration::panelAdaptive; the other modes and explicit steps halve the whole ray
// as above): each segment is cut into panels of two first steps h0; a panel p
// holds its samples at spacing h0 / 2^L_p (L_p >= 1) and the Simpson values of its optical
// depth tau_p and of its emission attenuated from its start E_p, at L_p and at L_p - 1. The
// pixel is C = sum_p T_p E_p, T_p = exp(-sum_{q<p} tau_q), alpha = 1 - T_end. Changing one
// panel's (tau_p, E_p) by (dtau, dE) changes C by T_p dE - dtau * sum_{q>p} T_q E_q and alpha
// by T_end dtau, to first order; eps_p is the largest |.| of these over the channels with
// (dtau, dE) = (level L_p) - (level L_p - 1). The ray is accepted when
// sum_p eps_p <= tol / 16: then the image with every panel one level coarser differs from
// the result by at most tol / 16 to first order (triangle inequality) -- the whole-ray
// criterion |C_L - C_{L-1}| <= tol, made 16x stricter and summed over panels in absolute
// value. Otherwise the panels of largest eps (by binary exponent) are halved until the rest,
// the halved ones' eps taken to fall 16x (Simpson), is within the bound, and the test is
// repeated (at most kMaxPanelLevels halvings a panel). The factor 1/16 is calibrated: with it
// the images are no further from a tight truth than the whole-ray scheme's at its default
// first step 0.25 (docs/accuracy.md: ch2 256^2 at 30 degrees, RMSE 2.8e-7 vs 3.0e-7), at ~60% of
// its samples. Early termination as below, at panel granularity, re-checked after refinement.
//
//  - dvr: optical depth tau(t) by Simpson/quadratic interpolation of rho at every sample,
//    I = int e exp(-tau) by Simpson. Early termination: a ray stops once
//    T < 0.01 * min(tolerance, 1e-4) / B. What follows the stop is
//    rest = int e exp(-tau) <= B (T - T_end) per colour channel, where B >= e / rho
//    everywhere (pre-classified: the largest voxel ratio e_i / rho_i, which bounds
//    e(x) / rho(x) because h >= 0 makes it a weighted mean of them, label colours included;
//    post-classified unshaded: the largest colour of the transfer function) and B >= 1 and
//    >= |background|; the stop composites the background with T instead of
//    rest + T_end * background, so it moves each channel by at most B (T - T_end) < B T <=
//    0.01 * tolerance (alpha: (1 - bg.a)(T - T_end) likewise). Without such a bound (shaded
//    post-classified, emission without extinction) the ray stops at
//    T < min(tolerance, 1e-3) * 1e-3 as before. Tested in tests/test_reference.cpp.
//  - xray: int f dt (world units). mip: max of the samples, polished by a golden-section
//    search around the largest one and around every other local maximum of the samples
//    whose hill could rise above the best value found: a hill peaking between two samples
//    h apart exceeds the larger one by at most |f''| h^2 / 8, about a quarter of the second
//    difference |f(i-1) - 2 f(i) + f(i+1)|, which is taken near the sample, doubled. Which
//    hill holds the largest sample depends on where the samples fall (a brick's segments
//    start at its own face), the peak does not (0 when the ray meets nothing).
//  - iso: first sample pair bracketing f = level, refined by bisection to 1e-9 voxels,
//    shaded with the normalised gradient of f (central differences) under a headlight.
#include "splat/reference.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <vector>

#include "model/clip_region.h"
#include "model/scene_impl.h"
#include "model/shading_model.h"
#include "frame/frame_progress.h"
#include "reference/field.h"
#include "reference/reference_frame.h"
#include "splat/error.h"

namespace splat {
namespace {

constexpr int kMaxLevels = 6;  // step halvings after the first pass
constexpr int kMaxPanelLevels = 7;  // panel adaptivity: halvings of a panel's first step
constexpr double kPanelShare = 1.0 / 16.0;  // panel adaptivity: sum of shares <= tol / 16

thread_local std::size_t tlSamples = 0;  // field samples taken on this thread

// mip: a local maximum of a pass's samples, at t in segment `segment`, and the most its hill
// can rise to between the neighbouring samples.
struct MipPeak {
    double bound = 0, t = 0;
    int segment = 0;
};

// Per-thread scratch of one ray.
template <int C>
struct RayScratch {
    std::vector<Segment> segments;
    std::vector<int> baseN;                                   // subintervals of pass 0
    std::vector<std::vector<std::array<float, C>>> old, cur;  // samples per segment
    std::vector<std::array<float, C>> tmp;
    std::vector<MipPeak> peaks;  // mip: local maxima of the samples of one pass
};

using Sample4 = std::array<float, 4>;

// dvr panel adaptivity (see "Panel adaptivity" above): one panel is two first steps of a
// segment; its samples hold (rho, e) at spacing h0 / 2^level.
struct Panel {
    double a = 0, h0 = 0;  // start, first step (the panel spans 2 h0)
    int level = 1;
    bool joined = false;  // starts where the previous panel ends (shares its end sample)
    double tau = 0, tauPrev = 0;  // optical depth over the panel at level and level - 1
    double att = 1;               // exp(-tau): the panel's transmittance
    glm::dvec3 e{0.0}, ePrev{0.0};  // emission from its start at level and level - 1
    double eps = 0;               // first-order change of the pixel between the two
};

struct PanelScratch {
    std::vector<Segment> segments;
    std::vector<Panel> panels;
    std::vector<std::vector<glm::dvec4>> q;  // (rho, e) per panel
    std::vector<glm::dvec4> tmp;
    std::vector<double> T;
};

// Simpson over n (even) subintervals of width h of the samples q[0], q[stride], ...,
// q[n stride]: the panel's optical depth and its emission attenuated from its start
// (the whole-ray formulas of Caster::integrate, restarted at the panel).
void panelIntegral(const glm::dvec4* q, int n, int stride, double h, double& tauOut,
                   glm::dvec3& eOut) {
    double tau = 0, T = 1;
    glm::dvec3 e(0.0);
    for (int m = 0; m < n / 2; ++m) {
        const glm::dvec4 A = q[2 * m * stride], B = q[(2 * m + 1) * stride],
                         C = q[(2 * m + 2) * stride];
        const double tauB = tau + h / 12.0 * (5.0 * A.x + 8.0 * B.x - C.x);
        const double tauC = tau + h / 3.0 * (A.x + 4.0 * B.x + C.x);
        const double TB = std::exp(-tauB), TC = std::exp(-tauC);
        e += h / 3.0 *
             (glm::dvec3(A.y, A.z, A.w) * T + 4.0 * glm::dvec3(B.y, B.z, B.w) * TB +
              glm::dvec3(C.y, C.z, C.w) * TC);
        tau = tauC;
        T = TC;
    }
    tauOut = tau;
    eOut = e;
}

class Caster {
  public:
    Caster(const Volume& volume, const ReferenceField& field, const Camera& camera,
           const RenderSettings& settings)
        : volume_(volume), camera_(camera), settings_(settings), field_(field) {
        const Quality& q = settings.quality;
        if (!(q.referenceStep == 0 || q.referenceStep >= 1e-3) || !std::isfinite(q.referenceStep))
            throw Error("reference: referenceStep must be finite and >= 0.001 voxels (or 0)");
        if (!(q.referenceTolerance > 0)) throw Error("reference: referenceTolerance must be > 0");
        if (volume.voxelCount() == 0) throw Error("reference: empty volume");
        invSpacing_ = 1.0 / volume.spacing;
        background_ = volume.background;
        const glm::dvec3 pad = field.radius() * volume.spacing;
        clips_ = settings.clipping.enabled() &&
                 !containsBox(settings.clipping, volume.world(glm::dvec3(0.0)) - pad,
                              volume.world(glm::dvec3(volume.dims) - 1.0) + pad);
        step_ = q.referenceStep > 0 ? q.referenceStep
                                    : referenceStepFor(settings.mode, field.kernelDeviation(),
                                                       field.acceleration().panelAdaptive);
        stepWorld_ = step_ * volume.minSpacing();
        preDvr_ = field.fourChannels();
        layout_ = field.layout();
        const bool post =
            settings.mode == RenderMode::Dvr && settings.classification == Classification::Post;
        shadePost_ = post && layout_ == FieldLayout::DensityGradient && settings.shading.enabled;
        edgesPost_ = post && layout_ == FieldLayout::DensityGradient && settings.edges.enabled();
        light_ = lightFrame(settings.shading, camera.view);
    }
    /// 1 / G for edge enhancement (the splat list's gradient scale).
    void setGradientScale(float g) { invGradientScale_ = g > 0.0f ? 1.0f / g : 0.0f; }
    void setLabels(const LabelLookup* labels) { labels_ = labels; }

    Image render(RenderStats* stats, Image* depth, std::size_t* samplesOut) {
        cutoff_ = terminationCutoff();
        const int w = camera_.width(), h = camera_.height();
        Image image(w, h);
        if (depth) *depth = Image(w, h);
        std::atomic<int> finest{0};
        std::atomic<std::size_t> samples{0};
        // Panels with the automatic first step only: an explicit step keeps the whole-ray
        // scheme (at small steps the summed shares over many panels refine further).
        const bool panels = settings_.mode == RenderMode::Dvr &&
                            field_.acceleration().panelAdaptive &&
                            settings_.quality.referenceStep == 0;
        FrameProgress progress(settings_.progress, std::size_t(h), "rows");
        auto body = [&](const tbb::blocked_range<int>& rows) {
            RayScratch<4> s4;
            RayScratch<1> s1;
            PanelScratch ps;
            int localFinest = 0;
            const std::size_t samplesBefore = tlSamples;
            for (int y = rows.begin(); y != rows.end() && !progress.stopped(); ++y) {
                for (int x = 0; x < w; ++x) {
                    int level = 0;
                    double hitDepth = -1;
                    if (panels)
                        image.at(x, y) =
                            field_.fourChannels()
                                ? pixelPanels(field_.grid4(), ps, x, y, level)
                                : pixelPanels(field_.grid1(), ps, x, y, level);
                    else
                        image.at(x, y) = preDvr_
                                             ? pixel(field_.grid4(), s4, x, y, level, hitDepth)
                                             : pixel(field_.grid1(), s1, x, y, level, hitDepth);
                    if (depth)
                        depth->at(x, y) = hitDepth >= 0
                                              ? glm::vec4(glm::vec3(float(hitDepth)), 1.0f)
                                              : glm::vec4(0.0f);
                    localFinest = std::max(localFinest, level);
                }
                progress.tick();
            }
            samples += tlSamples - samplesBefore;
            int cur = finest.load();
            while (localFinest > cur && !finest.compare_exchange_weak(cur, localFinest)) {
            }
        };
        tbb::parallel_for(tbb::blocked_range<int>(0, h, 1), body);
        progress.finish();
        if (stats)
            stats->referenceStep = step_ / double(1 << finest.load());
        if (samplesOut) *samplesOut = samples.load();
        return image;
    }

  private:
    // The transmittance below which a dvr ray stops (see "Early termination" above).
    double terminationCutoff() const {
        const double tol = settings_.quality.referenceTolerance;
        const double plain = std::min(tol, 1e-3) * 1e-3;
        if (!field_.acceleration().toleranceTermination) return plain;
        double bound = 1.0;  // B: colours of what follows, relative to its extinction
        if (layout_ == FieldLayout::Emission) {
            bound = std::max(bound, field_.emissionRatioBound());
            if (labels_)
                for (const glm::vec4& c : *labels_->table)
                    bound = std::max({bound, double(c.r), double(c.g), double(c.b)});
        } else if (shadePost_) {
            return plain;
        } else {
            for (const TransferPoint& p : settings_.transfer.points)
                bound = std::max({bound, double(p.rgba.r), double(p.rgba.g), double(p.rgba.b)});
        }
        const glm::vec4 bg = settings_.background;
        bound = std::max({bound, std::abs(double(bg.r)), std::abs(double(bg.g)),
                          std::abs(double(bg.b)), std::abs(1.0 - double(bg.a))});
        if (!std::isfinite(bound)) return plain;
        return std::max(plain, 0.01 * std::min(tol, 1e-4) / bound);
    }

    // Converts a grid sample into the quantities integrated: dvr -> (rho, e rgb), else f.
    template <int C>
    void sampleAt(const FieldGrid<C>& g, const glm::dvec3& p0, const glm::dvec3& v, double t,
                  float* out) const {
        ++tlSamples;
        double val[C];
        g.eval(p0 + t * v, val);
        if constexpr (C == 4) {
            for (int c = 0; c < 4; ++c) out[c] = float(val[c]);
            if (labels_) labels_->add(p0 + t * v, out);
        } else {
            out[0] = float(val[0]);
        }
    }

    // rho and emission of one post-classified / pre-classified sample.
    void dvrQuantities(const float* s, int channels, double& rho, glm::dvec3& e) const {
        if (channels == 4 && layout_ == FieldLayout::Emission) {
            rho = s[0];
            e = glm::dvec3(s[1], s[2], s[3]);
        } else if (channels == 4) {  // density and gradient: post-classified, shaded / edges
            const glm::vec4 c = settings_.transfer.sample(s[0] + background_);
            float r = c.r, g = c.g, b = c.b;
            float rhoF = settings_.transfer.extinctionFromOpacity(c.a);
            if (edgesPost_)
                rhoF *=
                    edgeFactor(settings_.edges, std::sqrt(s[1] * s[1] + s[2] * s[2] + s[3] * s[3]) *
                                                    invGradientScale_);
            if (shadePost_) {
                const LightTerms t =
                    blinnPhongGradient(settings_.shading, light_, s[1], s[2], s[3]);
                r = r * t.diffuse + t.specular;
                g = g * t.diffuse + t.specular;
                b = b * t.diffuse + t.specular;
            }
            rho = rhoF;
            e = glm::dvec3(r, g, b) * rho;
        } else {
            const glm::vec4 c = settings_.transfer.sample(s[0] + background_);
            rho = settings_.transfer.extinctionFromOpacity(c.a);
            e = glm::dvec3(c) * rho;
        }
    }

    /// The ray through pixel (x, y)'s centre in voxel units (p0 + t v, t in world units) and
    /// its segments through the field's occupied bricks; clipping cuts the ray to the kept
    /// region (the field itself is whole).
    template <int C>
    void pixelRay(const FieldGrid<C>& g, int x, int y, glm::dvec3& p0, glm::dvec3& v,
                  std::vector<Segment>& segments) const {
        const Ray ray = camera_.ray(x + 0.5, y + 0.5);
        p0 = (ray.origin - volume_.origin) * invSpacing_;
        v = ray.dir * invSpacing_;
        const double inf = std::numeric_limits<double>::infinity();
        double t0 = camera_.perspective() ? 0.0 : -inf, t1 = inf;
        if (!clips_ || keptInterval(settings_.clipping, ray.origin, ray.dir, t0, t1))
            raySegments(g, p0, v, t0, t1, segments);
        else
            segments.clear();
    }

    template <int C>
    glm::vec4 pixel(const FieldGrid<C>& g, RayScratch<C>& sc, int x, int y, int& levelUsed,
                    double& hitDepth) const {
        glm::dvec3 p0, v;
        pixelRay(g, x, y, p0, v, sc.segments);
        const RenderMode mode = settings_.mode;
        const glm::vec4 bg = settings_.background;
        auto finish = [&](glm::dvec4 c) -> glm::vec4 {
            if (mode == RenderMode::Dvr) {
                const double T = 1.0 - c.a;
                c += T * glm::dvec4(bg);
            } else if (mode == RenderMode::Iso && c.a == 0.0) {
                c = glm::dvec4(bg);
            }
            return glm::vec4(c);
        };
        levelUsed = 0;
        hitDepth = -1;
        if (sc.segments.empty()) {
            // Outside the data the field is b: x-ray (of f - b) sees 0, mip sees b.
            if (mode == RenderMode::Xray) return glm::vec4(0, 0, 0, 1);
            if (mode == RenderMode::Mip) return glm::vec4(glm::vec3(background_), 1.0f);
            return finish(glm::dvec4(0.0));
        }
        const std::size_t ns = sc.segments.size();
        sc.baseN.resize(ns);
        sc.old.resize(ns);
        sc.cur.resize(ns);
        for (std::size_t s = 0; s < ns; ++s) {
            const double len = sc.segments[s].b - sc.segments[s].a;
            const double half = std::ceil(len / (2.0 * stepWorld_));
            if (!(half <= double(1 << 28)))  // also NaN: never an unchecked float -> int
                throw Error("reference: a ray needs more than 2^29 steps; use a larger step");
            sc.baseN[s] = 2 * std::max(1, int(half));
            sc.old[s].clear();
            sc.cur[s].clear();
        }
        glm::dvec4 prev(0.0), result(0.0);
        double prevDepth = -1;
        const double tol = settings_.quality.referenceTolerance;
        for (int level = 0; level <= kMaxLevels; ++level) {
            double depthHere = -1;
            result = integrate(g, sc, p0, v, level, depthHere);
            levelUsed = level;
            hitDepth = depthHere;
            if (level > 0) {
                const glm::dvec4 d = glm::abs(result - prev);
                double scale = 1.0;
                if (mode == RenderMode::Xray) scale = std::max(1.0, std::abs(result.r));
                const bool depthStable =
                    mode != RenderMode::Iso || (depthHere < 0) == (prevDepth < 0);
                if (std::max(std::max(d.r, d.g), std::max(d.b, d.a)) <= tol * scale && depthStable)
                    break;
            }
            prev = result;
            prevDepth = depthHere;
            std::swap(sc.old, sc.cur);
        }
        return finish(result);
    }

    // (rho, e) of the dvr field at ray parameter t.
    template <int C>
    glm::dvec4 quantityAt(const FieldGrid<C>& g, const glm::dvec3& p0, const glm::dvec3& v,
                          double t) const {
        float s[C];
        sampleAt(g, p0, v, t, s);
        double rho;
        glm::dvec3 e;
        dvrQuantities(s, C, rho, e);
        return glm::dvec4(rho, e);
    }

    // Halves the panel's spacing: new samples between the present ones; its integrals at the
    // new level and the previous one.
    template <int C>
    void refinePanel(const FieldGrid<C>& g, const glm::dvec3& p0, const glm::dvec3& v, Panel& p,
                     std::vector<glm::dvec4>& q, std::vector<glm::dvec4>& tmp) const {
        const int n = 2 << p.level;  // subintervals now
        const double h = p.h0 / double(1 << (p.level + 1));
        tmp.resize(std::size_t(2 * n + 1));
        for (int k = 0; k <= n; ++k) tmp[std::size_t(2 * k)] = q[std::size_t(k)];
        for (int k = 0; k < n; ++k)
            tmp[std::size_t(2 * k + 1)] = quantityAt(g, p0, v, p.a + (2 * k + 1) * h);
        q.swap(tmp);
        ++p.level;
        p.tauPrev = p.tau;
        p.ePrev = p.e;
        panelIntegral(q.data(), 2 * n, 1, h, p.tau, p.e);
        p.att = std::exp(-p.tau);
    }

    // dvr with panel adaptivity (see "Panel adaptivity" above).
    template <int C>
    glm::vec4 pixelPanels(const FieldGrid<C>& g, PanelScratch& sc, int x, int y,
                          int& levelUsed) const {
        glm::dvec3 p0, v;
        pixelRay(g, x, y, p0, v, sc.segments);
        levelUsed = 0;
        sc.panels.clear();
        for (const Segment& seg : sc.segments) {
            const double len = seg.b - seg.a;
            const double half = std::ceil(len / (2.0 * stepWorld_));
            if (!(half <= double(1 << 28)))
                throw Error("reference: a ray needs more than 2^29 steps; use a larger step");
            const int np = std::max(1, int(half));
            const double h0 = len / (2.0 * np);
            for (int k = 0; k < np; ++k) {
                Panel p;
                p.a = seg.a + 2.0 * k * h0;
                p.h0 = h0;
                p.joined = k > 0;
                sc.panels.push_back(p);
            }
        }
        const std::size_t total = sc.panels.size();
        if (sc.q.size() < total) sc.q.resize(total);
        sc.T.resize(total + 1);
        const double tol = settings_.quality.referenceTolerance * kPanelShare;
        const double cutoff = cutoff_;
        std::size_t done = 0;  // panels sampled (level 1), front to back
        double Tend = 1.0;
        glm::dvec3 colour(0.0);
        while (true) {
            // Sample panels at levels 0 and 1 until the light still to come is negligible.
            while (done < total && Tend >= cutoff) {
                Panel& p = sc.panels[done];
                auto& q = sc.q[done];
                q.resize(5);
                const double h = 0.5 * p.h0;
                if (p.joined) {
                    q[0] = sc.q[done - 1].back();
                } else {
                    q[0] = quantityAt(g, p0, v, p.a);
                }
                for (int k = 1; k <= 4; ++k) q[std::size_t(k)] = quantityAt(g, p0, v, p.a + k * h);
                p.level = 1;
                panelIntegral(q.data(), 2, 2, p.h0, p.tauPrev, p.ePrev);
                panelIntegral(q.data(), 4, 1, h, p.tau, p.e);
                p.att = std::exp(-p.tau);
                Tend *= p.att;
                ++done;
            }
            // Transmittance in front of each panel, the colour, and each panel's share of the
            // change between its last two levels (first order, light behind it included).
            double T = 1.0;
            colour = glm::dvec3(0.0);
            for (std::size_t k = 0; k < done; ++k) {
                sc.T[k] = T;
                colour += T * sc.panels[k].e;
                T *= sc.panels[k].att;
            }
            sc.T[done] = T;
            Tend = T;
            glm::dvec3 behind(0.0);
            double sum = 0.0;
            for (std::size_t k = done; k-- > 0;) {
                Panel& p = sc.panels[k];
                const double dTau = p.tau - p.tauPrev;
                const glm::dvec3 d = glm::abs(sc.T[k] * (p.e - p.ePrev) - dTau * behind);
                p.eps = std::max({d.x, d.y, d.z, Tend * std::abs(dTau)});
                sum += p.eps;
                behind += sc.T[k] * p.e;
            }
            if (sum > tol) {
                // Refine the panels of largest share (by binary exponent) until the rest,
                // with the refined ones' shares predicted to fall 16x, is within tol.
                constexpr int kBuckets = 80;
                double bucket[kBuckets] = {};
                auto bucketOf = [](double eps) {
                    return std::clamp(std::ilogb(eps) + 70, 0, kBuckets - 1);
                };
                for (std::size_t k = 0; k < done; ++k) {
                    const Panel& p = sc.panels[k];
                    if (p.eps > 0 && p.level < kMaxPanelLevels) bucket[bucketOf(p.eps)] += p.eps;
                }
                double rest = sum;
                int cut = kBuckets;
                while (cut > 0 && rest > tol) {
                    --cut;
                    rest -= bucket[cut] * (15.0 / 16.0);
                }
                bool refined = false;
                for (std::size_t k = 0; k < done; ++k) {
                    Panel& p = sc.panels[k];
                    if (p.eps > 0 && p.level < kMaxPanelLevels && bucketOf(p.eps) >= cut) {
                        refinePanel(g, p0, v, p, sc.q[k], sc.tmp);
                        refined = true;
                    }
                }
                if (refined) {
                    Tend = 1.0;
                    for (std::size_t k = 0; k < done; ++k) Tend *= sc.panels[k].att;
                    continue;
                }
            }
            if (done == total || Tend < cutoff) break;
        }
        for (std::size_t k = 0; k < done; ++k) levelUsed = std::max(levelUsed, sc.panels[k].level);
        glm::dvec4 c(colour, 1.0 - Tend);
        c += Tend * glm::dvec4(settings_.background);
        return glm::vec4(c);
    }

    // One pass at `level`: fills sc.cur from sc.old (samples of level - 1) and new samples.
    template <int C>
    glm::dvec4 integrate(const FieldGrid<C>& g, RayScratch<C>& sc, const glm::dvec3& p0,
                         const glm::dvec3& v, int level, double& depth) const {
        const RenderMode mode = settings_.mode;
        const double cutoff = cutoff_;
        double tau = 0, xray = 0, mip = 0;
        glm::dvec3 emission(0.0);
        double T = 1.0;
        bool stop = false;
        depth = -1;
        double mipT = 0;
        int mipSeg = -1;
        sc.peaks.clear();
        for (std::size_t s = 0; s < sc.segments.size() && !stop; ++s) {
            const Segment seg = sc.segments[s];
            const int n = sc.baseN[s] << level;
            const double h = (seg.b - seg.a) / n;
            auto& old = sc.old[s];
            auto& cur = sc.cur[s];
            cur.clear();
            auto sample = [&](int idx) -> const std::array<float, C>& {
                if (level > 0 && (idx & 1) == 0 && std::size_t(idx / 2) < old.size()) {
                    cur.push_back(old[idx / 2]);
                } else {
                    std::array<float, C> v4;
                    sampleAt(g, p0, v, seg.a + idx * h, v4.data());
                    cur.push_back(v4);
                }
                return cur.back();
            };
            if (mode == RenderMode::Dvr) {
                double rhoA;
                glm::dvec3 eA;
                dvrQuantities(sample(0).data(), C, rhoA, eA);
                for (int m = 0; m < n / 2; ++m) {
                    double rhoB, rhoC;
                    glm::dvec3 eB, eC;
                    dvrQuantities(sample(2 * m + 1).data(), C, rhoB, eB);
                    dvrQuantities(sample(2 * m + 2).data(), C, rhoC, eC);
                    const double tauB = tau + h / 12.0 * (5.0 * rhoA + 8.0 * rhoB - rhoC);
                    const double tauC = tau + h / 3.0 * (rhoA + 4.0 * rhoB + rhoC);
                    const double TA = T, TB = std::exp(-tauB), TC = std::exp(-tauC);
                    emission += h / 3.0 * (eA * TA + 4.0 * eB * TB + eC * TC);
                    tau = tauC;
                    T = TC;
                    rhoA = rhoC;
                    eA = eC;
                    if (T < cutoff) {
                        stop = true;
                        break;
                    }
                }
            } else if (mode == RenderMode::Xray) {
                double acc = sample(0)[0];
                for (int m = 0; m < n / 2; ++m) {
                    acc += 4.0 * sample(2 * m + 1)[0];
                    const double fc = sample(2 * m + 2)[0];
                    acc += m + 1 < n / 2 ? 2.0 * fc : fc;
                }
                xray += acc * h / 3.0;
            } else if (mode == RenderMode::Mip) {
                for (int idx = 0; idx <= n; ++idx) {
                    const double f = sample(idx)[0];
                    if (f > mip) {
                        mip = f;
                        mipSeg = int(s);
                        mipT = seg.a + idx * h;
                    }
                }
                mipPeaks<C>(cur, int(s), seg.a, h, sc.peaks);
            } else {  // iso
                const double level0 = settings_.isoLevel - background_;  // samples: f - b
                double fPrev = sample(0)[0];
                // A ray entering the kept region of a clipped volume inside the surface hits
                // the cut face (the splatters' first sheet has nothing in front either).
                if (clips_ && s == 0 && level0 > 0 && fPrev >= level0) {
                    depth = seg.a;
                    stop = true;
                }
                for (int idx = 1; idx <= n && !stop; ++idx) {
                    const double f = sample(idx)[0];
                    if (fPrev < level0 && f >= level0) {
                        depth = bisect(g, p0, v, seg.a + (idx - 1) * h, seg.a + idx * h);
                        stop = true;
                        break;
                    }
                    fPrev = f;
                }
            }
        }
        if (mode == RenderMode::Dvr) return glm::dvec4(emission, 1.0 - T);
        if (mode == RenderMode::Xray) return glm::dvec4(xray, xray, xray, 1.0);
        if (mode == RenderMode::Mip) {
            auto polish = [&](int segment, double t) {
                const Segment seg = sc.segments[std::size_t(segment)];
                const double h = (seg.b - seg.a) / (sc.baseN[std::size_t(segment)] << level);
                const double lo = std::max(seg.a, t - h), hi = std::min(seg.b, t + h);
                mip = std::max(mip, goldenMax(g, p0, v, lo, hi));
            };
            if (mipSeg >= 0) {
                polish(mipSeg, mipT);
                std::sort(sc.peaks.begin(), sc.peaks.end(),
                          [](const MipPeak& a, const MipPeak& b) { return a.bound > b.bound; });
                for (const MipPeak& p : sc.peaks) {
                    if (p.bound <= mip) break;
                    if (p.segment != mipSeg || p.t != mipT) polish(p.segment, p.t);
                }
            }
            mip += background_;  // the samples hold f - b; outside the data a ray sees b
            return glm::dvec4(mip, mip, mip, 1.0);
        }
        if (depth < 0) return glm::dvec4(0.0);
        return glm::dvec4(shade(g, p0, v, depth), 1.0);
    }

    // mip: the local maxima of one segment's samples f(0..n) (spacing h from t = a) whose hill
    // could rise above 0, each with the bound of its hill (see the head of this file).
    template <int C>
    static void mipPeaks(const std::vector<std::array<float, C>>& f, int segment, double a,
                         double h, std::vector<MipPeak>& peaks) {
        const int n = int(f.size()) - 1;
        auto second = [&](int i) {  // |second difference| at i, 0 at the ends
            return i < 1 || i >= n
                       ? 0.0
                       : std::abs(double(f[std::size_t(i - 1)][0]) - 2.0 * f[std::size_t(i)][0] +
                                  f[std::size_t(i + 1)][0]);
        };
        for (int i = 0; i <= n; ++i) {
            const double fi = f[std::size_t(i)][0];
            if ((i > 0 && f[std::size_t(i - 1)][0] > fi) ||
                (i < n && f[std::size_t(i + 1)][0] > fi))
                continue;
            const double rise = 0.25 * std::max({second(i - 1), second(i), second(i + 1)});
            if (fi + rise > 0) peaks.push_back({fi + rise, a + i * h, segment});
        }
    }

    template <int C>
    double field(const FieldGrid<C>& g, const glm::dvec3& p) const {
        double val[C];
        g.eval(p, val);
        return val[0];
    }

    template <int C>
    double bisect(const FieldGrid<C>& g, const glm::dvec3& p0, const glm::dvec3& v, double lo,
                  double hi) const {
        const double level = settings_.isoLevel - background_;
        const double eps = 1e-9 * volume_.minSpacing();
        while (hi - lo > eps) {
            const double mid = 0.5 * (lo + hi);
            if (field(g, p0 + mid * v) >= level)
                hi = mid;
            else
                lo = mid;
            if (mid == lo && mid == hi) break;
        }
        return 0.5 * (lo + hi);
    }

    template <int C>
    double goldenMax(const FieldGrid<C>& g, const glm::dvec3& p0, const glm::dvec3& v, double a,
                     double b) const {
        const double r = 0.5 * (std::sqrt(5.0) - 1.0);
        double c = b - r * (b - a), d = a + r * (b - a);
        double fc = field(g, p0 + c * v), fd = field(g, p0 + d * v);
        for (int it = 0; it < 60 && b - a > 1e-10 * volume_.minSpacing(); ++it) {
            if (fc > fd) {
                b = d;
                d = c;
                fd = fc;
                c = b - r * (b - a);
                fc = field(g, p0 + c * v);
            } else {
                a = c;
                c = d;
                fc = fd;
                d = a + r * (b - a);
                fd = field(g, p0 + d * v);
            }
        }
        return std::max(fc, fd);
    }

    // Headlight shading of the iso surface at ray parameter t.
    template <int C>
    glm::dvec3 shade(const FieldGrid<C>& g, const glm::dvec3& p0, const glm::dvec3& v,
                     double t) const {
        const glm::dvec3 p = p0 + t * v;
        const double hIdx = 1e-3;
        glm::dvec3 grad;  // world gradient: d/dx = S^-1 d/dp
        for (int a = 0; a < 3; ++a) {
            glm::dvec3 d(0.0);
            d[a] = hIdx;
            grad[a] = (field(g, p + d) - field(g, p - d)) / (2.0 * hIdx) * invSpacing_[a];
        }
        const glm::dvec3 colour(settings_.transfer.sample(float(settings_.isoLevel)));
        const double len = glm::length(grad);
        const Shading& sh = settings_.shading;
        if (!(len > 0)) return colour * double(sh.ambient + sh.diffuse);
        // The one shading model; the headlight follows each (perspective) ray. The highlight
        // is added when shading is asked for (the default iso image is ambient + diffuse).
        const glm::dvec3 dir = glm::normalize(v * volume_.spacing);  // world ray direction
        const glm::dvec3 n = grad / len;
        const LightTerms lt =
            blinnPhong(sh, lightFrame(sh, dir), float(n.x), float(n.y), float(n.z));
        return colour * double(lt.diffuse) + (sh.enabled ? double(lt.specular) : 0.0);
    }

    const Volume& volume_;
    const Camera& camera_;
    const RenderSettings& settings_;
    const ReferenceField& field_;
    glm::dvec3 invSpacing_{1.0};
    /// b: the fields hold f - b (SplatList::background); added back where f itself is read.
    float background_ = 0.0f;
    double step_ = 0.25, stepWorld_ = 1;  // first step, voxels and world units
    bool preDvr_ = false;
    FieldLayout layout_ = FieldLayout::Density;
    bool shadePost_ = false, edgesPost_ = false;
    bool clips_ = false;  // the kept region cuts the volume (padded by R)
    LightFrame light_;
    float invGradientScale_ = 0;
    const LabelLookup* labels_ = nullptr;
    double cutoff_ = 0;  ///< dvr early termination: T below which a ray stops
};

}  // namespace

double referenceStepFor(RenderMode mode, double kernelDeviation, bool panelAdaptive) {
    if (mode != RenderMode::Dvr || !panelAdaptive) return 0.25;
    return std::clamp(1.75 * kernelDeviation, 0.25, 1.0);
}

void validateReferenceKernel(const footprint::Kernel& kernel) {
    if (!(kernel.radius() > 0) || kernel.radius() > 30)
        throw Error("reference: kernel radius must be in (0, 30] voxels");
}

Image renderReference(const Volume& volume, const ReferenceField& field, const Camera& camera,
                      const RenderSettings& settings, RenderStats* stats, Image* depth,
                      float gradientScale, const LabelLookup* labels, std::size_t* samples) {
    Caster caster(volume, field, camera, settings);
    caster.setGradientScale(gradientScale);
    caster.setLabels(labels);
    return caster.render(stats, depth, samples);
}

Image renderReference(const Volume& volume, const SplatList& splats,
                      const footprint::Kernel& kernel, const Camera& camera,
                      const RenderSettings& settings, RenderStats* stats) {
    const auto start = std::chrono::steady_clock::now();
    validateReferenceKernel(kernel);
    const ReferenceField field(volume, splats, kernel, fieldLayout(settings, splats));
    Image image;
    runOnThreads(settings.threads, [&] {
        image =
            renderReference(volume, field, camera, settings, stats, nullptr, splats.gradientScale);
    });
    if (stats) {
        stats->splats = splats.size();
        stats->voxels = splats.voxels;
        stats->milliseconds =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
    }
    return image;
}

Image renderReferenceDepth(const Volume& volume, const SplatList& splats,
                           const footprint::Kernel& kernel, const Camera& camera,
                           const RenderSettings& settings, RenderStats* stats) {
    if (settings.mode != RenderMode::Iso)
        throw Error("reference: hit depths exist only in iso mode");
    validateReferenceKernel(kernel);
    const ReferenceField field(volume, splats, kernel, FieldLayout::Density);
    Image depth;
    runOnThreads(settings.threads,
                 [&] { renderReference(volume, field, camera, settings, stats, &depth); });
    return depth;
}

}  // namespace splat
