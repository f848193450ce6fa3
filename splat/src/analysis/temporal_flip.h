#pragma once
// StopThePop's temporal FLIP over a popping sweep (splat/popping.h, splat/warp.h): per view
// the reference's depth, and per renderer FLIP_1 and FLIP_7 against the views 1 and 7 before.
#include <cstddef>
#include <deque>
#include <vector>

#include "analysis/flip_image.h"
#include "splat/popping.h"
#include "splat/scene.h"

namespace splat::analysis {

class TemporalFlip {
  public:
    /// `scene` null: depth from options.depthFrame (none: not measured). `geometry` places
    /// the cameras (the Scene's volume, or a Gaussian scene's geometry()).
    TemporalFlip(const PoppingOptions& options, const Volume& geometry, const Scene* scene);
    bool enabled() const { return enabled_; }
    /// View n of the sweep (views in order): `frames` per renderer as FLIP sees them, and
    /// `perceived` the same perceived by FLIP (analysis/flip_image.h).
    /// Appends FLIP_1 (n >= 1) and FLIP_7 (n >= 7) to each series.
    void addView(std::size_t n, const CameraParams& camera, const std::vector<Image>& frames,
                 const std::vector<FlipImage>& perceived, std::vector<RendererSeries>& series);
    /// The means over the pairs with valid pixels.
    void finish(std::vector<RendererSeries>& series) const;

  private:
    struct Past {
        Camera camera;
        Image depth;
        std::vector<Image> frames;
    };
    /// FLIP_k of renderer's frame of `later` (perceived: `laterFrame`) and `earlier` warped to it.
    double pairFlip(const Past& earlier, const Past& later, const FlipImage& laterFrame,
                    std::size_t renderer) const;

    const PoppingOptions& options_;
    const Volume& geometry_;
    const Scene* scene_;
    bool enabled_ = false;
    std::deque<Past> past_;  ///< the last 8 views, newest last
};

}  // namespace splat::analysis
