// Frame-parallel sequences over MPI (splat/mpi/frame_farm.h).
#include "splat/mpi/frame_farm.h"

#include <mpi.h>

#include <chrono>
#include <cstring>
#include <map>
#include <optional>
#include <thread>
#include <type_traits>

#include "splat/error.h"
#include "wire.h"

namespace splat::mpi {

namespace {

static_assert(std::is_trivially_copyable_v<CameraParams>);

// RenderStats on the wire: its numbers field by field, then the exact-path reason.
#define SPLAT_STATS_FIELDS(X)                                                                      \
    X(milliseconds)                                                                                \
    X(splats) X(voxels) X(footprintPixels) X(sheets) X(culledSplats) X(referenceStep) X(sheetAxis) \
        X(sheetSign) X(slabs) X(shadeMs) X(projectMs) X(orderMs) X(binMs) X(tilesMs)               \
            X(perspective) X(normals) X(pathScalePixels) X(exactPixels) X(lodLevel) X(lodSplats)

void putStats(Writer& w, const RenderStats& s) {
#define SPLAT_PUT(f) w.put(s.f);
    SPLAT_STATS_FIELDS(SPLAT_PUT)
#undef SPLAT_PUT
    w.putString(s.exactReason);
}

RenderStats getStats(Reader& r) {
    RenderStats s;
#define SPLAT_GET(f) s.f = r.get<decltype(s.f)>();
    SPLAT_STATS_FIELDS(SPLAT_GET)
#undef SPLAT_GET
    s.exactReason = r.getString();
    return s;
}

// A job: [u64 job][u64 view][CameraParams][u32 n][i32 renderer] * n
std::vector<char> encodeJob(std::uint64_t index, const FrameJob& job,
                            const std::vector<RendererKind>& renderers) {
    Writer w;
    w.put(index);
    w.put(std::uint64_t(job.view));
    w.put(job.camera);
    w.put(std::uint32_t(renderers.size()));
    for (RendererKind k : renderers) w.put(std::int32_t(k));
    return std::move(w.bytes);
}

// A result: [u64 job][u8 ok] then the frame ([u32 n] ([i32 w][i32 h][RenderStats][pixels]) * n)
// or the error message.
std::vector<char> encodeResult(std::uint64_t index, const SequenceFrame* f,
                               const std::string& error) {
    Writer w;
    w.put(index);
    w.put(std::uint8_t(f != nullptr));
    if (f) {
        w.put(std::uint32_t(f->images.size()));
        for (std::size_t k = 0; k < f->images.size(); ++k) {
            w.put(std::int32_t(f->images[k].width));
            w.put(std::int32_t(f->images[k].height));
            putStats(w, f->stats[k]);
            w.putArray(f->images[k].pixels.data(), f->images[k].pixels.size());
        }
    } else {
        w.putString(error);
    }
    return std::move(w.bytes);
}

class MpiFrameFarm : public FrameFarm {
  public:
    explicit MpiFrameFarm(Session& s) : s_(s) {}

    void render(const std::vector<RendererKind>& renderers, const std::vector<FrameJob>& jobs,
                const std::function<SequenceFrame(const FrameJob&)>& local,
                const std::function<void(SequenceFrame&&)>& sink) override {
        s_.awaitWorkers();
        inflight_.assign(std::size_t(s_.size()), 0);
        std::map<std::size_t, SequenceFrame> ready;
        std::size_t issued = 0, emitted = 0;
        auto give = [&](int rank) {
            if (issued >= jobs.size()) return;
            const std::vector<char> msg = encodeJob(issued, jobs[issued], renderers);
            MPI_Send(msg.data(), int(msg.size()), MPI_BYTE, rank, kJob, MPI_COMM_WORLD);
            ++issued;
            ++inflight_[std::size_t(rank)];
        };
        try {
            for (int depth = 0; depth < 2; ++depth)
                for (int r = 1; r < s_.size(); ++r) give(r);
            while (emitted < jobs.size()) {
                int waiting = 0;
                MPI_Status st;
                MPI_Iprobe(MPI_ANY_SOURCE, kResult, MPI_COMM_WORLD, &waiting, &st);
                if (waiting || issued >= jobs.size()) {
                    if (!waiting) MPI_Probe(MPI_ANY_SOURCE, kResult, MPI_COMM_WORLD, &st);
                    auto [index, frame] = receive(st, jobs);
                    give(st.MPI_SOURCE);
                    ready.emplace(index, std::move(frame));
                } else {
                    // No result waiting: the leader renders the next view itself.
                    const std::size_t index = issued++;
                    ready.emplace(index, local(jobs[index]));
                }
                for (auto it = ready.begin(); it != ready.end() && it->first == emitted;
                     it = ready.erase(it), ++emitted)
                    sink(std::move(it->second));
            }
        } catch (...) {
            drain();
            throw;
        }
    }

