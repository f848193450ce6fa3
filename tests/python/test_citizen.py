# Good-citizen behaviour: the GIL is released (two threads render at the same time), Ctrl-C
# raises KeyboardInterrupt in a long render or sweep and writes nothing, no memory growth
# over 1000 renders, docstrings for help().
import os
import threading
import time

import numpy as np
import pytest

import splat
from conftest import run_python


def test_two_threads_render_at_the_same_time():
    v = splat.synthetic("phantom", 64)
    scene = splat.Scene(v, size=(160, 160), threads=1)
    scene.render()  # warm the tables
    spans = {}

    def work(name):
        start = time.perf_counter()
        scene.render(renderer="sheet", slab=0.25)
        spans[name] = (start, time.perf_counter())

    threads = [threading.Thread(target=work, args=(n,)) for n in "ab"]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    # With the GIL held, the second thread could not start before the first finished.
    starts, ends = [s for s, _ in spans.values()], [e for _, e in spans.values()]
    assert max(starts) < min(ends)


INTERRUPT = r"""
import os, signal, sys, threading, time
import splat
{setup}
done = []
def progress(d, t, w):
    done.append(d)
def fire():
    while len(done) < 2:
        time.sleep(0.005)
    global fired
    fired = time.perf_counter()
    os.kill(os.getpid(), signal.SIGINT)
threading.Thread(target=fire, daemon=True).start()
try:
    {call}
    print("finished")
except KeyboardInterrupt:
    print("interrupted after %.3f s, %d progress calls" % (time.perf_counter() - fired, len(done)))
"""


def test_ctrl_c_interrupts_a_long_render():
    code = INTERRUPT.format(
        setup="v = splat.synthetic('phantom', 96)",
        call="splat.render(v, renderer='reference', size=(256, 256), ref_step=0.05, "
             "threads=1, progress=progress)")
    p = run_python(code)
    assert p.returncode == 0, p.stderr
    assert "interrupted after" in p.stdout, p.stdout
    # it stopped long before the frame's 256 rows were done
    assert int(p.stdout.split(",")[1].split()[0]) < 256


def test_ctrl_c_interrupts_a_sweep_and_writes_no_report(tmp):
    report = tmp / "pop"
    report.mkdir()
    code = INTERRUPT.format(
        setup="v = splat.synthetic('phantom', 48)",
        call=f"r = splat.popping(v, size=(96, 96), from_=0, to=30, step=1, progress=progress); "
             f"r.write_report({str(report)!r})")
    p = run_python(code)
    assert p.returncode == 0, p.stderr
    assert "interrupted after" in p.stdout, p.stdout
    assert list(report.iterdir()) == []


def _rss_kib():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") // 1024


def test_no_memory_growth_over_1000_renders():
    a = np.random.default_rng(3).random((12, 12, 12), dtype=np.float32)
    for _ in range(200):  # warm-up: allocator pools, TBB, tables
        splat.render(splat.Volume(a), size=(16, 16), threads=1)
    before = _rss_kib()
    for n in range(1000):
        splat.render(splat.Volume(a), size=(16, 16), azimuth=n, threads=1,
                     progress=lambda d, t, w: True)
    grown = _rss_kib() - before
    # 1000 frames of 16x16x16 bytes and 1000 volumes of 7 KiB would be > 10 MiB if kept.
    assert grown < 1024, f"resident memory grew by {grown} KiB"


def test_docstrings_name_the_options():
    assert "azimuth" in splat.render.__doc__ and "--tf" in splat.render.__doc__
    assert "[z, y, x]" in splat.Volume.__doc__
    assert "background_value" in splat.load.__doc__
    assert "from_" in splat.popping.__doc__
    for name in splat.__all__:
        assert getattr(splat, name).__doc__, name
