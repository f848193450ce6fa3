#!/usr/bin/env bash
# Installs the dependencies and builds splat (Release) into ./build; the log goes to
# build/build.log (never the repository root). ccache is used when it is installed.
# SPLAT_WITH_ICET=1: with splat::mpi's IceT compositor (docs/building.md).
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
mkdir -p build
log=build/build.log
launcher=()
if command -v ccache > /dev/null 2>&1; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
# SPLAT_WITH_ICET=1 (tools/setup.sh installs IceT): the IceT compositor must build.
icet=()
if [ "${SPLAT_WITH_ICET:-0}" = 1 ]; then icet=(-DSPLAT_ICET=ON); fi
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" "${icet[@]}" > "$log" 2>&1 || { cat "$log"; exit 1; }
cmake --build build -j"$(nproc)" >> "$log" 2>&1 || { tail -50 "$log"; exit 1; }
echo "build: ok (build/bin/splat; log in $log)"
