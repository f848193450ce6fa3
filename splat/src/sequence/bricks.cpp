// Sort-last bricks (splat/bricks.h).
#include "splat/bricks.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <memory>
#include <optional>

#include "footprint/kernel.h"
#include "frame/stopwatch.h"
#include "splat/camera.h"
#include "splat/error.h"
#include "splat/scene.h"

namespace splat {

BrickLayout splitBricks(const glm::ivec3& dims, int count, int ghost) {
    const std::size_t samples = std::size_t(dims.x) * std::size_t(dims.y) * std::size_t(dims.z);
    if (count < 1 || std::size_t(count) > samples)
        throw Error("bricks: " + std::to_string(count) + " bricks of a volume of " +
                    std::to_string(samples) + " samples");
    if (ghost < 0) throw Error("bricks: ghost layers must be >= 0");
    BrickLayout L;
    L.dims = dims;
    L.ghost = ghost;
    std::function<int(glm::ivec3, glm::ivec3, int)> split = [&](glm::ivec3 lo, glm::ivec3 hi,
                                                                int k) {
        const int node = int(L.nodes.size());
        L.nodes.emplace_back();
        const glm::ivec3 n = hi - lo;
        if (k == 1) {
            Brick b;
            b.lo = lo;
            b.hi = hi;
            b.loadLo = glm::max(lo - ghost, glm::ivec3(0));
            b.loadHi = glm::min(hi + ghost, dims);
            L.nodes[node].brick = int(L.bricks.size());
            L.bricks.push_back(b);
            return node;
        }
        // The longest axis (ties: x, then y, then z), cut so that the children own samples
        // in the ratio of their bricks, k0 : k - k0, and at least one sample per brick.
        int axis = 0;
        for (int a = 1; a < 3; ++a)
            if (n[a] > n[axis]) axis = a;
        const int k0 = k / 2;
        const std::int64_t area = std::int64_t(n.x) * n.y * n.z / n[axis];
        const int least0 = int((k0 + area - 1) / area), least1 = int((k - k0 + area - 1) / area);
        if (least0 + least1 > n[axis])
            throw Error("bricks: " + std::to_string(count) +
                        " bricks leave one without samples in a volume of " +
                        std::to_string(dims.x) + "x" + std::to_string(dims.y) + "x" +
                        std::to_string(dims.z));
        const int cut =
            std::clamp(int(std::lround(double(n[axis]) * k0 / k)), least0, n[axis] - least1);
        glm::ivec3 mid0 = hi, mid1 = lo;
        mid0[axis] = lo[axis] + cut;
        mid1[axis] = lo[axis] + cut;
        L.nodes[node].axis = axis;
        L.nodes[node].split = lo[axis] + cut;
        const int c0 = split(lo, mid0, k0);
        const int c1 = split(mid1, hi, k - k0);
        L.nodes[node].child[0] = c0;
        L.nodes[node].child[1] = c1;
        return node;
    };
    split(glm::ivec3(0), dims, count);
    return L;
}

int ghostLayers(double radius, const glm::dvec3& spacing) {
    // Every sample whose kernel a sheet pixel of the owned box can see: along the normal of
    // a brick face, R sqrt 2 + 1/2 index units (model/clip_region.h, clipReach), plus one
    // layer for the central-difference gradients. The kernel's radius is in index units, so
    // the spacing does not enter.
    (void)spacing;
    return int(std::ceil(radius * std::sqrt(2.0) + 0.5)) + 1;
}

std::vector<int> visibilityOrder(const BrickLayout& layout, const Volume& whole,
                                 const CameraParams& params) {
    const Camera cam(params, whole);
    std::vector<int> order;
    std::function<void(int)> visit = [&](int node) {
        const BrickLayout::Node& n = layout.nodes[std::size_t(node)];
        if (n.axis < 0) {
            order.push_back(n.brick);
            return;
        }
        glm::dvec3 p(0.0), q(0.0);
        p[n.axis] = n.split - 0.5;
        q[n.axis] = n.split + 0.5;
        const glm::dvec3 a = whole.world(p), b = whole.world(q);  // the plane between them
        const glm::dvec3 normal = b - a, point = 0.5 * (a + b);
        // Near child: the one on the eye's side (perspective) or the one the rays cross
        // first (orthographic: rays run along view).
        const double side =
            cam.perspective() ? glm::dot(cam.eye - point, normal) : -glm::dot(cam.view, normal);
        const int nearChild = side < 0 ? 0 : 1;
        visit(n.child[nearChild]);
        visit(n.child[1 - nearChild]);
    };
    visit(0);
    return order;
}

Volume brickGeometry(const Volume& whole, const Brick& brick) {
    Volume v;
    v.dims = brick.loadHi - brick.loadLo;
    v.spacing = whole.spacing;
    v.origin = whole.world(glm::dvec3(brick.loadLo));
    v.direction = whole.direction;
    v.background = whole.background;
    v.backgroundSource = whole.backgroundSource;
    v.source = whole.source;
    return v;
}

RenderSettings brickSettings(const RenderSettings& frame, const Volume& whole, const Brick& brick,
                             const glm::ivec3& dims) {
    RenderSettings s = frame;
    const Camera cam(frame.camera, whole);
    // The Camera's points are in the volume's frame; CameraParams are world (RAS).
    s.camera.lookAtSet = true;
    s.camera.lookAt = whole.direction * cam.target;
    s.camera.eye = whole.direction * cam.eye;
    s.camera.upHint = whole.direction * cam.up;
    s.camera.pixelSize = cam.pixelSize;
    s.background = glm::vec4(0.0f);
    s.quality.earlyTermination = 0;
    // The owned box, half a sample beyond the owned samples, as one clip plane per inner
    // face (open on the volume's faces: the field reaches past them by the kernel's
    // support). Planes, not a world-aligned crop box, so that any grid orientation works.
    const glm::dvec3 o = whole.world(glm::dvec3(0.0));
    for (int a = 0; a < 3; ++a) {
        glm::dvec3 e(0.0);
        e[a] = 1.0;
        const glm::dvec3 axis = glm::normalize(whole.world(e) - o);  // increasing index
        glm::dvec3 face = glm::dvec3(brick.lo) - 0.5;
        if (brick.lo[a] > 0) s.clipping.planes.push_back({whole.world(face), -axis});
        face = glm::dvec3(brick.hi) - 0.5;
        if (brick.hi[a] < dims[a]) s.clipping.planes.push_back({whole.world(face), axis});
    }
    return s;
}

namespace {

/// Lays the partial image `behind` behind `out` as `mode` combines pieces of a ray.
void compositeBehind(Image& out, const Image& behind, RenderMode mode) {
    if (behind.width != out.width || behind.height != out.height)
        throw Error("bricks: partial images differ in size");
    for (std::size_t p = 0; p < out.pixels.size(); ++p) {
        glm::vec4& o = out.pixels[p];
        const glm::vec4& c = behind.pixels[p];
        if (mode == RenderMode::Mip)
            o = glm::max(o, c);
        else if (mode == RenderMode::Xray)
            o = glm::vec4(glm::vec3(o) + glm::vec3(c), 1.0f);
        else
            o += (1.0f - o.a) * c;
    }
}

}  // namespace

Image compositePieces(const std::vector<const Image*>& frontToBack, RenderMode mode) {
    if (frontToBack.empty()) throw Error("bricks: no partial image to composite");
    Image out = *frontToBack.front();
    for (std::size_t b = 1; b < frontToBack.size(); ++b) compositeBehind(out, *frontToBack[b], mode);
    return out;
}

void blendBackground(Image& image, RenderMode mode, const glm::vec4& background) {
    if (mode == RenderMode::Dvr || mode == RenderMode::Iso)
        for (glm::vec4& o : image.pixels) o += (1.0f - o.a) * background;
}

Image compositeBricks(const std::vector<const Image*>& frontToBack, RenderMode mode,
                      const glm::vec4& background) {
    Image out = compositePieces(frontToBack, mode);
    blendBackground(out, mode, background);
    return out;
}

void LocalBrickGroup::agree(const std::string& error) {
    if (!error.empty()) throw Error(error);
}

Image LocalBrickGroup::composite(std::vector<std::pair<int, Image>>& partials,
                                 const std::vector<int>& frontToBack, int, int, RenderMode mode,
                                 const glm::vec4& background, std::uint64_t*) {
    std::vector<const Image*> ordered;
    for (int b : frontToBack)
        for (const auto& [brick, image] : partials)
            if (brick == b) ordered.push_back(&image);
    return compositeBricks(ordered, mode, background);
}

std::optional<Image> emptyBrickImage(const Volume& whole, const RenderSettings& brickFrame) {
    // Two samples of b a side at the volume's corner, spacing and orientation.
    Volume probe = makeVolume(glm::ivec3(2), whole.spacing, whole.source);
    probe.origin = whole.origin;
    probe.direction = whole.direction;
    probe.background = whole.background;
    std::fill(probe.data.begin(), probe.data.end(), whole.background);
    const Scene scene(std::move(probe), brickFrame);
    if (scene.splats().size() > 0) return std::nullopt;
    Image image = scene.render(brickFrame);
    for (const glm::vec4& p : image.pixels)
        if (p != image.pixels.front()) return std::nullopt;
    return image;
}

BrickedFrames::BrickedFrames(const Volume& geometry, std::function<Volume(const Brick&)> load,
                             const RenderSettings& frame, int bricks, BrickGroup& group,
                             BrickComposite composite, bool keep,
                             std::function<bool(const Brick&)> empty)
    : geometry_(geometry),
      load_(std::move(load)),
      group_(group),
      s_(frame),
      composite_(composite),
      keep_(keep) {
    if (frame.edges.enabled())
        throw Error(
            "--bricks: edge enhancement scales by the whole volume's largest gradient; "
            "render it without bricks");
    if (frame.labels.enabled) throw Error("--bricks: labels are rendered without bricks");
    const footprint::Kernel kernel =
        footprint::Kernel::fromName(frame.kernel, frame.kernelSigma, frame.kernelRadius);
    layout_ = splitBricks(geometry.dims, bricks, ghostLayers(kernel.radius(), geometry.spacing));
    st_.bricks = bricks;
    for (int b = group.rank(); b < bricks; b += group.size()) mine_.push_back(b);
    st_.rendered = int(mine_.size());
    empty_.assign(mine_.size(), 0);
    std::string error;
    try {
        if (empty)
            for (std::size_t i = 0; i < mine_.size(); ++i)
                empty_[i] = empty(layout_.bricks[std::size_t(mine_[i])]);
    } catch (const std::exception& e) {
        error = e.what();
    }
    group.agree(error);
    st_.empty = int(std::count(empty_.begin(), empty_.end(), 1));
    volumes_.resize(mine_.size());
    scenes_.resize(3);

    // The whole volume's range, when the settings are relative to it: one pass that loads
    // each brick; kept when the Scenes are (`keep`), or when this process holds one brick.
    const bool relative = frame.transfer.normalized || frame.isoNormalized;
    const bool exactSheets = exact(frame.renderer);
    float lo = INFINITY, hi = -INFINITY;
    try {
        if (keep || relative || (mine_.size() == 1 && !exactSheets))
            for (std::size_t i = 0; i < mine_.size(); ++i) {
                if (empty_[i]) {  // b alone: loaded only if its frames need it
                    lo = std::min(lo, geometry.background), hi = std::max(hi, geometry.background);
                    continue;
                }
                Volume v = loadBrick(mine_[i]);
                if (relative)
                    for (std::size_t n = 0; n < v.voxelCount(); ++n)
                        lo = std::min(lo, v.value(n)), hi = std::max(hi, v.value(n));
                if (keep || mine_.size() == 1)
                    volumes_[i] = std::make_shared<const Volume>(std::move(v));
            }
    } catch (const std::exception& e) {
        error = e.what();
    }
    group.agree(error);
    if (relative) {
        group.range(lo, hi);
        s_.transfer = s_.transfer.resolved(lo, hi);
        if (s_.isoNormalized) {
            s_.isoLevel = lo + s_.isoLevel * (hi - lo);
            s_.isoNormalized = false;
        }
    }
    if (!keep) return;
    try {  // the Scenes, once (their camera is any view's: a Scene does not depend on it)
        for (std::size_t i = 0; i < mine_.size(); ++i) {
            if (empty_[i]) continue;  // built at its first frame that renders it
            RenderSettings bs =
                brickSettings(s_, geometry_, layout_.bricks[std::size_t(mine_[i])], geometry_.dims);
            if (exactSheets) bs.clipping.planes.clear();
            scene(int(i), bs);
        }
    } catch (const std::exception& e) {
        error = e.what();
    }
    group.agree(error);
}

BrickedFrames::~BrickedFrames() = default;

Volume BrickedFrames::loadBrick(int b) {
    const auto t = Clock::now();
    Volume v = load_(layout_.bricks[std::size_t(b)]);
    v.background = geometry_.background;
    st_.samplesLoaded = std::max(st_.samplesLoaded, v.voxelCount());
    st_.loadMs += msSince(t);
    return v;
}

std::shared_ptr<const Scene> BrickedFrames::scene(int i, const RenderSettings& bs) {
    const std::size_t k = std::size_t(i);
    std::vector<std::shared_ptr<const Scene>>& set = scenes_.at(std::size_t(bs.renderer));
    set.resize(mine_.size());
    if (set[k]) return set[k];
    std::shared_ptr<const Volume> v = keep_ ? volumes_[k] : std::move(volumes_[k]);
    if (!v) {
        v = std::make_shared<const Volume>(loadBrick(mine_[k]));
        if (keep_) volumes_[k] = v;
    }
    const auto t = Clock::now();
    auto sc = std::make_shared<const Scene>(std::move(v), bs);
    st_.sceneMs += msSince(t);
    if (keep_) set[k] = sc;
    return sc;
}

Image BrickedFrames::render(const CameraParams& camera) { return render(camera, s_.renderer); }

Image BrickedFrames::render(const CameraParams& camera, RendererKind renderer, RenderStats* stats) {
    const auto start = Clock::now();
    RenderStats frameStats;
    Image out = renderFrame(camera, renderer, frameStats);
    frameStats.milliseconds = msSince(start);
    if (stats) *stats = frameStats;
    return out;
}

Image BrickedFrames::renderFrame(const CameraParams& camera, RendererKind renderer,
                                 RenderStats& frameStats) {
    RenderSettings s = s_;
    s.camera = camera;
    s.renderer = renderer;
    emptyImage_.reset();
    if (st_.empty > 0) {
        std::string error;
        try {
            emptyImage_ = emptyImage(s);
        } catch (const std::exception& e) {
            error = e.what();
        }
        group_.agree(error);
    }
    if (exact(renderer)) {
        // The slab sheets are sums over the bricks: a brick of b that makes no splat adds
        // nothing to them (every process keeps one brick, so that it takes part).
        std::vector<std::size_t> kept;
        for (std::size_t i = 0; i < mine_.size(); ++i)
            if (!emptyImage_ || !empty_[i]) kept.push_back(i);
        if (kept.empty() && !mine_.empty()) kept.push_back(0);
        std::vector<int> bricks;
        for (std::size_t i : kept) bricks.push_back(mine_[i]);
        return renderBrickedSlabs(
            geometry_, layout_, bricks,
            [&](int k, const RenderSettings& bs) { return scene(int(kept[std::size_t(k)]), bs); },
            s, group_, st_);
    }
    if (dynamic_cast<LocalBrickGroup*>(&group_)) return renderInOrder(camera, s, frameStats);
    return renderPieces(camera, s, frameStats);
}

std::optional<Image> BrickedFrames::emptyImage(const RenderSettings& s) const {
    Brick whole;
    whole.hi = whole.loadHi = geometry_.dims;
    return emptyBrickImage(geometry_, brickSettings(s, geometry_, whole, geometry_.dims));
}

Image BrickedFrames::renderPiece(std::size_t i, const RenderSettings& s, RenderStats& frameStats) {
    if (empty_[i] && emptyImage_) return *emptyImage_;
    const int b = mine_[i];
    const RenderSettings bs =
        brickSettings(s, geometry_, layout_.bricks[std::size_t(b)], geometry_.dims);
    const std::shared_ptr<const Scene> sc = scene(int(i), bs);
    const auto t = Clock::now();
    RenderStats rs;
    Image image = sc->render(bs, &rs);
    st_.renderMs += msSince(t);
    st_.splats += rs.splats;
    frameStats.splats += rs.splats;
    frameStats.voxels += rs.voxels;
    frameStats.sheetAxis = rs.sheetAxis;
    frameStats.sheetSign = rs.sheetSign;
    return image;
}

/// Every brick's partial image held until the group composites them (the processes
/// exchange them).
Image BrickedFrames::renderPieces(const CameraParams& camera, const RenderSettings& s,
                                  RenderStats& frameStats) {
    std::vector<std::pair<int, Image>> partials;
    std::string error;
    try {
        for (std::size_t i = 0; i < mine_.size(); ++i)
            partials.emplace_back(mine_[i], renderPiece(i, s, frameStats));
    } catch (const std::exception& e) {
        error = e.what();
    }
    group_.agree(error);
    const auto t = Clock::now();
    const std::vector<int> order = visibilityOrder(layout_, geometry_, camera);
    Image out = group_.composite(partials, order, camera.width, camera.height, s.mode, s.background,
                                 &st_.bytesExchanged);
    st_.compositeMs += msSince(t);
    return out;
}

/// One process: the bricks rendered in visibility order, each partial image composited
/// into the frame as soon as it is rendered (compositePieces' operations in its order, so
/// the frame is the same) and freed: one partial image held, not one per brick.
Image BrickedFrames::renderInOrder(const CameraParams& camera, const RenderSettings& s,
                                   RenderStats& frameStats) {
    std::vector<int> slot(layout_.bricks.size(), -1);
    for (std::size_t i = 0; i < mine_.size(); ++i) slot[std::size_t(mine_[i])] = int(i);
    Image out, rendered;
    for (int b : visibilityOrder(layout_, geometry_, camera)) {
        const std::size_t i = std::size_t(slot[std::size_t(b)]);
        const bool skip = empty_[i] && emptyImage_;
        if (!skip) rendered = renderPiece(i, s, frameStats);
        const Image& piece = skip ? *emptyImage_ : rendered;
        const auto t = Clock::now();
        if (out.pixels.empty())
            out = piece;
        else
            compositeBehind(out, piece, s.mode);
        st_.compositeMs += msSince(t);
    }
    blendBackground(out, s.mode, s.background);
    return out;
}

Image renderBricked(const Volume& geometry, const std::function<Volume(const Brick&)>& load,
                    const RenderSettings& frame, int bricks, BrickGroup& group, BrickStats* stats,
                    BrickComposite composite, const std::function<bool(const Brick&)>& empty) {
    BrickedFrames frames(geometry, load, frame, bricks, group, composite, false, empty);
    Image out = frames.render(frame.camera);
    if (stats) *stats = frames.stats();
    return out;
}

}  // namespace splat
