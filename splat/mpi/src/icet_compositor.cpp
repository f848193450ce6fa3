// The IceT compositor (icet_compositor.h); compiled only with SPLAT_ICET.
#include "icet_compositor.h"

#include <IceT.h>
#include <IceTMPI.h>
#include <mpi.h>

#include <algorithm>
#include <climits>
#include <cstring>
#include <numeric>
#include <string>

#include "sparse_rows.h"
#include "splat/bricks.h"
#include "splat/error.h"

namespace splat::mpi {

namespace {

/// The ranks in the order their bricks are seen, front first (ranks without a brick last);
/// empty when a rank's bricks are not consecutive in `frontToBack`.
std::vector<int> rankOrder(const std::vector<int>& frontToBack, int ranks) {
    std::vector<int> first(std::size_t(ranks), INT_MAX), last(std::size_t(ranks), -1),
        count(std::size_t(ranks), 0);
    for (int at = 0; at < int(frontToBack.size()); ++at) {
        const std::size_t r = std::size_t(frontToBack[std::size_t(at)] % ranks);
        first[r] = std::min(first[r], at);
        last[r] = std::max(last[r], at);
        ++count[r];
    }
    for (int r = 0; r < ranks; ++r)
        if (count[std::size_t(r)] &&
            last[std::size_t(r)] - first[std::size_t(r)] + 1 != count[std::size_t(r)])
            return {};
    std::vector<int> order(static_cast<std::size_t>(ranks));
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(),
                     [&](int a, int b) { return first[std::size_t(a)] < first[std::size_t(b)]; });
    return order;
}

/// The smallest viewport (x, y, width, height; IceT's y is our row) holding every pixel of
/// `image` that is not transparent; one transparent pixel when there is none.
void validViewport(const Image& image, IceTInt viewport[4]) {
    int x0 = image.width, x1 = 0, y0 = image.height, y1 = 0;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x)
            if (!transparent(image.at(x, y))) {
                x0 = std::min(x0, x), x1 = std::max(x1, x + 1);
                y0 = std::min(y0, y), y1 = std::max(y1, y + 1);
            }
    if (x1 <= x0) x0 = y0 = 0, x1 = y1 = 1;
    viewport[0] = x0, viewport[1] = y0, viewport[2] = x1 - x0, viewport[3] = y1 - y0;
}

void checkIcet(const char* what) {
    if (const IceTEnum e = icetGetError(); e != ICET_NO_ERROR) {
        char code[16];
        std::snprintf(code, sizeof code, "0x%X", unsigned(e));
        throw Error(std::string("IceT: ") + what + " failed (error " + code + ")");
    }
}

}  // namespace

bool icetComposites(const std::vector<int>& frontToBack, RenderMode mode, int ranks) {
    return (mode == RenderMode::Dvr || mode == RenderMode::Iso) &&
           !rankOrder(frontToBack, ranks).empty();
}

IcetCompositor::IcetCompositor() {
    communicator_ = icetCreateMPICommunicator(MPI_COMM_WORLD);
    context_ = icetCreateContext(communicator_);
    icetDiagnostics(ICET_DIAG_ERRORS | ICET_DIAG_ALL_NODES);
    icetSetColorFormat(ICET_IMAGE_COLOR_RGBA_FLOAT);
    icetSetDepthFormat(ICET_IMAGE_DEPTH_NONE);
    icetCompositeMode(ICET_COMPOSITE_MODE_BLEND);
    icetEnable(ICET_ORDERED_COMPOSITE);
    // Radix-k: the single-image strategy of IceT's large-scale results (docs/parallel.md
    // "Direct-send beside IceT").
    icetStrategy(ICET_STRATEGY_SEQUENTIAL);
    icetSingleImageStrategy(ICET_SINGLE_IMAGE_STRATEGY_RADIXK);
    checkIcet("setting up its context");
}

IcetCompositor::~IcetCompositor() {
    icetDestroyContext(context_);
    icetDestroyMPICommunicator(communicator_);
}

Image IcetCompositor::composite(const std::vector<std::pair<int, Image>>& partials,
                                const std::vector<int>& frontToBack, int width, int height,
                                RenderMode mode, std::uint64_t* sent) {
    int rank = 0, ranks = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    // My bricks are consecutive in the order: blend them first, front to back.
    std::vector<const Image*> mine;
    for (int b : frontToBack)
        for (const auto& [brick, image] : partials)
            if (brick == b) mine.push_back(&image);
    const Image local = mine.empty() ? Image(width, height) : compositePieces(mine, mode);
    icetSetContext(context_);
    icetResetTiles();
    icetAddTile(0, 0, width, height, 0);
    const std::vector<int> order = rankOrder(frontToBack, ranks);
    std::vector<IceTInt> icetOrder(order.begin(), order.end());
    icetCompositeOrder(icetOrder.data());
    IceTInt viewport[4];
    validViewport(local, viewport);
    const IceTDouble identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    const IceTFloat transparentBackground[4] = {0, 0, 0, 0};
    const IceTImage image = icetCompositeImage(&local.pixels[0].x, nullptr, viewport, identity,
                                               identity, transparentBackground);
    checkIcet("compositing");
    IceTInt bytes = 0;
    icetGetIntegerv(ICET_BYTES_SENT, &bytes);
    *sent += std::uint64_t(bytes);
    if (rank != 0) return Image();
    Image out(width, height);
    std::memcpy(&out.pixels[0].x, icetImageGetColorcf(image),
                out.pixels.size() * sizeof(glm::vec4));
    return out;
}

}  // namespace splat::mpi
