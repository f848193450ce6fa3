#!/usr/bin/env bash
# The README's Performance section: splat side by side with VTK's CPU ray caster
# (tools/bench/vs_vtk.py; VTK is optional, exit 77 without it). Builds the programs the
# benchmark runs, then passes its arguments on, e.g.
#   bash tools/bench.sh --rounds 1 --markdown perf.md --json perf.json   (~30 min, 2 cores)
#   bash tools/bench.sh --quick                                            (CI smoke, < 60 s)
set -euo pipefail
cd "$(dirname "$0")/.."
# The Performance figures are measured with -march=native (SPLAT_NATIVE=ON; the default build
# is portable and 4.6-6.6% slower on ch2 512^2, README "Building").
cmake -S . -B build -DSPLAT_NATIVE=ON > /dev/null
cmake --build build -j2 --target splat_cli bench_frames bench_fill > /dev/null
# As root, splat and VTK run at real-time priority (SCHED_FIFO, inherited by every child; the
# kernel still leaves 5% of each second to the rest), so other processes on a shared machine
# do not distort the timings of either.
RT=()
if [ "$(id -u)" -eq 0 ] && command -v chrt > /dev/null && chrt -f 50 true 2> /dev/null; then
    RT=(chrt -f 50)
fi
exec "${RT[@]}" python3 tools/bench/vs_vtk.py "$@"
