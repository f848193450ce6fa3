#!/usr/bin/env bash
# The tables of splat/docs/performance.md: splat side by side with VTK's CPU ray caster
# (tools/bench/vs_vtk.py; VTK is optional, exit 77 without it). Builds the programs the
# benchmark runs, then passes its arguments on, e.g.
#   bash tools/bench.sh --rounds 1 --markdown perf.md --json perf.json   (the published tables)
#   python3 tools/bench/update_perf_doc.py perf.md   (or --doc splat/docs/performance.md: into it)
#   bash tools/bench.sh --quick                                            (CI smoke, < 60 s)
# The full run also renders pixel-filtered references (cached in build/bench-cache between
# runs), the aliasing (EWA, level of detail) table and the 0-90 degree popping sweep of ch2
# (--no-sweep skips it); its run time is in its output.
set -euo pipefail
cd "$(dirname "$0")/.."
# The Performance figures are measured with -march=native (SPLAT_NATIVE=ON; the default build
# is portable and 4.6-6.6% slower on ch2 512^2, docs/building.md).
cmake -S . -B build -DSPLAT_NATIVE=ON > /dev/null
cmake --build build -j2 --target splat_cli bench_frames bench_fill bench_accuracy > /dev/null
# As root, splat and VTK run at real-time priority (SCHED_FIFO, inherited by every child; the
# kernel still leaves 5% of each second to the rest), so other processes on a shared machine
# do not distort the timings of either.
RT=()
if [ "$(id -u)" -eq 0 ] && command -v chrt > /dev/null && chrt -f 50 true 2> /dev/null; then
    RT=(chrt -f 50)
fi
# Debian's interpreter, which has Debian's python3-vtk9 (the first python3 on PATH may be
# another one).
PY=python3
[ -x /usr/bin/python3 ] && PY=/usr/bin/python3
BENCH_ARGS="$*" exec "${RT[@]}" "$PY" tools/bench/vs_vtk.py "$@"
