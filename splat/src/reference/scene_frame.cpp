// The reference ray caster's frame of a Scene: the field it reads (made once per Scene, or
// per frame when the emission is shaded for the view), labels, and the pixel filter.
#include <memory>
#include <mutex>

#include "model/shading_model.h"
#include "reference/field.h"
#include "reference/pixel_filter.h"
#include "reference/reference_frame.h"

namespace splat {

namespace {

/// The reference's state per scene (Scene::Impl::state): the dense field of an unshaded
/// scene, made on first use.
class FieldCache {
  public:
    explicit FieldCache(const Scene::Impl& scene) : scene_(scene) {}
    const ReferenceField& field() {
        std::lock_guard<std::mutex> lock(mutex_);
        if (!field_) {
            const SplatList& splats = scene_.splats;
            const RenderSettings& settings = scene_.settings;
            validateReferenceKernel(scene_.kernel);
            if (splats.paletted() && fieldLayout(settings, splats) == FieldLayout::Emission) {
                // The field reads the emission arrays: a full copy (the other layouts expand
                // the densities alone, in ReferenceField).
                SplatList full = splats;
                full.expandEmission();
                field_ = std::make_shared<ReferenceField>(*scene_.volume, full, scene_.kernel,
                                                          fieldLayout(settings, full));
            } else {
                field_ = std::make_shared<ReferenceField>(*scene_.volume, splats, scene_.kernel,
                                                          fieldLayout(settings, splats));
            }
        }
        return *field_;
    }

  private:
    const Scene::Impl& scene_;
    std::mutex mutex_;
    std::shared_ptr<const ReferenceField> field_;
};

/// The reference's nearest-voxel label lookup (null without labels).
const LabelLookup* labelLookup(const Scene::Impl& scene) {
    if (!scene.settings.labels.enabled) return nullptr;
    thread_local LabelLookup lookup;
    lookup = {scene.volume->dims, &scene.labelGrid, &scene.labelTable};
    return &lookup;
}

}  // namespace

Image referenceFrame(const Scene::Impl& scene, const Camera& camera, const RenderSettings& s,
                     RenderStats& stats, Image* depth) {
    if (!scene.shaded())
        return renderReference(*scene.volume, scene.state<FieldCache>().field(), camera, s, &stats,
                               depth, scene.splats.gradientScale, labelLookup(scene));
    // Shaded emission depends on the view: the field is made for this frame.
    SplatList lit = scene.splats;
    lit.expandEmission();
    shadeEmission(scene.splats, scene.settings.shading, camera.view, lit.r, lit.g, lit.b);
    const ReferenceField field(*scene.volume, lit, scene.kernel, FieldLayout::Emission);
    return renderReference(*scene.volume, field, camera, s, &stats, depth,
                           scene.splats.gradientScale, labelLookup(scene));
}

Image filteredReferenceFrame(const Scene::Impl& scene, const Camera& camera,
                             const RenderSettings& s, RenderStats& stats, Image* depth) {
    RenderStats fine;
    const PixelFilterResult r = filteredImage(
        camera, s.quality.pixelFilter, s.quality.pixelFilterTolerance, [&](const CameraParams& p) {
            return referenceFrame(scene, Camera(p, *scene.volume), s, fine, nullptr);
        });
    stats.referenceStep = fine.referenceStep;
    stats.pixelSamples = r.samples;
    stats.pixelFilterChange = r.change;
    if (depth) {
        RenderStats centre;
        (void)referenceFrame(scene, camera, s, centre, depth);
    }
    return r.image;
}

}  // namespace splat
