#!/usr/bin/python3
"""Sort-last bricks under MPI (docs/parallel.md): peak memory per rank,
strong and weak scaling with the work per rank and the bytes exchanged, a frame-time model
for 64-1024 ranks, and the plot (SVG) of docs/parallel.md.

    /usr/bin/python3 tools/bench/mpi_scaling.py [--splat build/bin/splat] [--out DIR]
        [--memory-volume synthetic:phantom:800] [--skip-memory]
        [--memory-file /tmp/shell_820.nii [--memory-size 820] [--file-only]]

Every figure is measured on this machine with `mpirun --oversubscribe` (ranks share its
cores, so wall times are not a scaling result; the work per rank and the bytes exchanged
do not depend on oversubscription). As root it sets OpenMPI's run-as-root variables.
"""
import argparse
import json
import os
import re
import subprocess
import sys

ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_btl="self,vader", OMPI_MCA_btl_vader_single_copy_mechanism="none")
# Only the skull is opaque (the phantom's 2.0 shell): few splats, so that the volume's
# samples dominate the memory.
SKULL_TF = {"domain": "normalized", "unit_distance": 1.0,
            "points": [[0.0, 0, 0, 0, 0], [0.8, 0, 0, 0, 0], [1.0, 1, 1, 1, 0.05]]}


