#!/usr/bin/env bash
# Installs the built splat into a temporary prefix, then configures, builds and runs the
# outside project tools/consumer against it (find_package(splat CONFIG) and pkg-config),
# which asserts a pixel value. Usage: bash tools/test_install.sh   (after tools/build.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cmake --install build --prefix "$tmp/prefix" > "$tmp/install.log"
cmake -S tools/consumer -B "$tmp/build" -DCMAKE_PREFIX_PATH="$tmp/prefix" -DCMAKE_BUILD_TYPE=Release \
    > "$tmp/configure.log" 2>&1 || { cat "$tmp/configure.log"; exit 1; }
cmake --build "$tmp/build" -j"$(nproc)" > "$tmp/build.log" 2>&1 || { cat "$tmp/build.log"; exit 1; }
"$tmp/build/splat_consumer" "$tmp"
# pkg-config sees the same package.
pc=$(find "$tmp/prefix" -name splat.pc | head -1)
[ -n "$pc" ] || { echo "test_install: no splat.pc installed"; exit 1; }
PKG_CONFIG_PATH=$(dirname "$pc") pkg-config --cflags --libs splat > /dev/null
echo "install: ok (find_package(splat) and pkg-config splat from a temporary prefix)"
