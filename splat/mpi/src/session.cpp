// The MPI job of the splat program (splat/mpi/session.h).
#include "splat/mpi/session.h"

#include <mpi.h>

#include <cstdio>
#include <cstdlib>

#include "splat/error.h"

namespace splat::mpi {

namespace {
Session* gSession = nullptr;
}

bool launchedByMpirun() {
    for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMI_RANK", "PMIX_RANK"})
        if (std::getenv(name)) return true;
    return false;
}

Session::Session(int* argc, char*** argv) {
    int provided = 0;
    MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
    heard_.assign(std::size_t(size_), false);
    gSession = this;
}

Session::~Session() {
    if (!finished_) finish(1);
    gSession = nullptr;
}

Session* Session::current() { return gSession; }

void Session::keepError(const std::string& line) {
    if (error_.empty()) error_ = line;
}

void Session::hello(bool ok, const std::string& why) {
    if (leader() || helloSent_) return;
    helloSent_ = true;
    std::string msg(1, ok ? '1' : '0');
    msg += why;
    MPI_Send(msg.data(), int(msg.size()), MPI_CHAR, 0, kHello, MPI_COMM_WORLD);
}

void Session::awaitWorkers() {
    for (int r = 1; r < size_; ++r) {
        if (heard_[std::size_t(r)]) continue;
        MPI_Status st;
        MPI_Probe(r, kHello, MPI_COMM_WORLD, &st);
        int n = 0;
        MPI_Get_count(&st, MPI_CHAR, &n);
        std::string msg(std::size_t(n), '\0');
        MPI_Recv(msg.data(), n, MPI_CHAR, r, kHello, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        heard_[std::size_t(r)] = true;
        if (workerFailure_.empty() && (msg.empty() || msg[0] != '1'))
            workerFailure_ = "rank " + std::to_string(r) + " of " + std::to_string(size_) + ": " +
                             (msg.size() > 1 ? msg.substr(1) : "failed");
    }
    if (!workerFailure_.empty()) throw Error(workerFailure_);
}

int Session::finish(int status) {
    if (finished_) return status;
    finished_ = true;
    if (leader()) {
        if (size_ > 1) {
            try {
                awaitWorkers();
            } catch (const Error& e) {
                // The command did not learn of it (it handed out no work): its outputs are
                // complete, but the job still fails, with the worker's error.
                if (status == 0) {
                    std::fprintf(stderr, "splat: error: %s\n", e.what());
                    status = 1;
                }
            }
            for (int r = 1; r < size_; ++r) MPI_Send(&status, 1, MPI_INT, r, kStop, MPI_COMM_WORLD);
        }
    } else {
        hello(status == 0, error_.empty() ? "failed" : error_);
        int leaderStatus = 1;
        MPI_Recv(&leaderStatus, 1, MPI_INT, 0, kStop, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        status = leaderStatus;
    }
    MPI_Finalize();
    return status;
}

}  // namespace splat::mpi
