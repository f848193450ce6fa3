#pragma once
// The `splat` program under mpirun (docs/parallel.md). Built with MPI
// (SPLAT_MPI), the program initialises MPI only when an MPI launcher started it (its
// environment says so: splat/mpi/session.h), so a plain `splat ...` never touches MPI.
// Under `mpirun -np K`, rank 0 runs the command and writes every output and message; the
// other ranks render frames for it (rotate, popping) or bricks (render --bricks) and print
// nothing; their errors reach rank 0, which prints one line and ends the job.
#include <functional>
#include <memory>
#include <string>

#include "splat/bricks.h"
#include "splat/scene.h"

namespace splat::cli {

class ParallelRun {
  public:
    ParallelRun(int* argc, char*** argv);
    ~ParallelRun();
    ParallelRun(const ParallelRun&) = delete;
    ParallelRun& operator=(const ParallelRun&) = delete;
    /// Ends the job; returns this process's exit status (splat/mpi/session.h).
    int finish(int status);
    /// A launcher started K > 1 processes of a splat built without MPI: one error line.
    std::string refusal() const { return refusal_; }

  private:
    std::string refusal_;
};

/// The number of processes of the job and this one's rank (1 and 0 without mpirun).
int processCount();
int processRank();
/// True on ranks > 0.
inline bool workerProcess() { return processRank() > 0; }
/// True for the commands the ranks > 0 take part in; they skip every other command.
bool workersTakePart(const std::string& command);

/// Prints `splat: error: LINE` (a worker keeps it for rank 0 instead).
void printError(const std::string& line);

/// Rank 0: hands the frames of rotate and popping to every rank (splat/frame_farm.h).
/// Ranks > 0: build the Scene and render the frames rank 0 asks for, until it stops.
void serveFrames(const std::function<Scene()>& build);

/// `--compositor direct|icet|auto` of render, rotate and popping: how the ranks composite the partial
/// images of bricks (splat/mpi/brick_group.h; direct by default, chosen from measurement:
/// docs/parallel.md "Direct-send beside IceT"). auto: icet when this splat was built with IceT
/// (SPLAT_ICET), else direct. A name that is none of the three, or icet in a splat built
/// without IceT, is a UsageError.
void checkCompositor(const std::string& name);

/// The processes that render the bricks of a frame (splat/bricks.h): every rank under
/// mpirun, compositing with `compositor` (checkCompositor), else this process alone.
std::unique_ptr<BrickGroup> brickGroup(const std::string& compositor = "direct");

}  // namespace splat::cli
