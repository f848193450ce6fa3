#!/usr/bin/env bash
# The test suite under AddressSanitizer + UBSan + float-cast-overflow (clang-14: GCC's
# UBSan cannot see float -> integer overflow). Configures build-san with
# CC=clang-14 CXX=clang++-14 -DSPLAT_SANITIZE=ON, builds the CLI and the tests under
# nice -n 19 and runs ctest; any sanitizer report aborts the test that triggered it
# (-fno-sanitize-recover=all). Extra arguments go to ctest (e.g. -R volume, -L extremes).
set -euo pipefail
cd "$(dirname "$0")/.."
build=build-san
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
if [[ ! -f "$build/CMakeCache.txt" ]]; then
  CC=clang-14 CXX=clang++-14 cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DSPLAT_SANITIZE=ON "${launcher[@]}" >/dev/null
fi
start=$(date +%s)
nice -n 19 cmake --build "$build" -j"${SPLAT_SAN_JOBS:-2}" --target splat_cli splat_tests
built=$(date +%s)
# The browser test drives Chromium, which is not instrumented; it is left to the normal build.
(cd "$build" && ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 \
  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  nice -n 19 ctest --output-on-failure -j"${SPLAT_SAN_JOBS:-2}" --timeout 3600 -LE browser "$@")
done_=$(date +%s)
echo "sanitize.sh: build $((built - start)) s, tests $((done_ - built)) s"
