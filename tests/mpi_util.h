// Starting the `splat` program under mpirun, for the tests of ranks (hidden tag [.mpi], run by
// the ctest test mpi.ranks when splat is built with MPI).
#pragma once
#include <cstdlib>
#include <string>
#include <vector>

#include "cli_util.h"

namespace splat::test {

/// True when `mpirun` is OpenMPI's (it needs --oversubscribe for more ranks than cores;
/// MPICH's hydra oversubscribes by itself and has no such option).
inline bool openMpi() {
    static const bool yes =
        runProgram("mpirun", {"--version"}).out.find("Open MPI") != std::string::npos;
    return yes;
}

/// `mpirun [--oversubscribe] -np N splat ARGS`, killed after 120 s (a hang fails the test).
inline RunResult mpirunSplat(int n, const std::vector<std::string>& args) {
    ::setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
    ::setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
    ::setenv("OMPI_MCA_btl", "self,vader", 0);  // one machine: shared memory, no network probe
    // Containers often forbid the cross-memory attach of OpenMPI's shared-memory transport.
    ::setenv("OMPI_MCA_btl_vader_single_copy_mechanism", "none", 0);
    std::vector<std::string> a = {"-s", "KILL", "120", "mpirun"};
    if (openMpi()) a.push_back("--oversubscribe");
    for (const std::string& s : {std::string("-np"), std::to_string(n), std::string(SPLAT_EXE)})
        a.push_back(s);
    a.insert(a.end(), args.begin(), args.end());
    return runProgram("timeout", a);
}

}  // namespace splat::test
