// The `splat` program under mpirun (parallel.h).
#include "parallel.h"

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <memory>

#include "diagnostics.h"

#if SPLAT_HAVE_MPI
#include "splat/mpi/brick_group.h"
#include "splat/mpi/frame_farm.h"
#include "splat/mpi/session.h"
#endif

namespace splat::cli {

namespace {
#if SPLAT_HAVE_MPI
std::unique_ptr<mpi::Session> gSession;
#endif
}  // namespace

ParallelRun::ParallelRun(int* argc, char*** argv) {
#if SPLAT_HAVE_MPI
    if (!mpi::launchedByMpirun()) return;
    gSession = std::make_unique<mpi::Session>(argc, argv);
    if (gSession->leader() && gSession->size() > 1) installFrameFarm(mpi::makeFrameFarm(*gSession));
#else
    (void)argc, (void)argv;
    for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"})
        if (const char* n = std::getenv(name); n && std::atoi(n) > 1)
            refusal_ = std::string("started by an MPI launcher with ") + n +
                       " processes, but this splat was built without MPI (SPLAT_MPI=OFF): "
                       "run it without mpirun";
#endif
}

ParallelRun::~ParallelRun() { finish(1); }

int ParallelRun::finish(int status) {
#if SPLAT_HAVE_MPI
    if (gSession) {
        installFrameFarm(nullptr);
        status = gSession->finish(status);
        gSession.reset();
    }
#endif
    return status;
}

int processCount() {
#if SPLAT_HAVE_MPI
    if (gSession) return gSession->size();
#endif
    return 1;
}

int processRank() {
#if SPLAT_HAVE_MPI
    if (gSession) return gSession->rank();
#endif
    return 0;
}

bool workersTakePart(const std::string& command) {
    return command == "rotate" || command == "popping" || command == "render" || command == "study";
}

void printError(const std::string& line) {
#if SPLAT_HAVE_MPI
    if (gSession && !gSession->leader()) {
        gSession->keepError(line);
        return;
    }
#endif
    std::fprintf(stderr, "splat: error: %s\n", line.c_str());
}

void serveFrames(const std::function<Scene()>& build) {
#if SPLAT_HAVE_MPI
    // A launcher that forwards Ctrl-C to every rank (OpenMPI's mpirun kills the job instead):
    // rank 0 stops the sequence and ends the job, so a worker ignores it and finishes the
    // frames it holds.
    std::signal(SIGINT, SIG_IGN);
    if (gSession && !gSession->leader()) mpi::serveFrames(*gSession, build);
#else
    (void)build;
#endif
}

void checkCompositor(const std::string& name) {
    if (name != "direct" && name != "icet" && name != "auto")
        throw UsageError("--compositor must be direct, icet or auto (got '" + name + "')");
#if SPLAT_HAVE_MPI
    const bool icet = mpi::icetBuilt();
#else
    const bool icet = false;
#endif
    if (name == "icet" && !icet)
        throw UsageError(
            "--compositor icet: this splat was built without IceT (SPLAT_ICET; Debian: "
            "paraview-dev, docs/building.md); use --compositor direct");
}

std::unique_ptr<BrickGroup> brickGroup(const std::string& compositor) {
#if SPLAT_HAVE_MPI
    checkCompositor(compositor);
    if (gSession)
        return mpi::makeBrickGroup(
            *gSession, compositor == "icet" || (compositor == "auto" && mpi::icetBuilt())
                           ? mpi::Compositor::Icet
                           : mpi::Compositor::Direct);
#else
    (void)compositor;
#endif
    return std::make_unique<LocalBrickGroup>();
}

}  // namespace splat::cli
