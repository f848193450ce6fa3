// Sort-last compositing, splat's direct-send against IceT (docs/parallel.md "Memory,
// scaling and a model"). Under `mpirun -np P` every rank holds one partial RGBA float image of W x
// H with premultiplied colour and all ranks share one visibility order. The partial images are
// either synthetic (a soft disc, different per rank, transparent outside it, as a brick's
// projection is) or, with --volume SPEC, the real partial images of splat's bricked render: rank 0
// renders SPEC in P bricks (renderBricked, axis splatter, transfer function gray-ramp, azimuth 30,
// elevation 15), keeps the partial images and the k-d visibility order that renderBricked hands to
// its BrickGroup, and sends brick b's image to rank b. The images are composited
//   (a) by splat::mpi's BrickGroup::composite (the code `splat render --bricks` runs),
//       called as it is, one brick per rank: direct-send (MPI_Alltoallv of the row spans of
//       the strips, each strip composited front to back, MPI_Gatherv of the spans to rank 0)
//       and the IceT compositor behind the same seam (--compositor icet);
//   (b) by IceT (ParaView 5.11's copy, libvtkIceTCore/libvtkIceTMPI): icetCompositeImage
//       with ICET_COMPOSITE_MODE_BLEND, ICET_ORDERED_COMPOSITE and icetCompositeOrder,
//       a float RGBA colour buffer, no depth, one tile displayed on rank 0, for each
//       single-image strategy (binary-swap, radix-k, tree, ...) under
//       ICET_STRATEGY_SEQUENTIAL, and ICET_STRATEGY_DIRECT / REDUCE.
// Both results are compared on rank 0 (max abs over the RGBA floats), and each is timed:
// per repetition MPI_Barrier, then the call; the time is the slowest rank's (MPI_MAX), the
// figure the median over the repetitions. Bytes sent per rank: splat's direct-send from its
// message sizes (sent only, splat::mpi::lastBytesSent, the same definition as IceT's), IceT's
// from ICET_BYTES_SENT.
//
//   mpirun -np P icet_compare [--size N] [--reps R] [--coverage F] [--volume SPEC]
// prints one JSON object per line on rank 0: {"P", "size", "method", "median_ms",
// "bytes_sent_max", "bytes_sent_mean", "max_abs"}.
#include <IceT.h>
#include <IceTMPI.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "splat/bricks.h"
#include "splat/image.h"
#include "splat/mpi/brick_group.h"
#include "splat/mpi/session.h"
#include "splat/settings.h"
#include "splat/transfer.h"
#include "splat/volume_io.h"

namespace {

/// Rank r's partial image: a disc of radius `coverage`/2 of the image, its centre on a
/// circle around the image centre at angle 2 pi r / P, opacity 0.6 in its middle falling
/// to 0 at its rim, colour premultiplied. Outside the disc: (0, 0, 0, 0).
splat::Image partialImage(int rank, int ranks, int n, float coverage) {
    splat::Image im(n, n);
    const float angle = 6.2831853f * float(rank) / float(ranks);
    const float cx = 0.5f + 0.2f * std::cos(angle), cy = 0.5f + 0.2f * std::sin(angle);
    const float radius = 0.5f * coverage;
    const glm::vec3 colour(0.3f + 0.7f * float(rank % 3 == 0), 0.3f + 0.7f * float(rank % 3 == 1),
                           0.3f + 0.7f * float(rank % 3 == 2));
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const float dx = (float(x) + 0.5f) / float(n) - cx;
            const float dy = (float(y) + 0.5f) / float(n) - cy;
            const float r = std::sqrt(dx * dx + dy * dy) / radius;
            if (r >= 1.0f) continue;
            const float a = 0.6f * (1.0f - r * r);
            im.at(x, y) = glm::vec4(colour * a, a);
        }
    return im;
}

/// The visibility order shared by every rank: a permutation that is neither the rank order
/// nor its reverse (ranks 1, 3, 5, ... first, then 0, 2, 4, ...).
std::vector<int> frontToBack(int ranks) {
    std::vector<int> order;
    for (int r = 1; r < ranks; r += 2) order.push_back(r);
    for (int r = 0; r < ranks; r += 2) order.push_back(r);
    return order;
}

/// One process holding every brick that keeps the partial images and the order renderBricked
/// composites them in.
class KeepingGroup : public splat::LocalBrickGroup {
  public:
    std::vector<std::pair<int, splat::Image>> partials;
    std::vector<int> order;
    splat::Image composite(std::vector<std::pair<int, splat::Image>>& p,
                           const std::vector<int>& frontToBack, int width, int height,
                           splat::RenderMode mode, const glm::vec4& background,
                           std::uint64_t* bytes) override {
        partials = p;
        order = frontToBack;
        return LocalBrickGroup::composite(p, frontToBack, width, height, mode, background, bytes);
    }
};

