#pragma once
// Parsing a file first in a forked child process (private, not installed), for libraries
// whose readers can abort or corrupt the heap on malformed input (OpenVDB on a damaged tree:
// "malloc(): corrupted top size", SIGABRT; GDCM's assertions). The child does the parse and
// exits; runInChild says how it ended, and parseInChild turns a death by a signal, a run past
// 60 s or running out of memory into one splat::Error line, so that the parent never parses
// the file itself.
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <functional>
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

/// The child's address-space cap (none under AddressSanitizer, whose shadow memory needs
/// terabytes of address space): the machine's physical memory, or the child's size at the
/// fork plus 1 GiB (for readers whose recovery heuristics may allocate a length no check saw).
enum class ChildMemory { Physical, PresentPlusGiB };

/// How the child ended: it returned (Clean; exceptions inside it are ignored, the parent's
/// own parse reports them), an allocation failed (OutOfMemory), it exited otherwise with
/// `code` (a sanitizer ended it), or it died by signal `code` (SIGALRM: the 60 s timeout).
struct ChildEnd {
    enum Kind { Clean, OutOfMemory, Exited, Signalled } kind = Clean;
    int code = 0;
};

inline void capChildMemory([[maybe_unused]] ChildMemory cap) {
#if !SPLAT_CHILD_ASAN
    rlim_t bytes = 0;
    if (cap == ChildMemory::Physical) {
        const long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGESIZE);
        if (pages > 0 && size > 0) bytes = rlim_t(pages) * rlim_t(size);
    } else {
        long pages = 0;
        if (FILE* f = std::fopen("/proc/self/statm", "r")) {
            if (std::fscanf(f, "%ld", &pages) != 1) pages = 0;
            std::fclose(f);
        }
        if (pages > 0) bytes = rlim_t(pages) * rlim_t(sysconf(_SC_PAGESIZE)) + (rlim_t(1) << 30);
    }
    if (bytes > 0) {
        const rlimit limit{bytes, bytes};
        setrlimit(RLIMIT_AS, &limit);
    }
#endif
}

/// The child's side: limits, quiet and plain deaths, then `work`; never returns.
[[noreturn]] inline void runChild(ChildMemory cap, const std::function<void()>& work) {
    alarm(60);  // a parser that hangs is a failure too
    capChildMemory(cap);
#if SPLAT_CHILD_ASAN
    // A sanitizer's death in the child (its allocator refusing a size the file declares)
    // is the child's failure, reported by the parent, not the host fuzzer's finding.
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

/// Runs `work` in a forked child and says how the child ended; throws "NAME: cannot start a
/// process to parse the FORMAT file" when fork fails.
inline ChildEnd runInChild(const std::string& name, const std::string& format, ChildMemory cap,
                           const std::function<void()>& work) {
    std::fflush(nullptr);
    const pid_t pid = fork();
    if (pid < 0) throw Error(name + ": cannot start a process to parse the " + format + " file");
    if (pid == 0) runChild(cap, work);
    int status = 0;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) throw Error(name + ": lost the " + format + " parsing process");
    if (WIFEXITED(status) && WEXITSTATUS(status) == 3) return {ChildEnd::OutOfMemory, 3};
    if (WIFEXITED(status) && WEXITSTATUS(status) != 0)
        return {ChildEnd::Exited, WEXITSTATUS(status)};
    if (WIFSIGNALED(status)) return {ChildEnd::Signalled, WTERMSIG(status)};
    return {};
}

/// Runs `work` in a forked child (address space capped at the physical memory); throws
/// "NAME: malformed FORMAT file (LIBRARY died on it with SIGABRT ...)" when the child is
/// killed by a signal, "... ran out of memory" when an allocation fails, "... failed on it"
/// when a sanitizer ends it.
inline void parseInChild(const std::string& name, const std::string& format,
                         const std::string& library, const std::function<void()>& work) {
    const ChildEnd end = runInChild(name, format, ChildMemory::Physical, work);
    const std::string malformed = name + ": malformed " + format + " file (" + library;
    switch (end.kind) {
        case ChildEnd::Clean:
            return;
        case ChildEnd::OutOfMemory:
            throw Error(malformed + " ran out of memory reading it)");
        case ChildEnd::Exited:
            throw Error(malformed + " failed on it, exit status " + std::to_string(end.code) + ")");
        case ChildEnd::Signalled:
            throw Error(malformed + " died on it with " +
                        (end.code == SIGABRT   ? std::string("SIGABRT")
                         : end.code == SIGSEGV ? std::string("SIGSEGV")
                         : end.code == SIGALRM ? std::string("a timeout")
                                               : "signal " + std::to_string(end.code)) +
                        ")");
    }
}

}  // namespace splat::detail
