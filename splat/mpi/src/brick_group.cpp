// Sort-last bricks over MPI (splat/mpi/brick_group.h).
#include "splat/mpi/brick_group.h"

#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <climits>
#include <cstring>
#include <thread>
#include <type_traits>

#include "sparse_rows.h"
#include "splat/error.h"
#include "splat/slab_sheets.h"
#if SPLAT_MPI_HAVE_ICET
#include "icet_compositor.h"
#endif

namespace splat::mpi {

namespace {

constexpr int kMessage = 512;  // characters of an error message sent in agree()

/// Rows [first, end) of the image strip owned by rank r of p.
int stripBegin(int height, int r, int p) { return int(std::int64_t(height) * r / p); }

class MpiBrickGroup : public BrickGroup {
  public:
    explicit MpiBrickGroup(Session& s) : s_(s) {}
    int rank() const override { return s_.rank(); }
    int size() const override { return s_.size(); }

    void agree(const std::string& error) override {
        int ok = error.empty() ? 1 : 0, all = 0;
        MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
        if (all) return;
        // Every rank learns the first failed rank's message.
        std::vector<char> mine(kMessage, '\0'), every(std::size_t(kMessage) * size());
        std::strncpy(mine.data(), error.c_str(), kMessage - 1);
        MPI_Allgather(mine.data(), kMessage, MPI_CHAR, every.data(), kMessage, MPI_CHAR,
                      MPI_COMM_WORLD);
        for (int r = 0; r < size(); ++r) {
            const char* m = every.data() + std::size_t(r) * kMessage;
            if (*m)
                throw Error("rank " + std::to_string(r) + " of " + std::to_string(size()) + ": " +
                            std::string(m, strnlen(m, kMessage)));
        }
        throw Error("a rank failed");
    }

    void range(float& lo, float& hi) override {
        float in[2] = {lo, -hi}, out[2];
        MPI_Allreduce(in, out, 2, MPI_FLOAT, MPI_MIN, MPI_COMM_WORLD);
        lo = out[0];
        hi = -out[1];
    }

    Image composite(std::vector<std::pair<int, Image>>& partials,
                    const std::vector<int>& frontToBack, int width, int height, RenderMode mode,
                    const glm::vec4& background, std::uint64_t* bytes) override {
        std::uint64_t sent = 0, received = 0;
        Image out;
#if SPLAT_MPI_HAVE_ICET
        if (icet_ && icetComposites(frontToBack, mode, size()))
            out = icet_->composite(partials, frontToBack, width, height, mode, &sent);
        else
#endif
            out = directSend(partials, frontToBack, width, height, mode, &sent, &received);
        partials.clear();  // the partial images are no longer needed
        if (rank() == 0) blendBackground(out, mode, background);
        lastSent_ = sent;
        if (bytes) *bytes += sent + received;
        return out;
    }

    std::uint64_t lastSent() const { return lastSent_; }

    std::vector<BrickStats> gather(const BrickStats& mine) override {
        static_assert(std::is_trivially_copyable_v<BrickStats>);
        std::vector<BrickStats> all(rank() == 0 ? std::size_t(size()) : 0);
        MPI_Gather(&mine, int(sizeof mine), MPI_BYTE, all.data(), int(sizeof mine), MPI_BYTE, 0,
                   MPI_COMM_WORLD);
        return all;
    }

