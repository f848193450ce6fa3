// The reference an analysis judges the splatters against (see splat/render.h, truthFilter).
#include "frame/projection.h"
#include "splat/render.h"

namespace splat {

double ewaLowPass(const RenderSettings& settings, const Volume& volume) {
    return ewaLowPass(settings.quality, settings.mode, Camera(settings.camera, volume), volume);
}

double truthFilter(const RenderSettings& settings, const Volume& volume,
                   const std::vector<CameraParams>& views, Truth truth) {
    const double given = settings.quality.pixelFilter;
    if (truth == Truth::Point) return 0;
    if (truth == Truth::Filtered || given > 0) return given > 0 ? given : Quality::kEwaDefaultSigma;
    RenderSettings frame = settings;
    for (const CameraParams& view : views) {
        frame.camera = view;
        if (ewaLowPass(frame, volume) > 0) return Quality::kEwaDefaultSigma;
    }
    return 0;
}

}  // namespace splat
