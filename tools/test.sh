#!/usr/bin/env bash
# Installs, builds and runs the whole test suite: the installed package consumed by an
# outside project (tools/test_install.sh), ctest, then a 5-second smoke run of every fuzz
# target (tools/fuzz.sh --smoke: clang-14 builds build-fuzz; fails in CI without clang).
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/build.sh
bash tools/test_install.sh
status=0
(cd build && ctest --output-on-failure -j"$(nproc)" --timeout 900) || status=$?
# The Python tests' own closing line ("N passed in S s"), which CI reads; with SPLAT_PYTHON on,
# a missing line (no test collected, pytest absent) is a failure, never silent.
if grep -q "^SPLAT_PYTHON:BOOL=ON" build/CMakeCache.txt; then
    grep -hE "^[0-9]+ (passed|failed).* in [0-9.]+s" build/Testing/Temporary/LastTest.log ||
        { echo "python.pytest: no pytest summary line"; status=1; }
fi
[ "$status" -eq 0 ] || exit "$status"
bash tools/fuzz.sh --smoke
