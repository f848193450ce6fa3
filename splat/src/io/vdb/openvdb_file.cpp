// OpenVDB files as volumes (openvdb_file.h), and listVdbGrids for `splat info`.
#include "io/vdb/openvdb_file.h"

#include <string>
#include <vector>

#include "io/parse_in_child.h"
#include "io/volume_detail.h"
#include "splat/error.h"
#include "splat/sparse_files.h"

#if SPLAT_HAVE_OPENVDB
#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Count.h>

#include <array>
#include <fstream>
#include <istream>
#include <mutex>
#endif

namespace fs = std::filesystem;

namespace splat::detail {

bool isVdbFile(const fs::path& p) { return toLower(p.extension().string()) == ".vdb"; }

}  // namespace splat::detail

#if !SPLAT_HAVE_OPENVDB

namespace splat {
namespace {
[[noreturn]] void withoutOpenVdb(const fs::path& p) {
    throw Error(detail::displayName(p) +
                ": this splat was built without OpenVDB (CMake option SPLAT_OPENVDB; Debian: "
                "libopenvdb-dev)");
}
}  // namespace

bool openVdbAvailable() { return false; }
std::vector<VdbGridInfo> listVdbGrids(const std::string& path) { withoutOpenVdb(path); }

namespace detail {
Volume loadVdb(const fs::path& p, const LoadOptions&) { withoutOpenVdb(p); }
Volume vdbGeometry(const fs::path& p, const LoadOptions&) { withoutOpenVdb(p); }
Volume loadVdbBrick(const fs::path& p, const LoadOptions&, const glm::ivec3&, const glm::ivec3&) {
    withoutOpenVdb(p);
}
bool vdbBoxHoldsOnlyBackground(const fs::path& p, const LoadOptions&, const glm::ivec3&,
                               const glm::ivec3&) {
    withoutOpenVdb(p);
}
glm::dvec2 vdbValueRange(const fs::path& p, const LoadOptions&) { withoutOpenVdb(p); }
}  // namespace detail
}  // namespace splat

#else

namespace splat {
namespace {

bool scalarGrid(const openvdb::GridBase& g) {
    return g.isType<openvdb::FloatGrid>() || g.isType<openvdb::DoubleGrid>();
}

/// Runs `f`, turning OpenVDB's exceptions into one splat::Error line about `name`.
template <typename F>
auto guarded(const std::string& name, F&& f) {
    try {
        return f();
    } catch (const Error&) {
        throw;
    } catch (const std::exception& e) {
        throw Error(name + ": not a readable OpenVDB file (" + e.what() + ")");
    }
}

/// A file's bytes as a stream whose reads never fail: past the last byte it serves zeros and
/// remembers that it did. OpenVDB reads lengths into uninitialised locals without checking
/// the stream (a truncated compressed block's size is whatever the stack held, and the next
/// `new[]` asks for it), so on a truncated file two processes could read different sizes.
/// Served zeros, every process reads the same values, and the reader refuses the file
/// afterwards because `overran()`.
class ZeroPaddedFile : public std::streambuf {
public:
    ZeroPaddedFile(const fs::path& p, const std::string& name) : size_(detail::regularFileSize(p)) {
        if (!file_.open(p, std::ios::in | std::ios::binary))
            throw Error(name + ": cannot open the file");
    }
    bool overran() const { return overran_; }

protected:
    int_type underflow() override {
        if (gptr() < egptr()) return traits_type::to_int_type(*gptr());
        start_ += std::uint64_t(egptr() - eback());
        std::streamsize n = 0;
        if (start_ < size_ && file_.pubseekpos(std::streamoff(start_), std::ios::in) !=
                                  std::streampos(std::streamoff(-1)))
            n = file_.sgetn(buf_.data(),
                            std::streamsize(std::min<std::uint64_t>(buf_.size(), size_ - start_)));
        if (n <= 0) {
            overran_ = true;
            std::fill(buf_.begin(), buf_.end(), char(0));
            n = std::streamsize(buf_.size());
        }
        setg(buf_.data(), buf_.data(), buf_.data() + n);
        return traits_type::to_int_type(buf_[0]);
    }
    pos_type seekoff(off_type off, std::ios::seekdir dir, std::ios::openmode which) override {
        const auto here = off_type(start_) + off_type(gptr() - eback());
        const off_type base = dir == std::ios::beg   ? 0
                              : dir == std::ios::cur ? here
                                                     : off_type(size_);
        return seekpos(pos_type(base + off), which);
    }
    pos_type seekpos(pos_type pos, std::ios::openmode which) override {
        if (!(which & std::ios::in) || off_type(pos) < 0) return pos_type(off_type(-1));
        start_ = std::uint64_t(off_type(pos));
        setg(buf_.data(), buf_.data(), buf_.data());  // the next read starts at `start_`
        return pos;
    }

private:
    std::filebuf file_;
    std::uint64_t size_ = 0, start_ = 0;  ///< the file's size; the offset of eback()
    std::array<char, 1 << 16> buf_{};
    bool overran_ = false;
};

/// Every grid of the file, read whole and in order through a ZeroPaddedFile; a file whose
/// grids run past its last byte is refused.
openvdb::GridPtrVecPtr readGrids(const fs::path& p, const std::string& name) {
    ZeroPaddedFile bytes(p, name);
    std::istream in(&bytes);
    const auto truncated = [&] {
        return Error(name + ": malformed OpenVDB file (its grids run past its last byte: "
                            "truncated or damaged)");
    };
    try {
        openvdb::io::Stream stream(in, /*delayLoad=*/false);
        if (bytes.overran()) throw truncated();
        return stream.getGrids();
    } catch (const Error&) {
        throw;
    } catch (...) {
        if (bytes.overran()) throw truncated();
        throw;
    }
}

/// A file's grids (OpenVDB's errors become one splat::Error line).
struct VdbFile {
    std::string name;
    openvdb::GridPtrVecPtr grids;

