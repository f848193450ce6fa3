// The command line as typed, quoted for a shell (reports show how to reproduce them), and
// the build facts of --version.
#include <string>

#include "commands.h"
#include "footprint/lanes.h"
#include "splat/version.h"

namespace splat::cli {

namespace {
std::string gCommandLine;
}  // namespace

std::string shellQuoted(const std::string& arg) {
    if (!arg.empty() && arg.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                              "0123456789-_./:=,+@%") == std::string::npos)
        return arg;
    std::string q = "'";
    for (char c : arg) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

const std::string& commandLine() { return gCommandLine; }

void setCommandLine(int argc, char** argv) {
    gCommandLine.clear();
    for (int i = 0; i < argc; ++i) {
        if (i) gCommandLine += ' ';
        gCommandLine += shellQuoted(i == 0 ? std::string("splat") : std::string(argv[i]));
    }
}

std::string versionText() {
    std::string s = std::string("splat ") + kVersion + "\n";
#if defined(__clang__)
    s += "compiler: clang " __clang_version__ "\n";
#elif defined(__GNUC__)
    s += "compiler: GCC " __VERSION__ "\n";
#else
    s += "compiler: unknown\n";
#endif
#if defined(FOOTPRINT_HAVE_LANES)
#if defined(__AVX2__) && defined(__FMA__)
    s += "SIMD: AVX2+FMA footprint lanes built in and always used (native build)";
#else
    s += std::string("SIMD: AVX2+FMA footprint lanes built in, chosen at run time: ") +
         (footprint::cpuHasLanes() ? "used (this CPU has AVX2 and FMA)"
                                   : "not used (this CPU lacks AVX2 or FMA; scalar loops)");
#endif
#else
    s += "SIMD: no AVX2 lanes on this architecture (scalar loops)";
#endif
    return s;
}

}  // namespace splat::cli
