// OpenVDB files as volumes (openvdb_file.h), and listVdbGrids for `splat info`.
#include "io/vdb/openvdb_file.h"

#include <string>
#include <vector>

#include "io/parse_in_child.h"
#include "io/volume_detail.h"
#include "splat/error.h"
#include "splat/sparse_files.h"

#if SPLAT_HAVE_OPENVDB
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

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

/// A file opened for reading (OpenVDB's errors become one splat::Error line).
struct VdbFile {
    std::string name;
    std::unique_ptr<openvdb::io::File> file;

    explicit VdbFile(const fs::path& p) : name(detail::displayName(p)) {
        static std::once_flag once;
        std::call_once(once, [] { openvdb::initialize(); });
        detail::regularFileSize(p);
        // OpenVDB can corrupt the heap or abort on a damaged tree (a byte changed in a leaf's
        // header): every float and double grid is read once in a child process first.
        detail::parseInChild(name, "OpenVDB", "OpenVDB", [&] {
            openvdb::io::File file(p.string());
            file.open(false);
            const openvdb::GridPtrVecPtr grids = file.readAllGridMetadata();
            for (const auto& g : *grids)
                if (scalarGrid(*g)) file.readGrid(g->getName());
        });
        guarded(name, [&] {
            file = std::make_unique<openvdb::io::File>(p.string());
            file->open(false);  // read grids whole when asked, no delayed loading
        });
    }
    ~VdbFile() {
        if (file && file->isOpen()) file->close();
    }
    template <typename F>
    auto guard(F&& f) const {
        return guarded(name, std::forward<F>(f));
    }
};

/// The grid LoadOptions::grid names (metadata only), or the default.
openvdb::GridBase::ConstPtr chooseGrid(const VdbFile& f, const std::string& wanted) {
    const openvdb::GridPtrVecPtr grids = f.guard([&] { return f.file->readAllGridMetadata(); });
    std::string names;
    for (const auto& g : *grids) names += (names.empty() ? "" : ", ") + g->getName();
    if (grids->empty()) throw Error(f.name + ": holds no grids");
    const auto byName = [&](const std::string& n) -> openvdb::GridBase::ConstPtr {
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

/// Fills `v` (the box [lo, lo + v.dims) in index space, already holding b) with the grid's
/// active values: voxels one by one, active tiles over their boxes.
template <typename GridT>
void fillActive(const GridT& grid, const openvdb::Coord& lo, Volume& v) {
    const openvdb::CoordBBox box(lo, lo + openvdb::Coord(v.dims.x - 1, v.dims.y - 1, v.dims.z - 1));
    for (auto it = grid.cbeginValueOn(); it; ++it) {
        if (it.isVoxelValue()) {
            const openvdb::Coord c = it.getCoord();
            if (box.isInside(c)) v.at(c.x() - lo.x(), c.y() - lo.y(), c.z() - lo.z()) = float(*it);
            continue;
        }
        openvdb::CoordBBox tile;
        it.getBoundingBox(tile);
        tile.intersect(box);
        if (tile.empty()) continue;
        for (int z = tile.min().z(); z <= tile.max().z(); ++z)
            for (int y = tile.min().y(); y <= tile.max().y(); ++y)
                for (int x = tile.min().x(); x <= tile.max().x(); ++x)
                    v.at(x - lo.x(), y - lo.y(), z - lo.z()) = float(*it);
    }
}

/// The box [lo, hi) of the volume whose index (0,0,0) is voxel `origin` of `grid`.
Volume readBox(const VdbFile& f, const openvdb::GridBase& grid, const Volume& g,
               const openvdb::Coord& origin, const glm::ivec3& lo, const glm::ivec3& hi) {
    Volume v = makeVolume(hi - lo, g.spacing, f.name);
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

/// The chosen grid's geometry; `grid` receives the whole grid when it had to be read.
Chosen choose(const VdbFile& f, const LoadOptions& options, openvdb::GridBase::Ptr* grid) {
    Chosen c;
    c.meta = chooseGrid(f, options.grid);
    std::uint64_t active = 0;
    if (const auto n =
            c.meta->getMetadata<openvdb::Int64Metadata>(openvdb::GridBase::META_FILE_VOXEL_COUNT))
        active = std::uint64_t(n->value());
    if (grid || !fileBBox(*c.meta, c.box)) {
        openvdb::GridBase::Ptr whole = f.guard([&] { return f.file->readGrid(c.meta->getName()); });
        c.box = whole->evalActiveVoxelBoundingBox();
        active = whole->activeVoxelCount();
        if (grid) *grid = whole;
        c.meta = whole;
    }
    c.geometry = geometry(f.name, *c.meta, c.box, active);
    if (!grid) {
        // The metadata hold no tree, and so no background: read the grid clipped to one
        // voxel's world box (the root node, which holds the background, and a leaf at most).
        const glm::dvec3 w = c.geometry.world(glm::dvec3(0.0));
        const openvdb::BBoxd one(openvdb::Vec3d(w.x, w.y, w.z), openvdb::Vec3d(w.x, w.y, w.z));
        c.meta = f.guard([&] { return f.file->readGrid(c.meta->getName(), one); });
    }
    c.geometry.background = float(background(*c.meta));
    c.geometry.backgroundSource = "OpenVDB grid background";
    return c;
}

}  // namespace

bool openVdbAvailable() { return true; }

std::vector<VdbGridInfo> listVdbGrids(const std::string& path) {
    const VdbFile f(path);
    const openvdb::GridPtrVecPtr grids = f.guard([&] { return f.file->readAllGridMetadata(); });
    std::vector<VdbGridInfo> out;
    for (const auto& meta : *grids) {
        VdbGridInfo info;
        info.name = meta->getName();
        info.valueType = meta->valueType();
        openvdb::GridBase::ConstPtr g = meta;
        if (scalarGrid(*meta)) g = f.guard([&] { return f.file->readGrid(info.name); });
        openvdb::CoordBBox box;
        if (g != meta) {
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
    return readBox(f, *grid, c.geometry, c.box.min(), glm::ivec3(0), c.geometry.dims);
}

Volume vdbGeometry(const fs::path& p, const LoadOptions& options) {
    const VdbFile f(p);
    return choose(f, options, nullptr).geometry;
}

Volume loadVdbBrick(const fs::path& p, const LoadOptions& options, const glm::ivec3& lo,
                    const glm::ivec3& hi) {
    const VdbFile f(p);
    const Chosen c = choose(f, options, nullptr);
    if (glm::any(glm::lessThan(lo, glm::ivec3(0))) ||
        glm::any(glm::greaterThan(hi, c.geometry.dims)) || glm::any(glm::lessThanEqual(hi, lo)))
        throw Error(f.name + ": brick outside the volume");
    // The world box of the brick's voxel centres, half a voxel wider: only the tree's nodes
    // that intersect it are read.
    const glm::dvec3 w0 = c.geometry.world(glm::dvec3(lo) - 0.5);
    const glm::dvec3 w1 = c.geometry.world(glm::dvec3(hi) - 0.5);
    const openvdb::BBoxd world(openvdb::Vec3d(w0.x, w0.y, w0.z), openvdb::Vec3d(w1.x, w1.y, w1.z));
    const openvdb::GridBase::Ptr part =
        f.guard([&] { return f.file->readGrid(c.meta->getName(), world); });
    return readBox(f, *part, c.geometry, c.box.min(), lo, hi);
}

}  // namespace detail
}  // namespace splat

#endif
