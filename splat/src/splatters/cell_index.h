#pragma once
// The splat list cut into cells along i within each row: the axis-aligned splatter's state per
// scene, which the factorised sheets read too.
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "model/scene_impl.h"

namespace splat {

/// The axis-aligned splatter's state per scene (Scene::Impl::state), made on first use: the
/// splat list cut into cells of kCellWidth voxels along i within each row (k, j): cell
/// (k * dims.y + j) * cellsX + c holds the splats of row (k, j) with i in
/// [c kCellWidth, (c + 1) kCellWidth), at list positions [start[cell], start[cell + 1])
/// (the list is in (k, j, i) order, so cells are consecutive). The splatter reads any slab of
/// kCellWidth slices along any axis from it in runs of consecutive splats, without a sorted
/// copy of the list per axis.
class CellIndex {
  public:
    static constexpr int kCellWidth = 8;
    explicit CellIndex(const Scene::Impl& scene) : scene_(scene) {}
    int cellsX() const { return (scene_.volume->dims.x + kCellWidth - 1) / kCellWidth; }
    /// Bricks of kCellWidth^3 voxels along each axis.
    glm::ivec3 bricks() const { return (scene_.volume->dims + (kCellWidth - 1)) / kCellWidth; }
    const std::vector<std::uint32_t>& cellStarts() {
        std::lock_guard<std::mutex> lock(mutex_);
        if (!cellStarts_) count();
        return *cellStarts_;
    }
    /// Splats per brick, brick (bi, bj, bk) at (bk * bricks.y + bj) * bricks.x + bi: a slab
    /// along any axis is one layer of these bricks.
    const std::vector<std::uint32_t>& brickCounts() {
        std::lock_guard<std::mutex> lock(mutex_);
        if (!cellStarts_) count();
        return *brickCounts_;
    }

  private:
    /// Makes cellStarts_ and brickCounts_ (one pass over the list).
    void count() {
        const SplatList& splats = scene_.splats;
        const glm::ivec3 dims = scene_.volume->dims;
        const std::size_t cx = std::size_t(cellsX()), rows = std::size_t(dims.y) * dims.z;
        auto start = std::make_unique<std::vector<std::uint32_t>>(rows * cx + 1, 0);
        std::vector<std::uint32_t>& st = *start;
        const std::size_t n = splats.size();
        for (std::size_t q = 0; q < n; ++q) {
            const std::size_t row = std::size_t(splats.k[q]) * dims.y + splats.j[q];
            ++st[row * cx + splats.i[q] / kCellWidth + 1];
        }
        const glm::ivec3 b = bricks();
        auto counts = std::make_unique<std::vector<std::uint32_t>>(std::size_t(b.x) * b.y * b.z, 0);
        for (std::size_t row = 0; row < rows; ++row) {
            const std::size_t j = row % std::size_t(dims.y), k = row / dims.y;
            const std::size_t brickRow = (k / kCellWidth * b.y + j / kCellWidth) * b.x;
            for (std::size_t c = 0; c < cx; ++c) (*counts)[brickRow + c] += st[row * cx + c + 1];
        }
        for (std::size_t c = 1; c < st.size(); ++c) st[c] += st[c - 1];
        cellStarts_ = std::move(start);
        brickCounts_ = std::move(counts);
    }

    const Scene::Impl& scene_;
    std::mutex mutex_;
    std::unique_ptr<std::vector<std::uint32_t>> cellStarts_, brickCounts_;
};

}  // namespace splat
