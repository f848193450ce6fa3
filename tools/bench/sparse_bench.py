#!/usr/bin/python3
"""Time and peak memory of `splat render SHELL.vdb --mode mip --size 256x256` for thin
spherical shells (one voxel thick, radius 0.45 N) in N^3 boxes: how cost grows with the
active voxels (about 2.5 N^2) against the bounding box (N^3). A benchmark, not a test.

    tools/bench/sparse_bench.py SPLAT_EXE [--sizes 128,256,512,1024] [--dir DIR] [-- FLAGS]

The shells are written by tests/sparse/make_sparse_data.py --shell N (python3-openvdb) into
DIR (default /tmp/splat_sparse_bench) once. Each render runs under nice with
/usr/bin/time -v; the table gives active voxels, the dense box's voxels, wall seconds and
peak RSS in MiB. FLAGS after `--` are passed to every render (e.g. --renderer sheet).
"""
import argparse
import os
import re
import subprocess
import sys

here = os.path.dirname(os.path.abspath(__file__))
make = os.path.join(here, "..", "..", "tests", "sparse", "make_sparse_data.py")

argv = sys.argv[1:]
flags = argv[argv.index("--") + 1:] if "--" in argv else []
argv = argv[:argv.index("--")] if "--" in argv else argv
ap = argparse.ArgumentParser()
ap.add_argument("splat")
ap.add_argument("--sizes", default="128,256,512,1024")
ap.add_argument("--dir", default="/tmp/splat_sparse_bench")
a = ap.parse_args(argv)
os.makedirs(a.dir, exist_ok=True)

print(f"{'N':>6} {'active':>10} {'box':>12} {'seconds':>8} {'peak MiB':>9}")
for n in [int(s) for s in a.sizes.split(",")]:
    shell = os.path.join(a.dir, f"shell_{n}.vdb")
    if not os.path.exists(shell):
        subprocess.run(["/usr/bin/python3", make, a.dir, "--shell", str(n)], check=True,
                       stdout=subprocess.DEVNULL)
    info = subprocess.run([a.splat, "info", shell], capture_output=True, text=True)
    m = re.search(r"'density' float: (\d+) active voxels", info.stdout)
    active = int(m.group(1)) if m else -1
    out = os.path.join(a.dir, f"shell_{n}.png")
    r = subprocess.run(["nice", "-n", "10", "/usr/bin/time", "-v", a.splat, "render", shell,
                        "--mode", "mip", "--size", "256x256", "-o", out] + flags,
                       capture_output=True, text=True)
    if r.returncode != 0:
        print(f"{n:>6} {active:>10} {n ** 3:>12}   failed: {r.stderr.strip().splitlines()[-1:]}")
        continue
    wall = re.search(r"Elapsed \(wall clock\) time.*: (?:(\d+):)?(\d+):([\d.]+)", r.stderr)
    secs = (int(wall.group(1) or 0) * 3600 + int(wall.group(2)) * 60 + float(wall.group(3)))
    rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", r.stderr).group(1))
    print(f"{n:>6} {active:>10} {n ** 3:>12} {secs:>8.2f} {rss / 1024:>9.0f}")
    sys.stdout.flush()
