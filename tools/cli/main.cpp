// The `splat` command-line program: see docs/command-line.md and docs/design.md.
// Exit statuses: 0 success, 1 the work failed, 2 usage error (diagnostics.h).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <exception>
#include <iostream>

#include "commands.h"
#include "diagnostics.h"
#include "parallel.h"
#include "splat/error.h"

namespace {

/// Levenshtein distance, for "did you mean".
std::size_t editDistance(const std::string& a, const std::string& b) {
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        std::size_t diag = row[0];
        row[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const std::size_t up = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] != b[j - 1])});
            diag = up;
        }
    }
    return row[b.size()];
}

std::vector<const CLI::App*> visibleCommands(const CLI::App& app) {
    return app.get_subcommands([](const CLI::App* c) { return !c->get_group().empty(); });
}

std::string usageText(const CLI::App& app) {
    std::string s = "usage: splat COMMAND [options]   (splat COMMAND --help for its options)\n\n";
    s += "commands:\n";
    for (const CLI::App* c : visibleCommands(app)) {
        char line[256];
        std::snprintf(line, sizeof line, "  %-9s %s\n", c->get_name().c_str(),
                      c->get_description().c_str());
        s += line;
    }
    s += "\nsplat --version prints the version and build; exit status 0 success, 1 failure, 2 "
         "usage error.\n";
    return s;
}

int runCommand(int argc, char** argv) {
    using namespace splat::cli;
    CLI::App app{
        "splat: splatting volume renderer (axis-aligned and image-aligned sheet "
        "buffers, reference ray caster)"};
    app.require_subcommand(1);
    app.set_version_flag(
        "--version", [] { return versionText(); }, "print the version and build");
    app.footer("Exit status: 0 success, 1 the work failed, 2 usage error.");
    registerInfo(app);
    registerRender(app);
    registerRotate(app);
    registerCompare(app);
    registerBench(app);
    registerPopping(app);
    registerStudy(app);
    registerSlices(app);
    registerIso(app);
    registerMpr(app);
    registerCpr(app);
    registerGaussians(app);
    registerCompletion(app);
    setCommandLine(argc, argv);
    if (argc < 2) {
        std::fputs(usageText(app).c_str(), stderr);
        return kExitUsage;
    }
    const std::string first = argv[1];
    const auto all = app.get_subcommands([](const CLI::App*) { return true; });
    const bool known = std::any_of(all.begin(), all.end(),
                                   [&](const CLI::App* c) { return c->get_name() == first; });
    if (!first.empty() && first[0] != '-' && !known) {
        std::string best;
        std::size_t bestDistance = 3;  // suggest only close names
        for (const CLI::App* c : visibleCommands(app)) {
            const std::size_t d = editDistance(first, c->get_name());
            if (d < bestDistance || (c->get_name().rfind(first, 0) == 0 && first.size() >= 2))
                best = c->get_name(), bestDistance = std::min(d, bestDistance);
        }
        std::fprintf(stderr, "splat: error: unknown command '%s'%s; 'splat --help' lists them\n",
                     first.c_str(),
                     best.empty() ? "" : (" (did you mean '" + best + "'?)").c_str());
        return kExitUsage;
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
        std::string where = "splat";
        for (const CLI::App* c : app.get_subcommands()) where += " " + c->get_name();
        std::string what = e.what();
        std::replace(what.begin(), what.end(), '\n', ' ');
        printError(what + " (see '" + where + " --help')");
        return kExitUsage;
    } catch (const splat::OptionError& e) {
        // UsageError, a malformed option value, or an option the input cannot honour (--time
        // past the last step)
        printError(e.what());
        return kExitUsage;
    } catch (const std::exception& e) {
        printError(e.what());
        return kExitFailure;
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    using namespace splat::cli;
    // Under mpirun the ranks > 0 take part in render, rotate and popping only (parallel.h).
    ParallelRun parallel(&argc, &argv);
    if (!parallel.refusal().empty()) {
        std::fprintf(stderr, "splat: error: %s\n", parallel.refusal().c_str());
        return kExitUsage;
    }
    if (workerProcess() && (argc < 2 || !workersTakePart(argv[1]))) return parallel.finish(0);
    return parallel.finish(runCommand(argc, argv));
}
