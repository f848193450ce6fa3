#!/usr/bin/env bash
# Installs, builds and runs the whole test suite: the installed package consumed by an
# outside project (tools/test_install.sh), then ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/build.sh
bash tools/test_install.sh
(cd build && ctest --output-on-failure -j"$(nproc)" --timeout 900)