    // Sparse direct exchange: every process sends the owner of each tile only the blocks it
    // wrote (a block whose rectangle is empty holds zeros), with their index and rectangle;
    // the owner adds them to its own. A brick writes only the tiles its footprint covers and
    // the slabs its depth range crosses, so this moves a fraction of the dense sheets an
    // MPI_Reduce_scatter would.
    void reduceSlabs(std::vector<float>& blocks, std::vector<int>& rects,
                     const std::vector<int>& tileStart, std::size_t tileFloats,
                     std::size_t tileInts, std::uint64_t* bytes) override {
        const int p = size(), me = rank();
        const std::size_t perTile = tileInts / 4, B = perTile ? tileFloats / perTile : 0;
        constexpr int kHead = 5;  // block index in the owner's part, then its rectangle
        std::vector<int> heads, headCount(p, 0), headOff(p, 0), floatCount(p, 0), floatOff(p, 0);
        std::vector<float> data;
        for (int d = 0; d < p; ++d) {
            headOff[d] = int(heads.size());
            floatOff[d] = int(data.size());
            if (d == me) continue;
            const std::size_t q0 = std::size_t(tileStart[d]) * perTile,
                              q1 = std::size_t(tileStart[d + 1]) * perTile;
            for (std::size_t q = q0; q < q1; ++q) {
                if (rects[4 * q] == kNoRect) continue;
                heads.push_back(int(q - q0));
                heads.insert(heads.end(), &rects[4 * q], &rects[4 * q] + 4);
                data.insert(data.end(), &blocks[q * B], &blocks[q * B] + B);
            }
            if (data.size() > std::size_t(INT_MAX))
                throw Error("exact brick sheets: a slab group exceeds MPI's count");
            headCount[d] = int(heads.size()) - headOff[d];
            floatCount[d] = int(data.size()) - floatOff[d];
        }
        std::vector<int> recvHeads(p), recvHeadOff(p), recvFloats(p), recvFloatOff(p);
        MPI_Alltoall(headCount.data(), 1, MPI_INT, recvHeads.data(), 1, MPI_INT, MPI_COMM_WORLD);
        std::size_t nh = 0, nf = 0;
        for (int q = 0; q < p; ++q) {
            recvHeadOff[q] = int(nh);
            recvFloatOff[q] = int(nf);
            recvFloats[q] = recvHeads[q] / kHead * int(B);
            nh += std::size_t(recvHeads[q]);
            nf += std::size_t(recvFloats[q]);
        }
        std::vector<int> inHeads(nh);
        std::vector<float> in(nf);
        MPI_Alltoallv(heads.data(), headCount.data(), headOff.data(), MPI_INT, inHeads.data(),
                      recvHeads.data(), recvHeadOff.data(), MPI_INT, MPI_COMM_WORLD);
        MPI_Alltoallv(data.data(), floatCount.data(), floatOff.data(), MPI_FLOAT, in.data(),
                      recvFloats.data(), recvFloatOff.data(), MPI_FLOAT, MPI_COMM_WORLD);
        // My tiles to the front, then every other process's blocks added in rank order.
        const std::size_t mine0 = std::size_t(tileStart[me]) * perTile,
                          mine1 = std::size_t(tileStart[me + 1]) * perTile;
        if (mine0 > 0) {
            std::copy(blocks.begin() + std::ptrdiff_t(mine0 * B),
                      blocks.begin() + std::ptrdiff_t(mine1 * B), blocks.begin());
            std::copy(rects.begin() + std::ptrdiff_t(4 * mine0),
                      rects.begin() + std::ptrdiff_t(4 * mine1), rects.begin());
        }
        for (std::size_t h = 0, f = 0; h < nh; h += kHead, f += B) {
            const std::size_t q = std::size_t(inHeads[h]);
            float* to = &blocks[q * B];
            for (std::size_t i = 0; i < B; ++i) to[i] += in[f + i];
            for (int c = 0; c < 4; ++c)
                rects[4 * q + c] = std::min(rects[4 * q + c], inHeads[h + 1 + c]);
        }
        if (bytes) *bytes += 4ull * (heads.size() + data.size() + nh + nf);
    }

    Image sumImages(const Image& image, std::uint64_t* bytes) override {
        Image out = rank() == 0 ? Image(image.width, image.height) : Image();
        const int n = int(image.pixels.size() * 4);
        MPI_Reduce(&image.pixels[0].x, rank() == 0 ? &out.pixels[0].x : nullptr, n, MPI_FLOAT,
                   MPI_SUM, 0, MPI_COMM_WORLD);
        if (bytes)
            *bytes += 4ull * std::uint64_t(n) * (rank() == 0 ? std::uint64_t(size() - 1) : 1);
        return out;
    }

    void broadcast(std::vector<unsigned char>& bytes) override {
        // The size first, without spinning: a rank waiting for rank 0 (which may work alone
        // meanwhile, as popping's analysis does between the frames it asks for) sleeps
        // between tests, since a blocking broadcast polls a core in OpenMPI.
        unsigned long long n = bytes.size();
        MPI_Request request;
        MPI_Ibcast(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, MPI_COMM_WORLD, &request);
        for (int done = 0; !done;) {
            MPI_Test(&request, &done, MPI_STATUS_IGNORE);
            if (!done) std::this_thread::sleep_for(std::chrono::microseconds(200));
        }
        bytes.resize(std::size_t(n));
        if (n) MPI_Bcast(bytes.data(), int(n), MPI_UNSIGNED_CHAR, 0, MPI_COMM_WORLD);
    }

  private:
    /// Sparse direct-send (brick_group.h): the frame on rank 0 without its background.
    Image directSend(const std::vector<std::pair<int, Image>>& partials,
                     const std::vector<int>& frontToBack, int width, int height, RenderMode mode,
                     std::uint64_t* sent, std::uint64_t* received);

    Session& s_;
    std::uint64_t lastSent_ = 0;
#if SPLAT_MPI_HAVE_ICET
    std::unique_ptr<IcetCompositor> icet_;