    explicit VdbFile(const fs::path& p) : name(detail::displayName(p)) {
        static std::once_flag once;
        std::call_once(once, [] { openvdb::initialize(); });
        detail::regularFileSize(p);
        // OpenVDB can corrupt the heap or abort on a damaged tree (a byte changed in a leaf's
        // header): the file is read once in a child process first, the same way.
        detail::parseInChild(name, "OpenVDB", "OpenVDB", [&] { readGrids(p, name); });
        grids = guarded(name, [&] { return readGrids(p, name); });
        if (!grids) throw Error(name + ": not a readable OpenVDB file");
    }
};

/// The grid LoadOptions::grid names, or the default.
openvdb::GridBase::Ptr chooseGrid(const VdbFile& f, const std::string& wanted) {
    const openvdb::GridPtrVecPtr& grids = f.grids;
    std::string names;
    for (const auto& g : *grids) names += (names.empty() ? "" : ", ") + g->getName();
    if (grids->empty()) throw Error(f.name + ": holds no grids");
    const auto byName = [&](const std::string& n) -> openvdb::GridBase::Ptr {
        for (const auto& g : *grids)
            if (g->getName() == n) return g;
        return nullptr;
    };
    if (!wanted.empty()) {
        const auto g = byName(wanted);
        if (!g) throw Error(f.name + ": no grid named '" + wanted + "' (grids: " + names + ")");
        if (!scalarGrid(*g))
            throw Error(f.name + ": grid '" + wanted + "' holds " + g->valueType() +
                        " values; splat renders float and double grids");
        return g;
    }
    if (const auto g = byName("density"); g && scalarGrid(*g)) return g;
    for (const auto& g : *grids)
        if (scalarGrid(*g)) return g;
    throw Error(f.name + ": no float or double grid (grids: " + names + ")");
}

/// The transform's per-axis scale and translation; anything else is refused.
void axisAligned(const openvdb::GridBase& g, const std::string& what, glm::dvec3& scale,
                 glm::dvec3& translation, bool* ok = nullptr) {
    const openvdb::math::MapBase::ConstPtr map = g.transform().baseMap();
    bool aligned = map->isLinear();
    if (aligned) {
        const openvdb::Mat4d m = map->getAffineMap()->getMat4();
        for (int r = 0; r < 3; ++r) {
            scale[r] = m(r, r);
            translation[r] = m(3, r);
            for (int c = 0; c < 3; ++c)
                if (r != c && std::abs(m(r, c)) > 1e-9 * std::abs(m(r, r))) aligned = false;
            if (!(m(r, r) > 0) || !std::isfinite(m(r, r)) || !std::isfinite(m(3, r)))
                aligned = false;
        }
    }
    if (ok) {
        *ok = aligned;
        return;
    }
    if (!aligned)
        throw Error(what + ": grid '" + g.getName() + "' has a " + map->type() +
                    " transform that is not a positive scale per axis and a translation "
                    "(splat reads axis-aligned grids)");
}

bool fileBBox(const openvdb::GridBase& g, openvdb::CoordBBox& box) {
    const auto lo = g.getMetadata<openvdb::Vec3IMetadata>(openvdb::GridBase::META_FILE_BBOX_MIN);
    const auto hi = g.getMetadata<openvdb::Vec3IMetadata>(openvdb::GridBase::META_FILE_BBOX_MAX);
    if (!lo || !hi) return false;
    box = openvdb::CoordBBox(openvdb::Coord(lo->value()), openvdb::Coord(hi->value()));
    return true;
}

template <typename GridT>
double backgroundOf(const openvdb::GridBase& g) {
    return double(static_cast<const GridT&>(g).background());
}

double background(const openvdb::GridBase& g) {
    return g.isType<openvdb::FloatGrid>() ? backgroundOf<openvdb::FloatGrid>(g)
                                          : backgroundOf<openvdb::DoubleGrid>(g);
}

/// The volume's geometry (no samples) for the active bounding box `box`.
Volume geometry(const std::string& name, const openvdb::GridBase& g, const openvdb::CoordBBox& box,
                std::uint64_t active) {
    if (box.empty()) throw Error(name + ": grid '" + g.getName() + "' has no active voxels");
    Volume v;
    glm::dvec3 scale, t;
    axisAligned(g, name, scale, t);
    const openvdb::Coord d = box.dim();
    v.dims = glm::ivec3(d.x(), d.y(), d.z());
    checkedVoxelCount(v.dims, name);
    v.spacing = scale;
    v.origin = t + scale * glm::dvec3(box.min().x(), box.min().y(), box.min().z());
    v.source = std::string("OpenVDB ") + g.valueType() + " grid '" + g.getName() + "', " +
               std::to_string(active) + " active voxels (" + name + ")";
    return v;
}

/// Calls `voxel(coord, value)` for every active voxel of `grid` inside `box` and
/// `tile(box, value)` for every active tile's part of it; either returns true to stop.
/// The leaves that meet `box` are found by their origins (one probe of the tree each), so
/// the cost follows the box and its active voxels, not the grid.
template <typename GridT, typename Voxel, typename Tile>
void visitActive(const GridT& grid, const openvdb::CoordBBox& box, Voxel&& voxel, Tile&& tile) {
    using TreeT = typename GridT::TreeType;
    const TreeT& tree = grid.tree();
    constexpr int dim = int(TreeT::LeafNodeType::DIM);
    const openvdb::Coord first = box.min() & ~(dim - 1);  // the first leaf's origin
    for (int z = first.z(); z <= box.max().z(); z += dim)
        for (int y = first.y(); y <= box.max().y(); y += dim)
            for (int x = first.x(); x <= box.max().x(); x += dim) {
                const auto* leaf = tree.probeConstLeaf(openvdb::Coord(x, y, z));
                if (!leaf) continue;
                for (auto it = leaf->cbeginValueOn(); it; ++it)
                    if (box.isInside(it.getCoord()) && voxel(it.getCoord(), *it)) return;
            }
    auto it = tree.cbeginValueOn();
    it.setMaxDepth(TreeT::ValueOnCIter::LEAF_DEPTH - 1);  // tiles of the root and inner nodes
    for (; it; ++it) {
        openvdb::CoordBBox t;
        it.getBoundingBox(t);
        t.intersect(box);
        if (!t.empty() && tile(t, *it)) return;
    }
}

/// Fills `v` (the box [lo, lo + v.dims) in index space, already holding b) with the grid's
/// active values: voxels one by one, active tiles over their boxes.
template <typename GridT>
void fillActive(const GridT& grid, const openvdb::Coord& lo, Volume& v) {
    const openvdb::CoordBBox box(lo, lo + openvdb::Coord(v.dims.x - 1, v.dims.y - 1, v.dims.z - 1));
    visitActive(
        grid, box,
        [&](const openvdb::Coord& c, double value) {
            v.at(c.x() - lo.x(), c.y() - lo.y(), c.z() - lo.z()) = float(value);
            return false;
        },
        [&](const openvdb::CoordBBox& t, double value) {
            for (int z = t.min().z(); z <= t.max().z(); ++z)
                for (int y = t.min().y(); y <= t.max().y(); ++y)
                    for (int x = t.min().x(); x <= t.max().x(); ++x)
                        v.at(x - lo.x(), y - lo.y(), z - lo.z()) = float(value);
            return false;
        });
}

/// Whether `box` (index space) holds an active voxel or tile whose value is not `b`.
template <typename GridT>
bool holdsOtherThan(const GridT& grid, const openvdb::CoordBBox& box, double b) {
    bool found = false;
    const auto other = [&](double value) {
        found = float(value) != float(b);
        return found;
    };
    visitActive(
        grid, box, [&](const openvdb::Coord&, double value) { return other(value); },
        [&](const openvdb::CoordBBox&, double value) { return other(value); });
    return found;
}

/// The box [lo, hi) of the volume whose index (0,0,0) is voxel `origin` of `grid`.
Volume readBox(const std::string& name, const openvdb::GridBase& grid, const Volume& g,
               const openvdb::Coord& origin, const glm::ivec3& lo, const glm::ivec3& hi) {
    Volume v = makeVolume(hi - lo, g.spacing, name);
    v.origin = g.world(glm::dvec3(lo));
    v.source = g.source;
    v.note = g.note;
    v.background = g.background;
    v.backgroundSource = g.backgroundSource;
    std::fill(v.data.begin(), v.data.end(), g.background);
    const openvdb::Coord at = origin + openvdb::Coord(lo.x, lo.y, lo.z);
    if (grid.isType<openvdb::FloatGrid>())
        fillActive(static_cast<const openvdb::FloatGrid&>(grid), at, v);
    else
        fillActive(static_cast<const openvdb::DoubleGrid&>(grid), at, v);
    return v;
}

struct Chosen {
    openvdb::GridBase::ConstPtr meta;
    openvdb::CoordBBox box;
    Volume geometry;
};

/// The chosen grid's geometry; `grid` receives the whole grid.
Chosen choose(const VdbFile& f, const LoadOptions& options, openvdb::GridBase::Ptr* grid) {
    Chosen c;
    *grid = chooseGrid(f, options.grid);
    c.meta = *grid;
    c.box = (*grid)->evalActiveVoxelBoundingBox();
    c.geometry = geometry(f.name, **grid, c.box, (*grid)->activeVoxelCount());
    c.geometry.background = float(background(**grid));
    c.geometry.backgroundSource = "OpenVDB grid background";
    return c;
}

/// The chosen grid of one file read whole (its tree: memory follows the active voxels, not
/// the bounding box) with its geometry: a frame's bricks read their samples from it.
struct OpenGrid {
    std::string key, name;
    openvdb::GridBase::Ptr grid;
    openvdb::Coord origin;  ///< the voxel at the volume's index (0, 0, 0)
    Volume geometry;

