#!/usr/bin/env bash
# Installs the built splat into a temporary prefix, then configures, builds and runs the
# outside project tools/consumer against it (find_package(splat CONFIG) and pkg-config),
# which asserts a pixel value. Usage: bash tools/test_install.sh   (after tools/build.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cmake --install build --prefix "$tmp/prefix" > "$tmp/install.log"
# IceT (SPLAT_ICET) is private to splat::mpi, which is not installed: the installed package
# config, splat.pc and libraries never name IceT or ParaView (docs/building.md).
if grep -rliE "icet|paraview" "$tmp/prefix/lib"*/cmake "$tmp/prefix/lib"*/pkgconfig; then
    echo "test_install: the installed package names IceT or ParaView (files above)"; exit 1
fi
for lib in $(find "$tmp/prefix" -name 'lib*.a' -o -name 'lib*.so*'); do
    if nm -A "$lib" 2> /dev/null | grep -qi " [UT] icet"; then
        echo "test_install: $lib refers to IceT"; exit 1
    fi
done
cmake -S tools/consumer -B "$tmp/build" -DCMAKE_PREFIX_PATH="$tmp/prefix" -DCMAKE_BUILD_TYPE=Release \
    > "$tmp/configure.log" 2>&1 || { cat "$tmp/configure.log"; exit 1; }
# A consumer configures without warning blocks from splat's or its dependencies' CMake files.
if grep -q "CMake Warning\|CMake Deprecation Warning" "$tmp/configure.log"; then
    echo "test_install: configuring the consumer printed warnings:"; cat "$tmp/configure.log"; exit 1
fi
cmake --build "$tmp/build" -j2 > "$tmp/build.log" 2>&1 || { cat "$tmp/build.log"; exit 1; }
"$tmp/build/splat_consumer" "$tmp"
# pkg-config: relocatable (the prefix comes from the .pc file's folder), and the static
# libraries' dependencies are in Libs, so a plain --libs links (with or without --static).
pc=$(find "$tmp/prefix" -name splat.pc | head -1)
[ -n "$pc" ] || { echo "test_install: no splat.pc installed"; exit 1; }
# The Python package (SPLAT_PYTHON): imported from the prefix's site folder, one render.
if grep -q "^SPLAT_PYTHON:BOOL=ON" build/CMakeCache.txt; then
    python=$(sed -n 's/^Python3_EXECUTABLE:[A-Z]*=//p' build/CMakeCache.txt)
    site=$(dirname "$(find "$tmp/prefix" -name '_splat*.so' | head -1)")
    [ "$site" != "." ] || { echo "test_install: the Python module was not installed"; exit 1; }
    (cd "$tmp" && PYTHONPATH=$(dirname "$site") "$python" -c \
        "import splat; assert splat.render(splat.synthetic('blob', 16), size=(8, 8)).shape == (8, 8, 4)")
    echo "install: Python package splat imports from $(dirname "$site")"
fi
mv "$tmp/prefix" "$tmp/moved"  # any prefix: the installed tree moved after installing
pcdir=$(dirname "${pc/$tmp\/prefix/$tmp/moved}")
flags=$(PKG_CONFIG_PATH=$pcdir pkg-config --cflags --libs splat)
inc=$(PKG_CONFIG_PATH=$pcdir pkg-config --variable=includedir splat)
[ "$(realpath "$inc")" = "$(realpath "$tmp/moved/include")" ] ||
    { echo "test_install: pkg-config's includedir $inc is not the prefix's"; exit 1; }
for mode in plain static; do
    extra=$([ $mode = static ] && PKG_CONFIG_PATH=$pcdir pkg-config --static --libs splat || true)
    # shellcheck disable=SC2086
    c++ -O1 -o "$tmp/pc_consumer_$mode" tools/consumer/main.cpp $flags $extra \
        > "$tmp/pc_$mode.log" 2>&1 || { echo "test_install: pkg-config ($mode) link failed:"; \
        tail -20 "$tmp/pc_$mode.log"; exit 1; }
    "$tmp/pc_consumer_$mode" "$tmp"
done
# The default build is portable: SPLAT_NATIVE is off and no target
# compiles with -march=native unless asked for.
cmake -S . -B "$tmp/defaults" > "$tmp/defaults.log" 2>&1 || { cat "$tmp/defaults.log"; exit 1; }
grep -q "^SPLAT_NATIVE:BOOL=OFF" "$tmp/defaults/CMakeCache.txt" ||
    { echo "test_install: SPLAT_NATIVE is not off by default"; exit 1; }
if grep -rq --include=flags.make -e "-march=native" "$tmp/defaults"; then
    echo "test_install: the default build compiles with -march=native"; exit 1
fi
echo "install: ok (find_package(splat) without warnings; pkg-config splat from a moved prefix, plain and --static)"
