// The frame farm seam of renderSequence (splat/frame_farm.h).
#include "splat/frame_farm.h"

#include <mutex>

#include "splat/error.h"
#include "splat/scene.h"

namespace splat {

namespace {
std::shared_ptr<FrameFarm>& farmSlot() {
    static std::shared_ptr<FrameFarm> farm;
    return farm;
}
}  // namespace

void installFrameFarm(std::shared_ptr<FrameFarm> farm) { farmSlot() = std::move(farm); }

FrameFarm* installedFrameFarm() { return farmSlot().get(); }

SequenceFrame renderFrameJob(const Scene& scene, const std::vector<RendererKind>& renderers,
                             const FrameJob& job) {
    SequenceFrame f;
    f.view = job.view;
    f.images.resize(renderers.size());
    f.stats.resize(renderers.size());
    RenderSettings s = scene.settings();
    s.camera = job.camera;
    for (std::size_t k = 0; k < renderers.size(); ++k) {
        s.renderer = renderers[k];
        f.images[k] = scene.render(s, &f.stats[k]);
    }
    return f;
}

void renderSequenceOnFarm(FrameFarm& farm, const Scene& scene,
                          const std::vector<RendererKind>& renderers, const CameraPath& path,
                          const std::vector<std::size_t>& views, const SequenceOptions& options,
                          const std::function<void(SequenceFrame&&)>& sink) {
    std::vector<FrameJob> jobs;
    for (std::size_t v : views) jobs.push_back({v, path.views[v]});
    const std::size_t total = views.size() * renderers.size();
    std::size_t done = 0;
    // Progress counts the frames as they come back, in view order, for the whole job.
    farm.render(
        renderers, jobs, [&](const FrameJob& job) { return renderFrameJob(scene, renderers, job); },
        [&](SequenceFrame&& f) {
            bool go = true;
            for (std::size_t k = 0; k < renderers.size(); ++k) {
                ++done;
                if (options.progress &&
                    !options.progress(done, total,
                                      std::string(toString(renderers[k])) + ", view " +
                                          std::to_string(f.view + 1)))
                    go = false;
            }
            sink(std::move(f));
            if (!go) throw Cancelled();
        });
}

}  // namespace splat
