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
# The Python package (SPLAT_PYTHON): imported from the prefix's site folder, one render.
if grep -q "^SPLAT_PYTHON:BOOL=ON" build/CMakeCache.txt; then
    python=$(sed -n 's/^Python3_EXECUTABLE:[A-Z]*=//p' build/CMakeCache.txt)
    site=$(dirname "$(find "$tmp/prefix" -name '_splat*.so' | head -1)")
    [ "$site" != "." ] || { echo "test_install: the Python module was not installed"; exit 1; }
    (cd "$tmp" && PYTHONPATH=$(dirname "$site") "$python" -c \
        "import splat; assert splat.render(splat.synthetic('blob', 16), size=(8, 8)).shape == (8, 8, 4)")
    echo "install: Python package splat imports from $(dirname "$site")"
fi
echo "install: ok (find_package(splat) and pkg-config splat from a temporary prefix)"