  public:
    void useIcet() { icet_ = std::make_unique<IcetCompositor>(); }
#endif
};

Image MpiBrickGroup::directSend(const std::vector<std::pair<int, Image>>& partials,
                                const std::vector<int>& frontToBack, int width, int height,
                                RenderMode mode, std::uint64_t* sent, std::uint64_t* received) {
    const int p = size(), me = rank();
    const int bricks = int(frontToBack.size());
    // My bricks in increasing index, the order every receiver expects them in.
    std::vector<const std::pair<int, Image>*> mine;
    for (const auto& partial : partials) mine.push_back(&partial);
    std::sort(mine.begin(), mine.end(),
              [](const auto* a, const auto* b) { return a->first < b->first; });
    // Send: for each other rank, its strip of each of my partials, row spans only.
    std::vector<int> sendCounts(p, 0), sendOffsets(p, 0), recvCounts(p, 0), recvOffsets(p, 0);
    std::vector<float> send;
    for (int d = 0; d < p; ++d) {
        sendOffsets[d] = int(send.size());
        if (d == me) continue;
        for (const auto* partial : mine)
            packRows(partial->second, stripBegin(height, d, p), stripBegin(height, d + 1, p), send);
        if (send.size() > std::size_t(INT_MAX))
            throw Error("bricks: a composite exceeds MPI's count (" + std::to_string(width) + "x" +
                        std::to_string(height) + " on " + std::to_string(p) + " ranks)");
        sendCounts[d] = int(send.size()) - sendOffsets[d];
    }
    MPI_Alltoall(sendCounts.data(), 1, MPI_INT, recvCounts.data(), 1, MPI_INT, MPI_COMM_WORLD);
    std::size_t total = 0;
    for (int q = 0; q < p; ++q) {
        recvOffsets[q] = int(total);
        total += std::size_t(recvCounts[q]);
    }
    if (total > std::size_t(INT_MAX)) throw Error("bricks: a composite exceeds MPI's count");
    std::vector<float> recv(total);
    MPI_Alltoallv(send.data(), sendCounts.data(), sendOffsets.data(), MPI_FLOAT, recv.data(),
                  recvCounts.data(), recvOffsets.data(), MPI_FLOAT, MPI_COMM_WORLD);
    for (int q = 0; q < p; ++q)
        if (q != me) *sent += 4ull * std::uint64_t(sendCounts[q]);
    *received += 4ull * std::uint64_t(total);
    send = {};
    // My strip of every brick: mine copied, the others' unpacked (transparent elsewhere).
    const int m0 = stripBegin(height, me, p), rows = stripBegin(height, me + 1, p) - m0;
    const std::size_t stripPixels = std::size_t(rows) * std::size_t(width);
    std::vector<Image> strips(static_cast<std::size_t>(bricks));
    for (const auto* partial : mine) {
        Image& strip = strips[std::size_t(partial->first)];
        strip = Image(width, rows);
        std::copy_n(partial->second.pixels.begin() + std::ptrdiff_t(std::size_t(m0) * width),
                    stripPixels, strip.pixels.begin());
    }
    for (int q = 0; q < p; ++q) {
        if (q == me) continue;
        std::size_t at = std::size_t(recvOffsets[q]);
        const std::size_t end = at + std::size_t(recvCounts[q]);
        for (int b = q; b < bricks; b += p) {
            strips[std::size_t(b)] = Image(width, rows);
            at += unpackRows(recv.data() + at, end - at, strips[std::size_t(b)], 0, rows);
        }
    }
    recv = {};
    std::vector<const Image*> ordered;
    for (int b : frontToBack) ordered.push_back(&strips[std::size_t(b)]);
    const Image strip = rows > 0 ? compositePieces(ordered, mode) : Image();
    strips.clear();
    // Gather the strips on rank 0, row spans only.
    std::vector<float> packed;
    if (me != 0) packRows(strip, 0, rows, packed);
    if (packed.size() > std::size_t(INT_MAX)) throw Error("bricks: a strip exceeds MPI's count");
    const int count = int(packed.size());
    std::vector<int> counts(me == 0 ? p : 0), offsets(me == 0 ? p : 0);
    MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
    std::vector<float> gathered;
    if (me == 0) {
        std::size_t n = 0;
        for (int q = 0; q < p; ++q) {
            offsets[q] = int(n);
            n += std::size_t(counts[q]);
        }
        if (n > std::size_t(INT_MAX)) throw Error("bricks: a frame exceeds MPI's count");
        gathered.resize(n);
        *received += 4ull * n;
    } else {
        *sent += 4ull * std::uint64_t(count);
    }
    MPI_Gatherv(packed.data(), count, MPI_FLOAT, gathered.data(), counts.data(), offsets.data(),
                MPI_FLOAT, 0, MPI_COMM_WORLD);
    if (me != 0) return Image();
    Image out(width, height);
    std::copy(strip.pixels.begin(), strip.pixels.end(), out.pixels.begin());
    for (int q = 1; q < p; ++q) {
        const int r0 = stripBegin(height, q, p), r1 = stripBegin(height, q + 1, p);
        unpackRows(gathered.data() + offsets[q], std::size_t(counts[q]), out, r0, r1 - r0);
    }
    return out;
}

}  // namespace

bool icetBuilt() {
#if SPLAT_MPI_HAVE_ICET
    return true;
#else
    return false;
#endif
}

std::unique_ptr<BrickGroup> makeBrickGroup(Session& session, Compositor compositor) {
    auto group = std::make_unique<MpiBrickGroup>(session);
    if (compositor == Compositor::Icet) {
#if SPLAT_MPI_HAVE_ICET
        group->useIcet();
#else
        throw Error("this splat was built without IceT (SPLAT_ICET=OFF): no IceT compositor");
#endif
    }
    return group;
}

std::uint64_t lastBytesSent(const BrickGroup& group) {
    const auto* g = dynamic_cast<const MpiBrickGroup*>(&group);
    return g ? g->lastSent() : 0;
}

}  // namespace splat::mpi