  private:
    std::pair<std::size_t, SequenceFrame> receive(const MPI_Status& probed,
                                                  const std::vector<FrameJob>& jobs) {
        const std::vector<char> msg = receiveBytes(probed.MPI_SOURCE, kResult);
        --inflight_[std::size_t(probed.MPI_SOURCE)];
        Reader r(msg);
        const std::size_t index = std::size_t(r.get<std::uint64_t>());
        if (!r.get<std::uint8_t>())
            throw Error("rank " + std::to_string(probed.MPI_SOURCE) + " of " +
                        std::to_string(s_.size()) + ": " + r.getString());
        if (index >= jobs.size()) throw Error("MPI frame farm: a result for an unknown view");
        SequenceFrame f;
        f.view = jobs[index].view;
        const std::uint32_t n = r.get<std::uint32_t>();
        f.images.resize(n);
        f.stats.resize(n);
        for (std::uint32_t k = 0; k < n; ++k) {
            const int w = r.get<std::int32_t>(), h = r.get<std::int32_t>();
            f.stats[k] = getStats(r);
            f.images[k] = Image(w, h);
            r.getArray(f.images[k].pixels.data(), f.images[k].pixels.size());
        }
        return {index, std::move(f)};
    }

    /// Receives (and drops) every result still in flight, so that no worker is left
    /// blocked in a send and the next render starts clean.
    void drain() {
        for (int r = 1; r < s_.size(); ++r)
            while (inflight_[std::size_t(r)] > 0) {
                receiveBytes(r, kResult);
                --inflight_[std::size_t(r)];
            }
    }

    Session& s_;
    std::vector<int> inflight_;
};

}  // namespace

std::shared_ptr<FrameFarm> makeFrameFarm(Session& session) {
    return std::make_shared<MpiFrameFarm>(session);
}

void serveFrames(Session& session, const std::function<Scene()>& build) {
    std::optional<Scene> scene;
    try {
        scene.emplace(build());
    } catch (const std::exception& e) {
        session.keepError(e.what());
        session.hello(false, e.what());
        return;
    }
    session.hello(true);
    // One result in flight while the next view renders.
    std::vector<char> sending;
    MPI_Request pending = MPI_REQUEST_NULL;
    for (;;) {
        // Waiting sleeps between polls: a blocking probe spins on a core (OpenMPI), which
        // would distort what rank 0 times meanwhile (`study`), for 1 ms at most per job.
        MPI_Status st;
        for (int arrived = 0;;) {
            MPI_Iprobe(0, MPI_ANY_TAG, MPI_COMM_WORLD, &arrived, &st);
            if (arrived) break;
            std::this_thread::sleep_for(std::chrono::microseconds(500));
        }
        if (st.MPI_TAG != kJob) break;  // the stop: Session::finish receives it
        const std::vector<char> msg = receiveBytes(0, kJob);
        Reader r(msg);
        const std::uint64_t index = r.get<std::uint64_t>();
        FrameJob job;
        job.view = std::size_t(r.get<std::uint64_t>());
        job.camera = r.get<CameraParams>();
        std::vector<RendererKind> renderers(r.get<std::uint32_t>());
        for (RendererKind& k : renderers) k = RendererKind(r.get<std::int32_t>());
        std::vector<char> result;
        try {
            const SequenceFrame f = renderFrameJob(*scene, renderers, job);
            result = encodeResult(index, &f, {});
        } catch (const std::exception& e) {
            result = encodeResult(index, nullptr, e.what());
        }
        MPI_Wait(&pending, MPI_STATUS_IGNORE);
        sending = std::move(result);
        MPI_Isend(sending.data(), int(sending.size()), MPI_BYTE, 0, kResult, MPI_COMM_WORLD,
                  &pending);
    }
    MPI_Wait(&pending, MPI_STATUS_IGNORE);
}

}  // namespace splat::mpi
