#pragma once
// `splat render --bricks K`, and `splat render` under `mpirun -np P` (K = P unless given):
// sort-last bricked rendering (splat/bricks.h, docs/parallel.md).
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "render_options.h"
#include "splat/bricks.h"
#include "volume_options.h"

namespace splat::cli {

/// The geometry of the volume of `volume` (no samples; background as --background-value
/// says, else from the outer faces), with a warning when its samples are not read by brick
/// (`alone`: whether they are; given, no warning).
Volume brickedGeometry(const VolumeArgs& volume, bool* alone = nullptr);

/// Loads brick's samples (with its ghost layers) of the volume of `volume`.
std::function<Volume(const Brick&)> brickLoader(const VolumeArgs& volume);

/// Which bricks of the volume of `volume` hold only its background value b, known without
/// loading them (brickHoldsOnlyBackground: an OpenVDB grid's empty boxes).
std::function<bool(const Brick&)> brickEmptiness(const VolumeArgs& volume);

/// The bricks `splat render` on one process chooses by itself (0: the whole volume at once),
/// docs/parallel.md "Larger than memory": an OpenVDB grid is rendered in bricks of about
/// kSparseBrickSamples samples (at most 4096 bricks) when a volume of b draws one constant
/// image (emptyBrickImage): its empty bricks are then neither loaded nor rendered, so cost
/// follows the active voxels; a volume read by brick that does not fit the budget (defaultRankBytes)
/// in as many as it needs, said on stderr. Volumes loaded whole, and settings that bricks
/// refuse (edge enhancement, labels, level of detail; the image-aligned splatter's clipping
/// and perspective views) and post-classified dvr (a transfer function that gives b opacity
/// fills the box with a haze that bricks do not draw as one volume) render whole.
int automaticBricks(const VolumeArgs& volume, const RenderSettings& settings);

/// The samples of a brick of an OpenVDB grid rendered by automaticBricks.
constexpr std::size_t kSparseBrickSamples = std::size_t(64) * 64 * 64;

/// K from the budget per process (`rankBytes`, 0: defaultRankBytes) by chooseBricks, said on
/// rank 0 unless `quiet`; `wholeFits`: whether the whole volume fits one process.
/// `extraSampleBytes`: bytes per sample held beyond the samples and one splat list
/// (BrickBudget; popping: poppingSampleBytes).
int bricksFromBudget(const Volume& geometry, const RenderSettings& settings, int ranks,
                     std::uint64_t rankBytes, bool* wholeFits = nullptr, bool quiet = false,
                     double extraSampleBytes = 0);

/// The options of a sequence in bricks (`rotate`, `popping`; docs/parallel.md).
struct SequenceBrickArgs {
    int bricks = 0;         ///< --bricks K (0: off, or chosen from the budget under mpirun)
    double rankMemory = 0;  ///< --rank-memory MiB; 0: the default under mpirun
    std::string composite = "exact";    ///< --brick-composite exact|fast
    std::string compositor = "direct";  ///< --compositor (parallel.h)
};
/// Registers --bricks, --rank-memory, --brick-composite and --compositor from the option
/// table's entries of `sets` (kRotateOptions, kPoppingOptions: their help says what the
/// bricks render).
void addSequenceBrickOptions(CLI::App& cmd, SequenceBrickArgs& b, unsigned sets);
/// Their values' checks (UsageError), and the warning for --compositor without mpirun.
void checkSequenceBrickOptions(const CLI::App& cmd, const SequenceBrickArgs& b);

/// Whether a sequence (`rotate`, `popping`) renders in bricks, docs/parallel.md:
/// when asked (`bricks` > 0), or when the budget per process (`rankMiB`, 0: defaultRankBytes)
/// says the volume does not fit one (mpirun, --rank-memory; `extraSampleBytes` as in
/// bricksFromBudget); else frames in parallel (`bricks` 0). Every rank decides alike (the same
/// geometry). `settings` gets the geometry's free camera target when it was read.
struct SequenceBricks {
    int bricks = 0;
    std::optional<Volume> geometry;  ///< read when bricks were asked for or under mpirun
    bool alone = true;               ///< whether the samples are read by brick
};
SequenceBricks chooseSequenceBricks(const VolumeArgs& volume, RenderSettings& settings, int bricks,
                                    double rankMiB, double extraSampleBytes = 0);

/// What `splat popping` in bricks holds per sample beyond the samples and one splat list: one
/// Scene per renderer of `renderers` over the same samples — another splat list each (26
/// bytes per splat), the reference's field grid (20 bytes per sample: FieldGrid<4> and <1>),
/// and the image-aligned splatter's projected splats (measured: ~50 bytes per splat, 120 MB
/// for the 2.4 M splats of phantom:200) — with `splatShare` of the samples as splats.
double poppingSampleBytes(const std::vector<RendererKind>& renderers, double splatShare = 0.25);

/// Every process loads and renders its bricks, the group composites the frame, and rank 0
/// writes it to `output` and prints what the frame took. `bricks` 0: chosen from the budget
/// per process (`rankBytes`, 0: defaultRankBytes) by chooseBricks, printed on rank 0.
/// `compositor`: --compositor (parallel.h).
void renderBrickedToFile(const VolumeArgs& volume, const RenderArgs& render,
                         RenderSettings settings, int bricks, std::uint64_t rankBytes,
                         const std::string& output,
                         BrickComposite composite = BrickComposite::Exact,
                         const std::string& compositor = "direct");

/// One line per rank of a bricked sequence (rotate, popping): bricks, samples loaded, load
/// and scene time (`scene` names how the scene time counts, e.g. " once"), render, composite
/// and bytes exchanged over `frames` frames.
void printRankStats(const std::vector<BrickStats>& ranks, std::size_t frames, const char* scene);

}  // namespace splat::cli
