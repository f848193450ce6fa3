#!/usr/bin/env python3
# What the Python module costs (docs/python.md "What Python costs"), measured in one run:
#  1. Python overhead per frame: wall time of Scene.render minus the library's own frame time
#     (RenderStats::milliseconds, the whole frame in C++), ch2 at 512x512, median of N frames;
#     and the one-shot splat.render's wall time against a C++ Scene + frame of the same
#     settings (classification included) timed by the library.
#  2. Throughput of 2 Python threads (1 render thread each) against 1 thread, same frames.
#  3. Peak memory of wrapping a 512^3 float32 array (VmHWM before and after).
#  4. Ctrl-C latency: SIGINT during a long reference render (ch2 512x512) and during a popping
#     sweep, time until KeyboardInterrupt reaches Python.
# Usage: PYTHONPATH=build/python /usr/bin/python3 tools/bench/python_bench.py [FRAMES]
import os
import signal
import statistics
import sys
import threading
import time

import numpy as np

import splat

CH2 = "/usr/share/mricron/templates/ch2.nii.gz"
FRAMES = int(sys.argv[1]) if len(sys.argv) > 1 else 7


def vm(key):
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(key + ":"):
                return int(line.split()[1])  # KiB
    raise KeyError(key)


def overhead(volume):
    for renderer in ("axis", "sheet"):
        scene = splat.Scene(volume, tf="mri-head", size=(512, 512), threads=2)
        scene.render(renderer=renderer)  # warm-up
        walls, libs = [], []
        for n in range(FRAMES):
            t = time.perf_counter()
            _, stats = scene.render(renderer=renderer, azimuth=10 * n, return_stats=True)
            walls.append((time.perf_counter() - t) * 1e3)
            libs.append(stats["milliseconds"])
        over = [w - c for w, c in zip(walls, libs)]
        print(f"overhead {renderer:5s}: frame {statistics.median(libs):8.2f} ms in C++, "
              f"{statistics.median(walls):8.2f} ms from Python: +{statistics.median(over):.3f} ms "
              f"({100 * statistics.median(over) / statistics.median(libs):.2f}%)")


def threads(volume):
    scene = splat.Scene(volume, tf="mri-head", size=(256, 256), threads=1)
    scene.render(renderer="axis", threads=1)
    work = [10 * n for n in range(2 * FRAMES)]

    def run(azimuths):
        for a in azimuths:
            scene.render(renderer="axis", azimuth=a, threads=1)

    t, c = time.perf_counter(), time.process_time()
    run(work)
    one, cpu1 = time.perf_counter() - t, time.process_time() - c
    t, c = time.perf_counter(), time.process_time()
    ts = [threading.Thread(target=run, args=(work[i::2],)) for i in range(2)]
    for th in ts:
        th.start()
    for th in ts:
        th.join()
    two, cpu2 = time.perf_counter() - t, time.process_time() - c
    # CPU seconds per wall second: 1 and 2 when the machine gives the process the cores.
    print(f"threads: {len(work)} frames 256x256 axis threads=1: 1 Python thread {one:.2f} s "
          f"(cpu/wall {cpu1 / one:.2f}), 2 Python threads {two:.2f} s (cpu/wall {cpu2 / two:.2f}): "
          f"throughput x{one / two:.2f}; load average {os.getloadavg()[0]:.1f}")


def wrap():
    a = np.random.default_rng(0).random((512, 512, 512), dtype=np.float32)
    before = vm("VmHWM")
    v = splat.Volume(a, background_value=0)
    after = vm("VmHWM")
    grown = after - before
    print(f"wrap 512^3 float32 ({a.nbytes >> 20} MiB): peak memory +{grown / 1024:.1f} MiB "
          f"({100 * grown * 1024 / a.nbytes:.2f}% of the array), borrowed={v.borrowed}")


def interrupt(label, call):
    """SIGINT once the call has run 1 s; the time until KeyboardInterrupt is caught."""
    fired = []

    def fire():
        time.sleep(1.0)
        fired.append(time.perf_counter())
        os.kill(os.getpid(), signal.SIGINT)

    threading.Thread(target=fire, daemon=True).start()
    try:
        call()
        print(f"ctrl-c {label}: finished before the signal")
    except KeyboardInterrupt:
        print(f"ctrl-c {label}: KeyboardInterrupt {1e3 * (time.perf_counter() - fired[0]):.0f} ms "
              f"after SIGINT")


if __name__ == "__main__":
    ch2 = splat.load(CH2)
    overhead(ch2)
    threads(ch2)
    wrap()
    interrupt("render", lambda: splat.render(ch2, tf="mri-head", size=(512, 512),
                                             renderer="reference"))
    interrupt("popping", lambda: splat.popping(ch2, tf="mri-head", size=(256, 256)))
