#pragma once
// The sweep the Gaussian popping tests share: gaussians:pop (two Gaussians whose centres
// swap depth order at azimuth 0) at 48², azimuth -5.5 to 5.5 in steps of 1, so the swap falls
// inside the interval [-0.5, 0.5].
#include "splat/gaussians.h"
#include "splat/popping.h"
#include "splat/render.h"

namespace splat::test {

inline const GaussianScene& popScene() {
    static const GaussianScene scene = syntheticGaussians("gaussians:pop");
    return scene;
}

inline RenderSettings popSettings() {
    RenderSettings settings;
    settings.camera.width = settings.camera.height = 48;
    return settings;
}

inline Sweep popSweep(const RenderSettings& settings) {
    Sweep sweep;
    sweep.base = settings.camera;
    sweep.from = -5.5;
    sweep.to = 5.5;
    sweep.step = 1;
    return sweep;
}

}  // namespace splat::test