/// Rank 0 renders `spec` in `ranks` bricks at n x n; every rank gets its brick's partial
/// image, every rank the visibility order.
splat::Image brickImage(const std::string& spec, int rank, int ranks, int n,
                        std::vector<int>& order) {
    splat::Image mine(n, n);
    order.assign(std::size_t(ranks), 0);
    if (rank == 0) {
        splat::RenderSettings s;
        s.renderer = splat::RendererKind::Axis;
        s.mode = splat::RenderMode::Dvr;
        s.camera.width = s.camera.height = n;
        s.camera.azimuthDeg = 30;
        s.camera.elevationDeg = 15;
        s.transfer = splat::TransferFunction::preset("gray-ramp");
        s.quality.earlyTermination = 0;
        bool alone = false;
        const splat::Volume geometry = splat::volumeGeometry(spec, {}, &alone);
        KeepingGroup group;
        splat::renderBricked(
            geometry,
            [&](const splat::Brick& b) {
                return splat::loadVolumeBrick(spec, {}, b.loadLo, b.loadHi);
            },
            s, ranks, group, nullptr);
        order = group.order;
        for (auto& [b, image] : group.partials) {
            if (b == 0)
                mine = image;
            else
                MPI_Send(&image.pixels[0].x, 4 * n * n, MPI_FLOAT, b, 7, MPI_COMM_WORLD);
        }
    } else {
        MPI_Recv(&mine.pixels[0].x, 4 * n * n, MPI_FLOAT, 0, 7, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    }
    MPI_Bcast(order.data(), ranks, MPI_INT, 0, MPI_COMM_WORLD);
    return mine;
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const std::size_t m = v.size() / 2;
    return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

struct Result {
    double medianMs = 0;
    double bytesMax = 0, bytesMean = 0;
    double maxAbs = 0;
};

/// Max abs difference between `got` (W H RGBA floats on rank 0) and `want`.
double maxAbs(const float* got, const splat::Image& want) {
    double m = 0;
    for (std::size_t i = 0; i < want.pixels.size(); ++i)
        for (int c = 0; c < 4; ++c)
            m = std::max(m, double(std::fabs(got[4 * i + c] - want.pixels[i][c])));
    return m;
}

void print(int ranks, int n, const std::string& method, const Result& r) {
    std::printf(
        "{\"P\": %d, \"size\": %d, \"method\": \"%s\", \"median_ms\": %.4f, "
        "\"bytes_sent_max\": %.0f, \"bytes_sent_mean\": %.0f, \"max_abs\": %.3g}\n",
        ranks, n, method.c_str(), r.medianMs, r.bytesMax, r.bytesMean, r.maxAbs);
    std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
    splat::mpi::Session session(&argc, &argv);
    int n = 256, reps = 15;
    float coverage = 0.7f;
    std::string volume;
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string a = argv[i];
        if (a == "--size")
            n = std::atoi(argv[i + 1]);
        else if (a == "--reps")
            reps = std::atoi(argv[i + 1]);
        else if (a == "--coverage")
            coverage = float(std::atof(argv[i + 1]));
        else if (a == "--volume")
            volume = argv[i + 1];
    }
    const int rank = session.rank(), ranks = session.size();
    std::vector<int> order = frontToBack(ranks);
    const splat::Image mine = volume.empty() ? partialImage(rank, ranks, n, coverage)
                                             : brickImage(volume, rank, ranks, n, order);
    const glm::vec4 transparent(0.0f);

    // The reference: every rank's partial image composited in one process, on rank 0.
    splat::Image reference;
    std::vector<splat::Image> all(rank == 0 ? std::size_t(ranks) : 0, splat::Image(n, n));
    if (rank == 0) all[0] = mine;
    for (int r = 1; r < ranks; ++r) {
        if (rank == r) MPI_Send(&mine.pixels[0].x, 4 * n * n, MPI_FLOAT, 0, 8, MPI_COMM_WORLD);
        if (rank == 0)
            MPI_Recv(&all[std::size_t(r)].pixels[0].x, 4 * n * n, MPI_FLOAT, r, 8, MPI_COMM_WORLD,
                     MPI_STATUS_IGNORE);
    }
    if (rank == 0) {
        std::vector<const splat::Image*> ordered;
        for (int r : order) ordered.push_back(&all[std::size_t(r)]);
        reference = splat::compositeBricks(ordered, splat::RenderMode::Dvr, transparent);
        all.clear();
    }

    auto timeIt = [&](auto&& prepare, auto&& call) {
        std::vector<double> ms;
        for (int k = 0; k < reps; ++k) {
            prepare();
            MPI_Barrier(MPI_COMM_WORLD);
            const double t0 = MPI_Wtime();
            call();
            double t = 1e3 * (MPI_Wtime() - t0), slowest = 0;
            MPI_Allreduce(&t, &slowest, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
            ms.push_back(slowest);
        }
        return median(ms);
    };
    auto bytesOver = [&](double mineBytes, Result& r) {
        double sum = 0, max = 0;
        MPI_Allreduce(&mineBytes, &sum, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
        MPI_Allreduce(&mineBytes, &max, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
        r.bytesMax = max;
        r.bytesMean = sum / ranks;
    };

    // (a) splat's compositors, through splat::mpi's BrickGroup (brick b on rank b), called as
    // `splat render --bricks` calls them: direct-send and, IceT's radix-k behind the same seam.
    const std::pair<const char*, splat::mpi::Compositor> compositors[] = {
        {"splat direct-send", splat::mpi::Compositor::Direct},
        {"splat --compositor icet", splat::mpi::Compositor::Icet}};
    for (const auto& [name, kind] : compositors) {
        auto group = splat::mpi::makeBrickGroup(session, kind);
        splat::Image out;
        Result r;
        std::vector<std::pair<int, splat::Image>> partials;
        double sent = 0;
        r.medianMs = timeIt(
            [&] {
                partials.clear();
                partials.emplace_back(rank, mine);  // composite() consumes its partials
            },
            [&] {
                out = group->composite(partials, order, n, n, splat::RenderMode::Dvr, transparent,
                                       nullptr);
                sent = double(splat::mpi::lastBytesSent(*group));
            });
        bytesOver(sent, r);
        if (rank == 0) r.maxAbs = maxAbs(&out.pixels[0].x, reference);
        if (rank == 0) print(ranks, n, name, r);
    }

    // (b) IceT.
    IceTCommunicator comm = icetCreateMPICommunicator(MPI_COMM_WORLD);
    IceTContext context = icetCreateContext(comm);
    icetDiagnostics(ICET_DIAG_ERRORS | ICET_DIAG_ALL_NODES);
    icetResetTiles();
    icetAddTile(0, 0, n, n, 0);
    icetSetColorFormat(ICET_IMAGE_COLOR_RGBA_FLOAT);
    icetSetDepthFormat(ICET_IMAGE_DEPTH_NONE);
    icetCompositeMode(ICET_COMPOSITE_MODE_BLEND);
    icetEnable(ICET_ORDERED_COMPOSITE);
    std::vector<IceTInt> icetOrder(order.begin(), order.end());
    icetCompositeOrder(icetOrder.data());
    const IceTInt viewport[4] = {0, 0, n, n};
    const IceTDouble identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    const IceTFloat background[4] = {0, 0, 0, 0};
    struct Variant {
        const char* name;
        IceTEnum strategy, single;
    };
    const Variant variants[] = {
        {"IceT sequential + binary-swap", ICET_STRATEGY_SEQUENTIAL,
         ICET_SINGLE_IMAGE_STRATEGY_BSWAP},
        {"IceT sequential + radix-k", ICET_STRATEGY_SEQUENTIAL, ICET_SINGLE_IMAGE_STRATEGY_RADIXK},
        {"IceT sequential + radix-kr", ICET_STRATEGY_SEQUENTIAL,
         ICET_SINGLE_IMAGE_STRATEGY_RADIXKR},
        {"IceT sequential + tree", ICET_STRATEGY_SEQUENTIAL, ICET_SINGLE_IMAGE_STRATEGY_TREE},
        {"IceT sequential + bswap-folding", ICET_STRATEGY_SEQUENTIAL,
         ICET_SINGLE_IMAGE_STRATEGY_BSWAP_FOLDING},
        {"IceT reduce + automatic", ICET_STRATEGY_REDUCE, ICET_SINGLE_IMAGE_STRATEGY_AUTOMATIC},
        {"IceT direct", ICET_STRATEGY_DIRECT, ICET_SINGLE_IMAGE_STRATEGY_AUTOMATIC},
    };
    for (const Variant& v : variants) {
        icetStrategy(v.strategy);
        icetSingleImageStrategy(v.single);
        IceTImage image;
        double bytes = 0;
        Result r;
        r.medianMs = timeIt([] {},
                            [&] {
                                image = icetCompositeImage(&mine.pixels[0].x, nullptr, viewport,
                                                           identity, identity, background);
                                IceTInt sent = 0;
                                icetGetIntegerv(ICET_BYTES_SENT, &sent);
                                bytes = double(sent);
                            });
        bytesOver(bytes, r);
        if (rank == 0) r.maxAbs = maxAbs(icetImageGetColorcf(image), reference);
        if (rank == 0) print(ranks, n, v.name, r);
    }
    icetDestroyContext(context);
    icetDestroyMPICommunicator(comm);
    return session.finish(0);
}