    void check(const glm::ivec3& lo, const glm::ivec3& hi) const {
        if (glm::any(glm::lessThan(lo, glm::ivec3(0))) ||
            glm::any(glm::greaterThan(hi, geometry.dims)) ||
            glm::any(glm::lessThanEqual(hi, lo)))
            throw Error(name + ": brick outside the volume");
    }
};

/// The grid of `p` that `options` choose, read once per process and kept while the same
/// file (path, size, modification time) and grid are asked for: the bricks of a frame open
/// and check the file once.
std::shared_ptr<const OpenGrid> openGrid(const fs::path& p, const LoadOptions& options) {
    static std::mutex mutex;
    static std::shared_ptr<const OpenGrid> last;
    std::error_code ec;
    const auto size = fs::file_size(p, ec);
    const auto time = fs::last_write_time(p, ec).time_since_epoch().count();
    const std::string key = fs::absolute(p, ec).string() + '\n' + options.grid + '\n' +
                            std::to_string(size) + '\n' + std::to_string(time);
    const std::lock_guard<std::mutex> lock(mutex);
    if (last && last->key == key) return last;
    last.reset();  // the previous file's tree is freed before the next is read
    const VdbFile f(p);
    auto g = std::make_shared<OpenGrid>();
    const Chosen c = choose(f, options, &g->grid);
    g->key = key;
    g->name = f.name;
    g->origin = c.box.min();
    g->geometry = c.geometry;
    last = g;
    return g;
}

}  // namespace

bool openVdbAvailable() { return true; }

std::vector<VdbGridInfo> listVdbGrids(const std::string& path) {
    const VdbFile f(path);
    std::vector<VdbGridInfo> out;
    for (const auto& meta : *f.grids) {
        VdbGridInfo info;
        info.name = meta->getName();
        info.valueType = meta->valueType();
        const openvdb::GridBase::ConstPtr g = meta;
        openvdb::CoordBBox box;
        if (scalarGrid(*g)) {
            box = g->evalActiveVoxelBoundingBox();
            info.activeVoxels = g->activeVoxelCount();
            info.background = background(*g);
        } else {
            fileBBox(*meta, box);
            if (const auto n = meta->getMetadata<openvdb::Int64Metadata>(
                    openvdb::GridBase::META_FILE_VOXEL_COUNT))
                info.activeVoxels = std::uint64_t(n->value());
        }
        if (!box.empty()) {
            info.bboxMin = glm::ivec3(box.min().x(), box.min().y(), box.min().z());
            info.bboxMax = glm::ivec3(box.max().x(), box.max().y(), box.max().z());
        }
        const openvdb::Vec3d vs = meta->transform().voxelSize();
        info.voxelSize = glm::dvec3(vs.x(), vs.y(), vs.z());
        glm::dvec3 s, t;
        axisAligned(*meta, f.name, s, t, &info.axisAligned);
        out.push_back(std::move(info));
    }
    return out;
}

namespace detail {

Volume loadVdb(const fs::path& p, const LoadOptions& options) {
    const VdbFile f(p);
    openvdb::GridBase::Ptr grid;
    const Chosen c = choose(f, options, &grid);
    return readBox(f.name, *grid, c.geometry, c.box.min(), glm::ivec3(0), c.geometry.dims);
}

Volume vdbGeometry(const fs::path& p, const LoadOptions& options) {
    return openGrid(p, options)->geometry;
}

Volume loadVdbBrick(const fs::path& p, const LoadOptions& options, const glm::ivec3& lo,
                    const glm::ivec3& hi) {
    const std::shared_ptr<const OpenGrid> g = openGrid(p, options);
    g->check(lo, hi);
    return readBox(g->name, *g->grid, g->geometry, g->origin, lo, hi);
}

glm::dvec2 vdbValueRange(const fs::path& p, const LoadOptions& options) {
    const std::shared_ptr<const OpenGrid> g = openGrid(p, options);
    glm::dvec2 range(INFINITY, -INFINITY);
    if (g->grid->activeVoxelCount() < g->geometry.voxelCount())  // some samples are b
        range = glm::dvec2(g->geometry.background);
    const auto widen = [&](const auto& grid) {
        const auto m = openvdb::tools::minMax(grid.tree());
        range = glm::dvec2(std::min(range.x, double(float(m.min()))),
                           std::max(range.y, double(float(m.max()))));
    };
    if (g->grid->isType<openvdb::FloatGrid>())
        widen(static_cast<const openvdb::FloatGrid&>(*g->grid));
    else
        widen(static_cast<const openvdb::DoubleGrid&>(*g->grid));
    return range;
}

bool vdbBoxHoldsOnlyBackground(const fs::path& p, const LoadOptions& options,
                               const glm::ivec3& lo, const glm::ivec3& hi) {
    const std::shared_ptr<const OpenGrid> g = openGrid(p, options);
    g->check(lo, hi);
    const openvdb::CoordBBox box(g->origin + openvdb::Coord(lo.x, lo.y, lo.z),
                                 g->origin + openvdb::Coord(hi.x - 1, hi.y - 1, hi.z - 1));
    const double b = g->geometry.background;
    if (g->grid->isType<openvdb::FloatGrid>())
        return !holdsOtherThan(static_cast<const openvdb::FloatGrid&>(*g->grid), box, b);
    return !holdsOtherThan(static_cast<const openvdb::DoubleGrid&>(*g->grid), box, b);
}

}  // namespace detail
}  // namespace splat

#endif