def run(cmd):
    r = subprocess.run(cmd, env=ENV, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit("failed: " + " ".join(cmd) + "\n" + r.stderr)
    return r


def bricked(splat, ranks, volume, out, extra, timed=False):
    cmd = ["mpirun", "--oversubscribe", "-np", str(ranks)]
    if timed:
        cmd += ["/usr/bin/time", "-f", "peak-kib %M"]
    cmd += [splat, "render", volume, "--bricks", str(ranks), "-o", out] + extra
    r = run(cmd)
    per = [{"bricks": int(m[2]), "samples": int(m[3]), "splats": int(m[4]),
            "load_ms": float(m[5]), "scene_ms": float(m[6]), "render_ms": float(m[7]),
            "bytes": int(m[8])}
           for m in re.finditer(r"rank (\d+): (\d+) bricks, largest (\d+) samples .*?, (\d+) "
                                r"splats, load ([\d.]+) ms, scene ([\d.]+) ms, render ([\d.]+) "
                                r"ms, exchanged (\d+)", r.stdout)]
    comp = float(re.search(r"composite ([\d.]+) ms", r.stdout)[1])
    est = re.search(r"memory estimate: ([\d.]+) MiB", r.stdout)
    peaks = [int(m) for m in re.findall(r"peak-kib (\d+)", r.stderr)]
    return {"ranks": ranks, "per_rank": per, "composite_ms": comp, "peak_kib": peaks,
            "estimate_mib": float(est[1]) if est else 0.0}


def compare(splat, a, b):
    r = run([splat, "compare", a, b])
    return float(re.search(r"max abs\s+([\d.e+-]+)", r.stdout)[1])


def write_shell(path, n):
    """A float32 NIfTI of n^3 samples, written slab by slab: 0 around a shell of 2.0 (the
    phantom's skull) of radius 0.4 n and thickness 0.03 n, with a little texture."""
    import nibabel as nib
    import numpy as np
    hdr = nib.Nifti1Header()
    hdr.set_data_shape((n, n, n))
    hdr.set_data_dtype(np.float32)
    hdr.set_sform(np.diag([1.0, 1.0, 1.0, 1.0]), code=1)
    hdr.set_qform(np.diag([1.0, 1.0, 1.0, 1.0]), code=1)
    hdr["vox_offset"] = 352
    c = (n - 1) / 2
    y, x = np.mgrid[0:n, 0:n].astype(np.float32)
    with open(path + ".part", "wb") as f:
        f.write(hdr.binaryblock)
        f.write(b"\0" * 4)
        for k in range(n):
            r = np.sqrt((x - c) ** 2 + (y - c) ** 2 + (k - c) ** 2) / n
            slab = np.where(np.abs(r - 0.4) < 0.015, 2.0, 0.0).astype(np.float32)
            slab += (0.1 * np.sin(x * 0.3 + k * 0.2)).astype(np.float32) * (slab > 0)
            f.write(slab.astype("<f4").tobytes(order="C"))  # slab[y, x]: x fastest
    os.replace(path + ".part", path)


def memory_file(a, common):
    """Peak RSS per rank reading a >= 2 GiB float NIfTI from disk with K = 1, 2, 4, 8
    ranks (each reads its brick by byte ranges and the outer faces), against one process
    loading it whole."""
    if not os.path.exists(a.memory_file):
        write_shell(a.memory_file, a.memory_size)
    one = os.path.join(a.out, "file_one.exr")
    r = run(["/usr/bin/time", "-f", "peak-kib %M", a.splat, "render", a.memory_file, "-o", one]
            + common)
    mem = {"file": a.memory_file, "bytes": os.path.getsize(a.memory_file),
           "one_process_kib": int(re.findall(r"peak-kib (\d+)", r.stderr)[-1]), "runs": []}
    print(f"file {a.memory_file}: one process {mem['one_process_kib'] / 1024:.0f} MiB", flush=True)
    for k in (1, 2, 4, 8):
        out = os.path.join(a.out, f"file{k}.exr")
        m = bricked(a.splat, k, a.memory_file, out, common, timed=True)
        m["max_abs_vs_one_process"] = compare(a.splat, out, one)
        mem["runs"].append(m)
        print(f"file K={k}: peak per rank {max(m['peak_kib']) / 1024:.0f} MiB (all: "
              f"{[p // 1024 for p in m['peak_kib']]}), estimate {m.get('estimate_mib', 0):.0f} "
              f"MiB, load {max(p['load_ms'] for p in m['per_rank']):.0f} ms, max abs vs one "
              f"process {m['max_abs_vs_one_process']:.3g}", flush=True)
    with open(os.path.join(a.out, "memory_file.json"), "w") as f:
        json.dump(mem, f, indent=1)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--splat", default="build/bin/splat")
    ap.add_argument("--out", default="build/mpi_scaling")
    ap.add_argument("--memory-volume", default="synthetic:phantom:800")
    ap.add_argument("--skip-memory", action="store_true")
    ap.add_argument("--memory-file", help="also measure memory per rank on this float NIfTI "
                    "(written first when missing: a skull-like shell, N^3 float32)")
    ap.add_argument("--memory-size", type=int, default=820)
    ap.add_argument("--file-only", action="store_true", help="only the --memory-file runs")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    tf = os.path.join(a.out, "skull.json")
    with open(tf, "w") as f:
        json.dump(SKULL_TF, f)
    common = ["--renderer", "axis", "--tf", tf, "--size", "256x256", "--azimuth", "30",
              "--elevation", "15", "--early-termination", "0"]
    results = {}
    if a.memory_file:
        memory_file(a, common)
        if a.file_only:
            return

    # Strong scaling: one volume, K = 1..8 bricks on K ranks.
    strong = [bricked(a.splat, k, "synthetic:phantom:256", os.path.join(a.out, f"strong{k}.exr"),
                      common) for k in (1, 2, 3, 4, 6, 8)]
    results["strong"] = strong
    # Weak scaling: N^3 grows with K (N = 160 K^(1/3)).
    weak = []
    for k in (1, 2, 4, 8):
        n = round(160 * k ** (1 / 3))
        w = bricked(a.splat, k, f"synthetic:phantom:{n}", os.path.join(a.out, f"weak{k}.exr"),
                    common)
        w["n"] = n
        weak.append(w)
    results["weak"] = weak

    # Memory per rank on a volume of >= 2 GiB of floats, and the same image as one process.
    if a.skip_memory:  # keep the memory figures of an earlier run
        try:
            with open(os.path.join(a.out, "mpi_scaling.json")) as f:
                old = json.load(f)
            if "memory" in old:
                results["memory"] = old["memory"]
        except (OSError, ValueError):
            pass
    else:
        one = os.path.join(a.out, "memory_one.exr")
        r = run(["/usr/bin/time", "-f", "peak-kib %M", a.splat, "render", a.memory_volume, "-o",
                 one] + common)
        mem = {"one_process_kib": int(re.findall(r"peak-kib (\d+)", r.stderr)[-1]), "runs": []}
        for k in (1, 2, 4, 8):
            out = os.path.join(a.out, f"memory{k}.exr")
            m = bricked(a.splat, k, a.memory_volume, out, common, timed=True)
            m["max_abs_vs_one_process"] = compare(a.splat, out, one)
            mem["runs"].append(m)
            print(f"memory K={k}: peak per rank {max(m['peak_kib']) / 1024:.0f} MiB "
                  f"(all: {[p // 1024 for p in m['peak_kib']]}), max abs vs one process "
                  f"{m['max_abs_vs_one_process']:.3g}", flush=True)
        results["memory"] = mem
    with open(os.path.join(a.out, "mpi_scaling.json"), "w") as f:
        json.dump(results, f, indent=1)
    report(results, a.out)


def model(strong, width=1024, height=1024, volume_n=4096, sparse_ratio=0.115):
    """Frame time for P ranks of a volume_n^3 volume at width x height: the measured render
    rate (splats per second per rank, from the 1-rank strong-scaling run) on V/P of the
    splats, plus direct-send (P - 1 messages of W H 16 / P bytes each) and the gather on rank
    0 over an interconnect of alpha = 2 us latency, beta = 1 / (12.5 GB/s) (InfiniBand HDR
    200 Gb/s at half its peak). The sparse direct-send (row spans of the pixels that are not
    transparent) sends `sparse_ratio` of those bytes: measured 1.93 MB against 16.78 MB for
    the busiest rank at P = 8, 1024^2, phantom:128 (tools/bench/icet_compare.sh; a brick
    covers less of the frame as P grows, so the ratio at P = 8 is an upper bound beyond)."""
    one = strong[0]["per_rank"][0]
    rate = one["splats"] / (one["render_ms"] / 1000.0)          # splats per second per rank
    classify = one["samples"] / (one["scene_ms"] / 1000.0)      # samples per second per rank
    splats_per_sample = one["splats"] / (256 ** 3)
    alpha, beta = 2e-6, 1 / 12.5e9
    image = width * height * 16
    rows = []
    for p in (64, 128, 256, 512, 1024):
        render = splats_per_sample * volume_n ** 3 / p / rate
        scene = volume_n ** 3 / p / classify
        exchange = (p - 1) * alpha + image * (p - 1) / p * beta * 2   # send and receive
        gather = p * alpha + image * beta
        latency = (2 * p - 1) * alpha
        sparse = latency + sparse_ratio * (exchange + gather - latency)
        rows.append({"ranks": p, "scene_s": scene, "render_s": render,
                     "composite_dense_s": exchange + gather, "composite_s": sparse,
                     "frame_s": render + sparse})
    return rate, classify, rows


def report(results, out):
    strong, weak = results["strong"], results["weak"]
    lines = ["**Strong scaling** (synthetic:phantom:256, axis, 256², skull-only transfer "
             "function; K bricks on K ranks):", "",
             "| ranks | largest brick (samples) | splats per rank (max) | scene ms per rank (max) | "
             "frame ms per rank (max) | bytes exchanged per rank (max) | composite ms |",
             "|---|---|---|---|---|---|---|"]
    for s in strong:
        pr = s["per_rank"]
        lines.append(f"| {s['ranks']} | {max(p['samples'] for p in pr)} | "
                     f"{max(p['splats'] for p in pr)} | {max(p['scene_ms'] for p in pr):.1f} | "
                     f"{max(p['render_ms'] for p in pr):.1f} | "
                     f"{max(p['bytes'] for p in pr)} | {s['composite_ms']:.1f} |")
    lines += ["", "**Weak scaling** (phantom:N with N = 160 K^(1/3)):", "",
              "| ranks | N | largest brick (samples) | splats per rank (max) | bytes exchanged "
              "per rank (max) |", "|---|---|---|---|---|"]
    for w in weak:
        pr = w["per_rank"]
        lines.append(f"| {w['ranks']} | {w['n']} | {max(p['samples'] for p in pr)} | "
                     f"{max(p['splats'] for p in pr)} | {max(p['bytes'] for p in pr)} |")
    if "memory" in results:
        mem = results["memory"]
        lines += ["", f"**Memory per rank** (one process without bricks: "
                  f"{mem['one_process_kib'] / 1024:.0f} MiB peak):", "",
                  "| ranks | peak RSS per rank, MiB (max) | all ranks | max abs vs one process |",
                  "|---|---|---|---|"]
        for m in mem["runs"]:
            lines.append(f"| {m['ranks']} | {max(m['peak_kib']) / 1024:.0f} | "
                         f"{', '.join(str(p // 1024) for p in m['peak_kib'])} | "
                         f"{m['max_abs_vs_one_process']:.3g} |")
    rate, classify, rows = model(strong)
    lines += ["", f"**Model** (4096³ volume of the phantom's density of opaque samples, 1024²; "
              f"measured per rank: frame {rate:.3g} splats/s, classification {classify:.3g} "
              f"samples/s):", "",
              "| ranks | classification s (once per volume) | frame: render s | composite s, "
              "dense | composite s, sparse | frame s |", "|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['ranks']} | {r['scene_s']:.2f} | {r['render_s']:.4f} | "
                     f"{r['composite_dense_s']:.4f} | {r['composite_s']:.4f} | "
                     f"{r['frame_s']:.4f} |")
    text = "\n".join(lines) + "\n"
    with open(os.path.join(out, "mpi_scaling.md"), "w") as f:
        f.write(text)
    print(text)
    plot(results, rows, os.path.join(out, "mpi_scaling.svg"))


def plot(results, rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 3, figsize=(13, 3.8))
    strong = results["strong"]
    k = [s["ranks"] for s in strong]
    ax[0].plot(k, [max(p["samples"] for p in s["per_rank"]) / 1e6 for s in strong], "o-",
               label="largest brick (M samples)")
    ax[0].plot(k, [max(p["splats"] for p in s["per_rank"]) / 1e6 for s in strong], "s-",
               label="splats per rank (M)")
    ax[0].plot(k, [strong[0]["per_rank"][0]["samples"] / 1e6 / r for r in k], "k:",
               label="1/K")
    ax[0].set_xlabel("ranks K")
    ax[0].set_title("strong scaling: work per rank")
    ax[0].legend(fontsize=8)
    if "memory" in results:
        mem = results["memory"]["runs"]
        ax[1].plot([m["ranks"] for m in mem], [max(m["peak_kib"]) / 1024 for m in mem], "o-",
                   label="peak RSS per rank (max)")
        ax[1].axhline(results["memory"]["one_process_kib"] / 1024, color="gray", ls="--",
                      label="one process, no bricks")
        ax[1].set_xlabel("ranks K")
        ax[1].set_ylabel("MiB")
        ax[1].set_title("memory per rank, phantom:800 (1.9 GiB floats)")
        ax[1].legend(fontsize=8)
    p = [r["ranks"] for r in rows]
    ax[2].loglog(p, [r["scene_s"] for r in rows], "^--", label="classification (once)")
    ax[2].loglog(p, [r["render_s"] for r in rows], "o-", label="render (measured rate)")
    ax[2].loglog(p, [r["composite_s"] for r in rows], "s-", label="sparse direct-send + gather")
    ax[2].loglog(p, [r["frame_s"] for r in rows], "k-", label="frame")
    ax[2].set_xlabel("ranks P")
    ax[2].set_ylabel("seconds")
    ax[2].set_title("model: 4096³, 1024², HDR InfiniBand")
    ax[2].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path)


if __name__ == "__main__":
    main()
