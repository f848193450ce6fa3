#pragma once
// One MPI job of the splat program (docs/parallel.md): rank 0 (the
// leader) runs the command and writes every output; the other ranks (workers) render what
// the leader asks for and write nothing. This module is the only code that calls MPI; it
// uses only the MPI standard (OpenMPI and MPICH).
//
// The job's life, which guarantees one error on rank 0 and no hang:
// - every worker sends the leader exactly one hello: ready, or why it failed (its scene
//   could not be built, a bad option, ...);
// - the leader collects the hellos before it first hands out work (a failed worker ends
//   the command with that worker's error) and at the latest when it finishes;
// - the leader ends the job by sending every worker a stop carrying its exit status.
#include <string>
#include <vector>

namespace splat::mpi {

/// True when an MPI launcher started this process (OpenMPI's mpirun sets
/// OMPI_COMM_WORLD_SIZE; MPICH's hydra, Intel MPI and Slurm's PMI set PMI_SIZE or
/// PMI_RANK; PMIx launchers PMIX_RANK). A process started otherwise never initialises MPI.
bool launchedByMpirun();

/// Message tags of the job.
enum Tag : int { kHello = 101, kJob = 102, kResult = 103, kStop = 104, kBrick = 105 };

class Session {
  public:
    /// Initialises MPI (MPI_THREAD_FUNNELED: only the calling thread calls MPI).
    Session(int* argc, char*** argv);
    ~Session();
    Session(const Session&) = delete;
    Session& operator=(const Session&) = delete;

    /// The session of this process, or null.
    static Session* current();

    int rank() const { return rank_; }
    int size() const { return size_; }
    bool leader() const { return rank_ == 0; }

    /// Worker: tells the leader that this process is ready (`ok`) or why it failed. Only
    /// the first call sends anything.
    void hello(bool ok, const std::string& why = {});
    /// Leader: receives the hellos not yet received; throws splat::Error naming the first
    /// failed rank and its message.
    void awaitWorkers();

    /// Ends the job (once; the destructor calls it with status 1 if nobody did) and
    /// returns this process's exit status: the leader sends every worker the stop with
    /// `status` (1 instead of 0 if a worker failed, whose message it prints); a worker
    /// sends its hello if it has not (failed if `status` != 0, with the error kept by
    /// keepError), then waits for the stop and returns the leader's status.
    int finish(int status);

    /// Worker: the error line this process would have printed; sent with its hello.
    void keepError(const std::string& line);

  private:
    int rank_ = 0, size_ = 1;
    bool finished_ = false, helloSent_ = false;
    std::string error_;
    std::string workerFailure_;  // leader: the first failed worker's message
    std::vector<bool> heard_;    // leader: hellos received, per rank
};

}  // namespace splat::mpi
