// The command line as typed, quoted for a shell (reports show how to reproduce them).
#include <string>

#include "commands.h"

namespace splat::cli {

namespace {
std::string gCommandLine;

std::string shellQuoted(const std::string& arg) {
    if (!arg.empty() && arg.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                              "0123456789-_./:=,+@%") == std::string::npos)
        return arg;
    std::string q = "'";
    for (char c : arg) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}
}  // namespace

const std::string& commandLine() { return gCommandLine; }

void setCommandLine(int argc, char** argv) {
    gCommandLine.clear();
    for (int i = 0; i < argc; ++i) {
        if (i) gCommandLine += ' ';
        gCommandLine += shellQuoted(i == 0 ? std::string("splat") : std::string(argv[i]));
    }
}

}  // namespace splat::cli
