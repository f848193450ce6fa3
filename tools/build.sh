#!/usr/bin/env bash
# Installs the dependencies and builds splat (Release) into ./build; the log goes to
# build/build.log (never the repository root). ccache is used when it is installed.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
mkdir -p build
log=build/build.log
launcher=()
if command -v ccache > /dev/null 2>&1; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" > "$log" 2>&1 || { cat "$log"; exit 1; }
cmake --build build -j"$(nproc)" >> "$log" 2>&1 || { tail -50 "$log"; exit 1; }
echo "build: ok (build/bin/splat; log in $log)"
