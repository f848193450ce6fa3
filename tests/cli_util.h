#pragma once
// Runs the `splat` executable (SPLAT_EXE) with arguments and captures its exit status,
// stdout and stderr, for command-line end-to-end tests. No shell is involved, so
// arguments need no quoting. Scratch files go to testTmpDir() (SPLAT_TEST_TMP).
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

extern char** environ;

namespace splat::test {

struct RunResult {
    int status = -1;  ///< exit code; 128 + signal number if killed by a signal
    std::string out;  ///< everything written to stdout
    std::string err;  ///< everything written to stderr
    /// Non-empty lines of stderr.
    std::vector<std::string> errLines() const {
        std::vector<std::string> lines;
        std::istringstream in(err);
        for (std::string l; std::getline(in, l);)
            if (!l.empty()) lines.push_back(l);
        return lines;
    }
};

/// The scratch folder for tests (created on first use); `sub` makes a fresh subfolder
/// (removed first if it exists).
inline std::filesystem::path testTmpDir(const std::string& sub = "") {
    std::filesystem::path dir(SPLAT_TEST_TMP);
    std::filesystem::create_directories(dir);
    if (!sub.empty()) {
        dir /= sub;
        std::filesystem::remove_all(dir);
        std::filesystem::create_directories(dir);
    }
    return dir;
}

inline std::string readTextFile(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

/// Runs the program `exe` (a path, or a name looked up in PATH) with `args`; stdout and
/// stderr are captured through files in the scratch folder (unique per call, removed
/// afterwards).
inline RunResult runProgram(const std::string& exe, const std::vector<std::string>& args) {
    static std::atomic<int> counter{0};
    std::filesystem::path dir = testTmpDir();
    std::string tag = std::to_string(::getpid()) + "_" + std::to_string(counter++);
    std::filesystem::path outPath = dir / (".run_" + tag + ".out");
    std::filesystem::path errPath = dir / (".run_" + tag + ".err");

    std::vector<std::string> argv_s{exe};
    argv_s.insert(argv_s.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& a : argv_s) argv.push_back(a.data());
    argv.push_back(nullptr);

    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, outPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                     0644);
    posix_spawn_file_actions_addopen(&actions, 2, errPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                     0644);
    RunResult r;
    pid_t pid = 0;
    int rc = posix_spawnp(&pid, exe.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) {
        r.err = "posix_spawn failed for " + exe;
        return r;
    }
    int wstatus = 0;
    while (::waitpid(pid, &wstatus, 0) < 0) {
    }
    if (WIFEXITED(wstatus))
        r.status = WEXITSTATUS(wstatus);
    else if (WIFSIGNALED(wstatus))
        r.status = 128 + WTERMSIG(wstatus);
    r.out = readTextFile(outPath);
    r.err = readTextFile(errPath);
    std::error_code ec;
    std::filesystem::remove(outPath, ec);
    std::filesystem::remove(errPath, ec);
    return r;
}

/// Runs SPLAT_EXE with `args` (runProgram).
inline RunResult runSplat(const std::vector<std::string>& args) {
    return runProgram(SPLAT_EXE, args);
}

}  // namespace splat::test
