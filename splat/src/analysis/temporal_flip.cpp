// StopThePop's temporal FLIP over a popping sweep (temporal_flip.h).
#include "analysis/temporal_flip.h"

#include "splat/depth.h"

namespace splat::analysis {

namespace {

constexpr std::size_t kFar = 7;  // FLIP_7: the farther of the two frame distances

/// Mean of the values >= 0; -1 when there is none.
double meanOfValid(const std::vector<double>& v) {
    double sum = 0;
    std::size_t n = 0;
    for (double x : v)
        if (x >= 0) {
            sum += x;
            ++n;
        }
    return n ? sum / double(n) : -1.0;
}

}  // namespace

TemporalFlip::TemporalFlip(const PoppingOptions& options, const Volume& geometry,
                           const Scene* scene)
    : options_(options), geometry_(geometry), scene_(scene) {
    // mip and xray have no depth (splat/depth.h): nothing to warp with.
    const bool depth = scene ? scene->settings().mode == RenderMode::Dvr ||
                                   scene->settings().mode == RenderMode::Iso
                             : bool(options.depthFrame);
    enabled_ = options.flip && options.warpFlip && depth;
}

void TemporalFlip::addView(std::size_t n, const CameraParams& camera,
                           const std::vector<Image>& frames,
                           const std::vector<FlipImage>& perceived,
                           std::vector<RendererSeries>& series) {
    if (!enabled_) return;
    Past view{Camera(camera, geometry_),
              scene_ ? referenceDepth(*scene_, camera) : options_.depthFrame(camera), frames};
    past_.push_back(std::move(view));
    if (past_.size() > kFar + 1) past_.pop_front();
    const Past& now = past_.back();
    for (std::size_t k = 0; k < series.size(); ++k) {
        if (n >= 1)
            series[k].flipWarp1.push_back(pairFlip(past_[past_.size() - 2], now, perceived[k], k));
        if (n >= kFar) series[k].flipWarp7.push_back(pairFlip(past_.front(), now, perceived[k], k));
    }
}

double TemporalFlip::pairFlip(const Past& earlier, const Past& later, const FlipImage& laterFrame,
                              std::size_t renderer) const {
    const WarpedFrame warped =
        warpFrame(earlier.frames[renderer], earlier.depth, earlier.camera, later.frames[renderer],
                  later.depth, later.camera, options_.warp);
    return warpedFlip(laterFrame, warped);
}

void TemporalFlip::finish(std::vector<RendererSeries>& series) const {
    if (!enabled_) return;
    for (RendererSeries& s : series) {
        s.flipWarp1Mean = meanOfValid(s.flipWarp1);
        s.flipWarp7Mean = meanOfValid(s.flipWarp7);
    }
}

}  // namespace splat::analysis
