// Sort-last bricks over MPI (splat/mpi/brick_group.h).
#include "splat/mpi/brick_group.h"

#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <climits>
#include <cstring>
#include <thread>
#include <type_traits>

#include "splat/error.h"
#include "splat/slab_sheets.h"

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
        const int p = size();
        const int bricks = int(frontToBack.size());
        const std::size_t rowFloats = std::size_t(width) * 4;
        // Send: for each destination rank, the destination's strip of each of my partials
        // (in my brick order).
        std::vector<int> sendCounts(p, 0), sendOffsets(p, 0), recvCounts(p, 0), recvOffsets(p, 0);
        std::vector<float> send;
        for (int d = 0; d < p; ++d) {
            sendOffsets[d] = int(send.size());
            const int r0 = stripBegin(height, d, p), r1 = stripBegin(height, d + 1, p);
            for (const auto& [b, image] : partials) {
                const float* from = &image.pixels[std::size_t(r0) * width].x;
                send.insert(send.end(), from, from + std::size_t(r1 - r0) * rowFloats);
            }
            sendCounts[d] = int(send.size()) - sendOffsets[d];
        }
        // Receive: from each source rank, my strip of each of its bricks (b % p == source).
        const int m0 = stripBegin(height, rank(), p), m1 = stripBegin(height, rank() + 1, p);
        const std::size_t stripFloats = std::size_t(m1 - m0) * rowFloats;
        int total = 0;
        for (int q = 0; q < p; ++q) {
            int count = 0;
            for (int b = q; b < bricks; b += p) ++count;
            recvOffsets[q] = total;
            recvCounts[q] = int(std::size_t(count) * stripFloats);
            total += recvCounts[q];
        }
        std::vector<float> recv(static_cast<std::size_t>(total));
        MPI_Alltoallv(send.data(), sendCounts.data(), sendOffsets.data(), MPI_FLOAT, recv.data(),
                      recvCounts.data(), recvOffsets.data(), MPI_FLOAT, MPI_COMM_WORLD);
        std::uint64_t moved = 0;
        for (int q = 0; q < p; ++q)
            if (q != rank()) moved += 4ull * (std::uint64_t(sendCounts[q]) + recvCounts[q]);
        partials.clear();  // the partial images are no longer needed
        std::vector<Image> strips(static_cast<std::size_t>(bricks));
        for (int q = 0; q < p; ++q) {
            std::size_t at = std::size_t(recvOffsets[q]);
            for (int b = q; b < bricks; b += p, at += stripFloats) {
                strips[std::size_t(b)] = Image(width, m1 - m0);
                std::memcpy(strips[std::size_t(b)].pixels.data(), recv.data() + at,
                            stripFloats * sizeof(float));
            }
        }
        recv.clear();
        std::vector<const Image*> ordered;
        for (int b : frontToBack) ordered.push_back(&strips[std::size_t(b)]);
        const Image strip = m1 > m0 ? compositeBricks(ordered, mode, background) : Image();
        // Gather the strips on rank 0.
        std::vector<int> counts(p), offsets(p);
        for (int q = 0; q < p; ++q) {
            offsets[q] = int(std::size_t(stripBegin(height, q, p)) * rowFloats);
            counts[q] = int(std::size_t(stripBegin(height, q + 1, p) - stripBegin(height, q, p)) *
                            rowFloats);
        }
        Image out = rank() == 0 ? Image(width, height) : Image();
        MPI_Gatherv(strip.pixels.empty() ? nullptr : &strip.pixels[0].x, counts[rank()], MPI_FLOAT,
                    rank() == 0 ? &out.pixels[0].x : nullptr, counts.data(), offsets.data(),
                    MPI_FLOAT, 0, MPI_COMM_WORLD);
        if (rank() == 0)
            for (int q = 1; q < p; ++q) moved += 4ull * std::uint64_t(counts[q]);
        else
            moved += 4ull * std::uint64_t(counts[rank()]);
        if (bytes) *bytes += moved;
        return out;
    }

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
    Session& s_;
};

}  // namespace

std::unique_ptr<BrickGroup> makeBrickGroup(Session& session) {
    return std::make_unique<MpiBrickGroup>(session);
}

}  // namespace splat::mpi
