#!/usr/bin/env bash
# Installs, builds and runs the whole test suite: the installed package consumed by an
# outside project (tools/test_install.sh), ctest, then a 5-second smoke run of every fuzz
# target (tools/fuzz.sh --smoke: clang-14 builds build-fuzz; fails in CI without clang).
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/build.sh
bash tools/test_install.sh
(cd build && ctest --output-on-failure -j"$(nproc)" --timeout 900)
bash tools/fuzz.sh --smoke
