// The per-brick level of detail of a Scene (Scene::Impl::brickDetail, lodParts; see
// model/brick_lod.h).
#include <tbb/task_arena.h>

#include <algorithm>

#include "model/scene_impl.h"

namespace splat {

Scene::Impl::Impl(const Impl& lvl, SplatList part, Part)
    : volume(lvl.volume),
      settings(lvl.settings),
      given(lvl.given),
      kernel(lvl.kernel),
      splats(std::move(part)),
      transfer(lvl.transfer),
      table(lvl.table),
      poly(lvl.poly),
      level(lvl.level),
      minValue(lvl.minValue),
      maxValue(lvl.maxValue),
      labelTable(lvl.labelTable) {}

const BrickDetail& Scene::Impl::brickDetail() const {
    std::lock_guard<std::mutex> lock(lodMutex_);
    if (!brickDetail_) {
        std::vector<const SplatList*> lists{&splats};
        std::vector<glm::ivec3> dims{volume->dims};
        for (const Impl* l = this; int(lists.size()) <= kLodBrickMaxLevel;) {
            l = l->coarser();
            if (!l) break;
            lists.push_back(&l->splats);
            dims.push_back(l->volume->dims);
        }
        tbb::this_task_arena::isolate(
            [&] { brickDetail_ = std::make_unique<BrickDetail>(splat::brickDetail(lists, dims)); });
    }
    return *brickDetail_;
}

std::vector<std::shared_ptr<const Scene::Impl>> Scene::Impl::lodParts(
    const std::vector<std::uint8_t>& levels) const {
    const BrickDetail& detail = brickDetail();
    std::lock_guard<std::mutex> lock(lodMutex_);
    if (levels == lodLevels_) return lodParts_;
    int coarsest = 0;
    for (std::size_t b = 0; b < levels.size(); ++b)
        if (detail.occupied[b]) coarsest = std::max(coarsest, int(levels[b]));
    // Merging under a tenth of level 0 is not worth a copy of the rest (memory: the part of
    // level 0 would be nearly a second level-0 list): the frame is level 0.
    std::size_t kept = 0;
    for (std::size_t q = 0; q < splats.size(); ++q)
        kept += levels[detail.brick(splats.i[q], splats.j[q], splats.k[q])] == 0;
    if (coarsest == 0 || kept > splats.size() - splats.size() / 10) {
        lodLevels_ = levels;
        lodParts_ = {std::shared_ptr<const Impl>(std::shared_ptr<const Impl>(), this)};
        return lodParts_;
    }
    std::vector<std::shared_ptr<const Impl>> parts;
    const Impl* lvl = this;
    for (int L = 0; lvl && L <= coarsest; ++L, lvl = L <= coarsest ? lvl->coarser() : nullptr) {
        // Whether some occupied brick took level L, and whether all of them did.
        bool some = false, all = true;
        for (std::size_t b = 0; b < levels.size(); ++b)
            if (detail.occupied[b]) {
                some |= levels[b] == L;
                all &= levels[b] == L;
            }
        if (!some) continue;
        if (all)  // the level itself (owned by the pyramid: no owner here)
            parts.push_back(std::shared_ptr<const Impl>(std::shared_ptr<const Impl>(), lvl));
        else
            parts.push_back(std::make_shared<const Impl>(
                *lvl, splatsOfBricks(lvl->splats, L, levels, detail.bricks), Part{}));
    }
    lodLevels_ = levels;
    lodParts_ = parts;
    return parts;
}

}  // namespace splat
