#pragma once
// Parsing a file first in a forked child process (private, not installed), for libraries
// whose readers can abort or corrupt the heap on malformed input (OpenVDB on a damaged tree:
// "malloc(): corrupted top size", SIGABRT). The child does the parse and exits; when it
// dies by a signal, runs past 60 s or runs out of memory, the parent throws one
// splat::Error line and never parses the file itself.
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <new>
#include <string>

#include "splat/error.h"

#if defined(__SANITIZE_ADDRESS__)
#define SPLAT_CHILD_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SPLAT_CHILD_ASAN 1
#endif
#endif
#ifndef SPLAT_CHILD_ASAN
#define SPLAT_CHILD_ASAN 0
#endif
#if SPLAT_CHILD_ASAN
#include <sanitizer/common_interface_defs.h>
#endif

namespace splat::detail {

/// Runs `work` in a forked child; throws "NAME: malformed FORMAT file (LIBRARY died on it
/// with SIGABRT ...)" when the child is killed by a signal, "... ran out of memory" when an
/// allocation fails (the child's address space is capped at the machine's physical memory,
/// except under AddressSanitizer). Exceptions inside the child are ignored: the parent's
/// own parse reports them.
template <typename F>
void parseInChild(const std::string& name, const std::string& format, const std::string& library,
                  F work) {
    std::fflush(nullptr);
    const pid_t pid = fork();
    if (pid < 0) throw Error(name + ": cannot start a process to parse the " + format + " file");
    if (pid == 0) {
        alarm(60);  // a parser that hangs is a failure too
#if !SPLAT_CHILD_ASAN
        {
            const long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGESIZE);
            if (pages > 0 && size > 0) {
                const rlim_t cap = rlim_t(pages) * rlim_t(size);
                const rlimit limit{cap, cap};
                setrlimit(RLIMIT_AS, &limit);
            }
        }
#endif
#if SPLAT_CHILD_ASAN
        // A sanitizer's death in the child (its allocator refusing a size the file declares)
        // is the child's failure, reported by the parent below, not the host fuzzer's finding.
        __sanitizer_set_death_callback(nullptr);
#endif
        std::set_new_handler([] { _exit(3); });
        // The library's messages are not for the user, and the host's crash handlers (a test
        // framework's, a fuzzer's) must not report the child's death as their own.
        for (int sig : {SIGABRT, SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGALRM}) signal(sig, SIG_DFL);
        const int null = open("/dev/null", O_WRONLY);
        if (null >= 0) {
            dup2(null, 1);
            dup2(null, 2);
        }
        try {
            work();
        } catch (...) {
        }
        _exit(0);
    }
    int status = 0;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) throw Error(name + ": lost the " + format + " parsing process");
    if (WIFEXITED(status) && WEXITSTATUS(status) == 3)
        throw Error(name + ": malformed " + format + " file (" + library +
                    " ran out of memory reading it)");
    if (WIFEXITED(status) && WEXITSTATUS(status) != 0)  // a sanitizer ended the child
        throw Error(name + ": malformed " + format + " file (" + library +
                    " failed on it, exit status " + std::to_string(WEXITSTATUS(status)) + ")");
    if (WIFSIGNALED(status)) {
        const int sig = WTERMSIG(status);
        throw Error(name + ": malformed " + format + " file (" + library + " died on it with " +
                    (sig == SIGABRT   ? std::string("SIGABRT")
                     : sig == SIGSEGV ? std::string("SIGSEGV")
                     : sig == SIGALRM ? std::string("a timeout")
                                      : "signal " + std::to_string(sig)) +
                    ")");
    }
}

}  // namespace splat::detail
