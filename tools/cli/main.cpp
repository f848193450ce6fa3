// The `splat` command-line program: see README.md ("Command line") and splat/DESIGN.md.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>

#include "commands.h"

int main(int argc, char** argv) {
    CLI::App app{
        "splat: splatting volume renderer (axis-aligned and image-aligned sheet "
        "buffers, reference ray caster)"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "splat 0.1.0");
    splat::cli::registerInfo(app);
    splat::cli::registerRender(app);
    splat::cli::registerRotate(app);
    splat::cli::registerCompare(app);
    splat::cli::registerBench(app);
    splat::cli::registerPopping(app);
    splat::cli::registerStudy(app);
    splat::cli::setCommandLine(argc, argv);
    splat::cli::registerSlices(app);
    splat::cli::registerMpr(app);
    splat::cli::registerCpr(app);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "splat: error: %s\n", e.what());
        return 1;
    }
    return 0;
}
