#!/usr/bin/env python3
"""splat side by side with VTK's CPU ray caster (vtkFixedPointVolumeRayCastMapper).

Both render the same volume (splat exports it as a float MetaImage on its own world grid),
the same transfer function (normalized domain: opacity 0 up to 0.25, 0.3 at 0.5, 0.8 at 1;
colour black -> (0.9, 0.6, 0.5) at 0.5 -> white; unit distance 1 mm), the same image size
and thread count, and the same orthographic cameras (splat's camera convention and framing:
bench_frames prints each frame's target, view, up and pixel size, and VTK's camera is set
from them). Times are medians over a rotation (azimuth 360 k / F, elevation 15), splat and
VTK interleaved per configuration, in rounds. Accuracy is each image's RMSE (RGB over
black, [0, 1]) against its own converged answer: splat against its reference ray caster,
VTK against itself at 1/8-voxel steps (VTK's images are the 8-bit frame buffer, so its
errors include 8-bit rounding). "splat vs VTK" checks that the two see the same picture.
The fill limit is tools/bench/bench_fill.cpp: a minimal AVX2 footprint-accumulate kernel.

Beside the comparison (docs/performance.md): splat's error against the
pixel-filtered reference where voxels are smaller than pixels (FILTERED; the filtered frames
are cached in BUILD/bench-cache between runs), an aliasing table of EWA and level of detail
against it (ALIASING), the reference ray caster's time per ch2 256^2 frame, the accuracy check
of bench_accuracy against its recorded baseline, the 0-90 degree popping sweep of ch2 as a
whole job (SWEEP; --no-sweep skips it) and peak memory. `--lod auto` rows are added when
the build's --lod accepts `auto`.

Usage:
  python3 tools/bench/vs_vtk.py [--quick] [--build build] [--json FILE] [--markdown FILE]
      [--doc splat/docs/performance.md] [--no-sweep] [--no-filtered] [--cache DIR] [--rounds N]
Needs build/bin/{bench_frames,bench_fill,bench_accuracy,splat} (cmake --build build --target
bench_frames bench_fill bench_accuracy splat_cli) and python3-vtk9; without a display it re-runs itself under
xvfb-run (Debian: xvfb). Exit status: 0 done, 1 a step failed, 77 VTK (or a display) is not
available (the benchmark is skipped; VTK is never a dependency of the library or tests).
--quick (a CI smoke run, < 60 s): ch2 at 256^2, 4 frames, one round, one error frame, a 32^2
aliasing case; no sweep, memory or accuracy check.
"""
import argparse
import hashlib
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

SKIP = 77
CH2 = "/usr/share/mricron/templates/ch2.nii.gz"
TF = {
    "domain": "normalized",
    "unit_distance": 1.0,
    "points": [
        [0.0, 0.0, 0.0, 0.0, 0.0],
        [0.25, 0.45, 0.3, 0.25, 0.0],
        [0.5, 0.9, 0.6, 0.5, 0.3],
        [1.0, 1.0, 1.0, 1.0, 0.8],
    ],
}
ELEVATION = 15.0
VTK_FINE_STEP = 0.125  # voxels: VTK's converged answer


def ensure_vtk():
    """Imports vtk, re-running under Debian's python3 or xvfb-run when that is what is
    missing; exits with SKIP and one line when VTK cannot run here."""
    try:
        import vtk  # noqa: F401
    except ImportError:
        debian = "/usr/bin/python3"
        if os.path.exists(debian) and os.path.realpath(sys.executable) != os.path.realpath(debian) \
                and not os.environ.get("VS_VTK_REEXEC"):
            os.environ["VS_VTK_REEXEC"] = "1"
            os.execv(debian, [debian] + sys.argv)
        print("vs_vtk: VTK's Python bindings are not installed (Debian: apt-get install "
              "python3-vtk9); the side-by-side benchmark is skipped", file=sys.stderr)
        sys.exit(SKIP)
    if not os.environ.get("DISPLAY"):
        xvfb = shutil.which("xvfb-run")
        if xvfb and not os.environ.get("VS_VTK_XVFB"):
            os.environ["VS_VTK_XVFB"] = "1"
            os.execv(xvfb, [xvfb, "-a", "-s", "-screen 0 1280x1280x24", sys.executable] + sys.argv)
        print("vs_vtk: VTK needs a display and xvfb-run is missing (Debian: apt-get install "
              "xvfb xauth); the side-by-side benchmark is skipped", file=sys.stderr)
        sys.exit(SKIP)


def run_json(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"vs_vtk: {' '.join(cmd)} failed ({r.returncode}): {r.stderr.strip()}")
    return json.loads(r.stdout)


class Vtk:
    """VTK's fixed-point CPU ray caster set up as a VTK user would: the same
    transfer function, linear interpolation, no shading, fixed sample distance."""

    def __init__(self, mha, info, size, threads):
        import vtk
        self.vtk = vtk
        vtk.vtkMultiThreader.SetGlobalMaximumNumberOfThreads(threads)
        reader = vtk.vtkMetaImageReader()
        reader.SetFileName(mha)
        reader.Update()
        self.reader = reader
        lo, hi = info["min"], info["max"]
        colour = vtk.vtkColorTransferFunction()
        opacity = vtk.vtkPiecewiseFunction()
        for v, r, g, b, a in TF["points"]:
            colour.AddRGBPoint(lo + v * (hi - lo), r, g, b)
            opacity.AddPoint(lo + v * (hi - lo), a)
        prop = vtk.vtkVolumeProperty()
        prop.SetColor(colour)
        prop.SetScalarOpacity(opacity)
        prop.SetScalarOpacityUnitDistance(TF["unit_distance"])
        prop.SetInterpolationTypeToLinear()
        prop.ShadeOff()
        mapper = vtk.vtkFixedPointVolumeRayCastMapper()
        mapper.SetInputConnection(reader.GetOutputPort())
        mapper.SetAutoAdjustSampleDistances(0)
        mapper.SetLockSampleDistanceToInputSpacing(0)
        mapper.SetImageSampleDistance(1.0)
        mapper.SetNumberOfThreads(threads)
        self.mapper = mapper
        self.voxel = min(info["spacing"])
        volume = vtk.vtkVolume()
        volume.SetMapper(mapper)
        volume.SetProperty(prop)
        ren = vtk.vtkRenderer()
        ren.SetBackground(0, 0, 0)
        ren.AddVolume(volume)
        rw = vtk.vtkRenderWindow()
        rw.SetOffScreenRendering(1)
        rw.SetMultiSamples(0)
        rw.SetSize(size, size)
        rw.AddRenderer(ren)
        self.ren, self.rw, self.size = ren, rw, size
        self.prop, self.colour, self.opacity, self.volume = prop, colour, opacity, volume

    def camera(self, f):
        cam = self.ren.GetActiveCamera()
        t, v = f["target"], f["view"]
        d = 4.0 * f["radius"]
        cam.ParallelProjectionOn()
        cam.SetFocalPoint(*t)
        cam.SetPosition(*[t[i] - d * v[i] for i in range(3)])
        cam.SetViewUp(*f["up"])
        cam.SetParallelScale(0.5 * f["pixel_size"] * self.size)
        self.ren.ResetCameraClippingRange()

    def render(self, f, step):
        self.mapper.SetSampleDistance(step * self.voxel)
        self.camera(f)
        t = time.perf_counter()
        self.rw.Render()
        return 1e3 * (time.perf_counter() - t)

    def save(self, path):
        w2i = self.vtk.vtkWindowToImageFilter()
        w2i.SetInput(self.rw)
        w2i.SetInputBufferTypeToRGB()
        w2i.ReadFrontBufferOff()
        w2i.Update()
        with open(path, "wb") as out:
            out.write(memoryview(w2i.GetOutput().GetPointData().GetScalars()).tobytes())


class Bench:
    def __init__(self, args):
        self.args = args
        self.bin = os.path.join(args.build, "bin")
        for b in ("bench_frames", "bench_fill", "splat"):
            if not os.access(os.path.join(self.bin, b), os.X_OK):
                sys.exit(f"vs_vtk: {self.bin}/{b} is missing: cmake --build {args.build} "
                         "--target bench_frames bench_fill splat_cli")
        self.tmp = tempfile.mkdtemp(prefix="vs_vtk.")
        self.tf = os.path.join(self.tmp, "tf.json")
        with open(self.tf, "w") as f:
            json.dump(TF, f)
        self.volumes = {}
        self.refs = {}
        self.ref_times = {}
        self.computed = []  # filtered references used: made or read from the cache
        self.pixels_per_voxel = {}
        self.lod_auto = False

    def path(self, *parts):
        p = os.path.join(self.tmp, *parts)
        os.makedirs(os.path.dirname(p), exist_ok=True)
        return p

    def volume(self, name, spec):
        if name not in self.volumes:
            if name in FINER:  # a finer resampling of another volume (FINER)
                src, factor = FINER[name]
                spec = self.path(name.replace(":", "_").replace(" ", "_"), "finer.mha")
                lps = self.path(name.replace(":", "_").replace(" ", "_"), "source.mha")
                run_json([f"{self.bin}/bench_frames", "export", VOLUMES[src], lps])
                refine_metaimage(lps, spec, factor)
                os.remove(lps)
            mha = self.path(name.replace(":", "_").replace(" ", "_"), "volume.mha")
            info = run_json([f"{self.bin}/bench_frames", "export", spec, mha])
            vtk_world_frame(mha, info)
            self.volumes[name] = (spec, mha, info)
        return self.volumes[name]

    def splat(self, spec, renderer, size, threads, frames, save, out, slab=1.0, lod="0",
              extra=(), tf=None, warmup=None):
        """bench_frames render: `extra` are further `splat render` options (--mode, --ewa,
        --pixel-filter, ...)."""
        os.makedirs(out, exist_ok=True)
        if warmup is None:
            warmup = renderer != "reference"
        return run_json([f"{self.bin}/bench_frames", "render", spec, tf or self.tf, "--renderer",
                         renderer, "--slab", str(slab), "--size", str(size), "--threads",
                         str(threads), "--frames", str(frames), "--elevation", str(ELEVATION),
                         "--save", ",".join(map(str, save)), "--out", out,
                         "--warmup", "1" if warmup else "0"]
                        + (["--lod", str(lod)] if str(lod) != "0" else []) + list(extra))

    def filtered_refs(self, spec, size, frames, wanted, tf=None, mode="dvr"):
        """The pixel-filtered reference (--renderer reference --pixel-filter FILTER_SIGMA) of
        frames `wanted` of a `frames`-frame rotation: {frame: path of its .f32}, read from the
        cache folder when an earlier run made it (keyed by volume, size, view, transfer
        function and settings), else rendered and stored there."""
        out, uncached = {}, []
        tf_text = open(tf or self.tf).read() if os.path.exists(tf or self.tf) else (tf or self.tf)
        for k in wanted:
            key = {"volume": spec, "volume_file": file_id(spec), "size": size, "frames": frames,
                   "frame": k, "elevation": ELEVATION, "tf": tf_text, "mode": mode,
                   "pixel_filter": FILTER_SIGMA, "threads_independent": True}
            h = hashlib.sha1(json.dumps(key, sort_keys=True).encode()).hexdigest()[:16]
            path = os.path.join(self.args.cache, f"filtered_{h}.f32")
            out[k] = path
            if os.path.exists(path) and os.path.exists(path[:-4] + ".json"):
                self.computed.append(dict(json.load(open(path[:-4] + ".json")), cached=True))
            else:
                uncached.append((k, key, path))
        if uncached:
            os.makedirs(self.args.cache, exist_ok=True)
            tmp = self.path("filtered", "tmp")
            tmp = os.path.dirname(tmp)
            run = self.splat(spec, "reference", size, 2, frames,
                             [k for k, _, _ in uncached], tmp, extra=["--mode", mode,
                             "--pixel-filter", str(FILTER_SIGMA)], tf=tf, warmup=False)
            by_frame = {f["frame"]: f for f in run["frames"]}
            for k, key, path in uncached:
                f = by_frame[k]
                info = dict(key, tf=None, ms=f["ms"], cpu_ms=f["cpu_ms"],
                            pixel_samples=f["pixel_samples"],
                            pixel_filter_change=f["pixel_filter_change"], cached=False)
                shutil.move(os.path.join(tmp, f"frame_{k}.f32"), path + ".part")
                os.replace(path + ".part", path)
                with open(path[:-4] + ".json", "w") as j:
                    json.dump(info, j)
                self.computed.append(info)
        return out

    def compare(self, a, b, size):
        return run_json([f"{self.bin}/bench_frames", "compare", a, b, str(size), str(size)])

    def config(self, name, size, threads, renderer="axis", slab=1.0, vtk_step=1.0, lod="0",
               quality="default"):
        """One row: splat (renderer, slab, level of detail, --quality preset) and VTK
        (vtk_step voxels) on `name` at size^2."""
        a = self.args
        spec, mha, info = self.volume(name, VOLUMES[name])
        frames, save = a.frames, a.error_frames
        tag = f"{name}_{size}_{threads}_{renderer}_{slab}_{vtk_step}_{lod}_{quality}".replace(
            ":", "_")
        preset = ([] if quality == "default" else
                  ["--warp-tolerance", quality[len("warp="):]] if quality.startswith("warp=")
                  else ["--quality", quality])
        splat_ms, vtk_ms, splat_runs = [], [], []
        vtk = Vtk(mha, info, size, threads)
        cameras = None
        for rnd in range(a.rounds):
            run = self.splat(spec, renderer, size, threads, frames, save if rnd == 0 else [],
                             self.path(tag, "splat"), slab, lod, extra=preset)
            splat_runs.append(run)
            splat_ms += [f["ms"] for f in run["frames"]]
            cameras = run["frames"]
            vtk.render(cameras[0], vtk_step)  # warm-up: VTK builds its tables
            for f in cameras:
                vtk_ms.append(vtk.render(f, vtk_step))
                if rnd == 0 and f["frame"] in save:
                    vtk.save(self.path(tag, "vtk", f"frame_{f['frame']}.rgb8"))
        # Converged answers, once per volume and size.
        key = (name, size)
        splat_errors = size <= a.error_max_size and name not in FINER
        filtered_frames = [k for k in FILTERED.get(key, []) if k in save] \
            if splat_errors and not a.no_filtered and not a.quick else []
        filtered = self.filtered_refs(spec, size, frames, filtered_frames) \
            if filtered_frames else {}
        if key not in self.refs:
            ref_dir = self.path(f"{name}_{size}_ref".replace(":", "_"), "splat")
            t = time.perf_counter()
            ref_run = None
            if splat_errors:
                ref_run = self.splat(spec, "reference", size, threads, frames, save, ref_dir)
            ref_s = time.perf_counter() - t
            fine_dir = self.path(f"{name}_{size}_ref".replace(":", "_"), "vtk")
            os.makedirs(fine_dir, exist_ok=True)
            for f in cameras:
                if f["frame"] in save:
                    vtk.render(f, VTK_FINE_STEP)
                    vtk.save(os.path.join(fine_dir, f"frame_{f['frame']}.rgb8"))
            self.refs[key] = (ref_dir, fine_dir, ref_s)
            if ref_run:
                self.ref_times[key] = [(f["ms"], f["cpu_ms"]) for f in ref_run["frames"]]
        ref_dir, fine_dir, _ = self.refs[key]
        err_splat, err_vtk, cross, err_filtered, aliasing = [], [], [], [], []
        for k in save:
            s_img = self.path(tag, "splat", f"frame_{k}.f32")
            v_img = self.path(tag, "vtk", f"frame_{k}.rgb8")
            if splat_errors:
                err_splat.append(self.compare(s_img, os.path.join(ref_dir, f"frame_{k}.f32"),
                                              size))
            if k in filtered:
                err_filtered.append(self.compare(s_img, filtered[k], size))
                aliasing.append(self.compare(os.path.join(ref_dir, f"frame_{k}.f32"),
                                             filtered[k], size))
            err_vtk.append(self.compare(v_img, os.path.join(fine_dir, f"frame_{k}.rgb8"), size))
            cross.append(self.compare(s_img, os.path.join(fine_dir, f"frame_{k}.rgb8"), size))
        last = splat_runs[-1]["frames"]
        self.pixels_per_voxel[(name, size)] = max(splat_runs[-1]["spacing"]) / last[0]["pixel_size"]
        fp = statistics.median(f["footprint_pixels"] / (f["ms"] * 1e-3) for f in last)
        stage = {s: statistics.median(f[s] for f in last)
                 for s in ("project_ms", "order_ms", "bin_ms", "tiles_ms")}
        row = {
            "volume": name, "size": size, "threads": threads, "renderer": renderer,
            "slab": slab, "lod": lod, "quality": quality, "vtk_step": vtk_step, "frames": frames, "rounds": a.rounds,
            "splat_ms": statistics.median(splat_ms), "vtk_ms": statistics.median(vtk_ms),
            "splat_rmse_frames": save if err_splat else [],
            "splat_rmse": statistics.mean(e["rmse"] for e in err_splat) if err_splat else None,
            # Against the pixel-filtered reference (FILTER_SIGMA), frames filtered_frames only;
            # "point_ref_vs_filtered": the point-sampled reference's own error (the aliasing).
            "splat_rmse_filtered": statistics.mean(e["rmse"] for e in err_filtered)
            if err_filtered else None,
            "point_ref_vs_filtered": statistics.mean(e["rmse"] for e in aliasing)
            if aliasing else None,
            "filtered_frames": sorted(filtered),
            "lod_levels": sorted({f.get("lod_level", 0) for f in last}),
            "vtk_rmse": statistics.mean(e["rmse"] for e in err_vtk),
            "splat_vs_vtk_rmse": statistics.mean(e["rmse"] for e in cross),
            "splats": splat_runs[-1]["splats"],
            # Splats of the level rendered (level of detail: the merged level's).
            "splats_rendered": statistics.median(f.get("lod_splats") or splat_runs[-1]["splats"]
                                                 for f in last),
            "splat_bytes": splat_runs[-1]["splat_bytes"],
            "footprint_pixels": statistics.median(f["footprint_pixels"] for f in last),
            "footprint_px_per_s": fp,
            "culled_splats": statistics.median(f["culled_splats"] for f in last),
            "stages_ms": stage,
        }
        row["ratio"] = row["splat_ms"] / row["vtk_ms"]
        print(f"  {name} {size}^2 {threads}T {label(row)} vs VTK step {vtk_step}: "
              f"splat {row['splat_ms']:.0f} ms, VTK {row['vtk_ms']:.0f} ms, "
              f"ratio {row['ratio']:.2f}", file=sys.stderr)
        return row

    def fill(self):
        return run_json([f"{self.bin}/bench_fill", "--box", "7", "--seconds",
                         "0.5" if self.args.quick else "1", "--threads-list", "1,2"])

    def fill_best(self, samples):
        """The fill limit from several bench_fill runs spread over the benchmark: per thread
        count the fastest (a ceiling; a busy moment on a shared machine only lowers it), with
        every sample kept."""
        best = dict(samples[0])
        per = {}
        for s in samples:
            for r in s["runs"]:
                per.setdefault(r["threads"], []).append(r["px_per_s"])
        best["runs"] = [dict(r, px_per_s=max(per[r["threads"]])) for r in samples[0]["runs"]]
        best["samples"] = {str(k): v for k, v in per.items()}
        return best

    def memory(self):
        """Peak RSS (KiB, /usr/bin/time -f %M) of `splat --version` and of an axis-aligned
        `splat render ch2 --size 512x512` with the benchmark's transfer function (and with
        `--lod auto` when the binary has it)."""
        timer = "/usr/bin/time"
        if not os.access(timer, os.X_OK) or not os.path.exists(CH2):
            return None
        out = {}
        render = [f"{self.bin}/splat", "render", CH2, "--tf", self.tf, "--size", "512x512",
                  "--threads", "2", "-o", self.path("memory", "ch2.png")]
        runs = [("baseline_kib", [f"{self.bin}/splat", "--version"]), ("render_kib", render)]
        if self.lod_auto:
            runs.append(("render_lod_auto_kib", render + ["--lod", "auto"]))
        for key, cmd in runs:
            r = subprocess.run([timer, "-f", "%M"] + cmd, capture_output=True, text=True)
            if r.returncode != 0:
                sys.exit(f"vs_vtk: {' '.join(cmd)} failed: {r.stderr.strip()}")
            out[key] = int(r.stderr.strip().splitlines()[-1])
        ch2 = self.volumes.get("ch2")
        out["volume_float_kib"] = ch2[2]["float_bytes"] // 1024 if ch2 else 181 * 217 * 181 * 4 // 1024
        out["over_baseline_in_volumes"] = (out["render_kib"] - out["baseline_kib"]) / out["volume_float_kib"]
        if "render_lod_auto_kib" in out:
            out["lod_auto_over_baseline_in_volumes"] = \
                (out["render_lod_auto_kib"] - out["baseline_kib"]) / out["volume_float_kib"]
        return out

    def supports_lod_auto(self):
        """True when this build's `--lod` accepts `auto` (bench_frames parses the option with
        `splat render`'s own code)."""
        r = subprocess.run([f"{self.bin}/bench_frames", "render", "synthetic:phantom:16", self.tf,
                            "--size", "16", "--frames", "1", "--lod", "auto"],
                           capture_output=True, text=True)
        return r.returncode == 0

    def aliasing(self, case):
        """One aliasing case (ALIASING): the pixel-filtered and the point-sampled reference of
        frame 1 of a 12-frame rotation, and the splatter settings of the case, each timed over
        the rotation (median) and compared with both references on frame 1."""
        name, spec, tf, mode, size, settings = case
        frames, k = self.args.frames, 1
        tag = f"aliasing_{name}_{mode}_{size}".replace(":", "_").replace(" ", "_")
        tf_arg = tf if tf != "bench" else None
        filtered = self.filtered_refs(spec, size, frames, [k], tf=tf_arg, mode=mode)[k]
        ref_dir = self.path(tag, "ref", "x")
        ref_dir = os.path.dirname(ref_dir)
        ref = self.splat(spec, "reference", size, 2, frames, [k], ref_dir, tf=tf_arg,
                         extra=["--mode", mode])
        point = os.path.join(ref_dir, f"frame_{k}.f32")
        rows = []
        for i, (renderer, opts) in enumerate(settings):
            lod = "0"
            extra = ["--mode", mode]
            for o, v in opts:
                if o == "--lod":
                    lod = v
                else:
                    extra += [o, v]
            if lod == "auto" and not self.lod_auto:
                rows.append({"case": name, "renderer": renderer, "options": opts,
                             "skipped": "this build's --lod has no 'auto'"})
                continue
            out = self.path(tag, f"s{i}", "x")
            out = os.path.dirname(out)
            run = self.splat(spec, renderer, size, 2, frames, [k], out, lod=lod, extra=extra,
                             tf=tf_arg)
            img = os.path.join(out, f"frame_{k}.f32")
            fr = run["frames"]
            rows.append({
                "case": name, "mode": mode, "size": size, "renderer": renderer, "options": opts,
                "ms": statistics.median(f["ms"] for f in fr),
                "rmse_point": self.compare(img, point, size)["rmse"],
                "rmse_filtered": self.compare(img, filtered, size)["rmse"],
                "lod_levels": sorted({f.get("lod_level", 0) for f in fr}),
            })
        f1 = ref["frames"][0]
        result = {"case": name, "spec": spec, "mode": mode, "size": size, "frame": k,
                  "pixel_size": f1["pixel_size"],
                  "pixels_per_voxel": max(ref["spacing"]) / f1["pixel_size"], "rows": rows,
                  "point_ref_vs_filtered": self.compare(point, filtered, size)["rmse"],
                  "reference_ms": f1["ms"]}
        for r in rows:
            if "ms" in r:
                print(f"  aliasing {name} {mode} {size}^2 {r['renderer']} {r['options']}: "
                      f"{r['ms']:.0f} ms, RMSE point {r['rmse_point']:.2e}, filtered "
                      f"{r['rmse_filtered']:.2e}", file=sys.stderr)
        return result

    def reference_time(self):
        """The reference ray caster on ch2 with mri-head at 256^2 (the popping sweep's frames):
        wall and CPU ms of frames 1 and 4 of the rotation."""
        run = self.splat(CH2, "reference", 256, 2, self.args.frames, [1, 4],
                         os.path.dirname(self.path("reftime", "x")), tf="mri-head")
        return [{"frame": f["frame"], "ms": f["ms"], "cpu_ms": f["cpu_ms"]} for f in run["frames"]]

    def sweep(self):
        """The whole popping job (SWEEP), timed from outside, with its per-renderer
        median and total from summary.json."""
        report = os.path.dirname(self.path("sweep", "report", "x"))
        cmd = [f"{self.bin}/splat", "popping", CH2] + SWEEP + ["--threads", "2", "--report",
                                                                report, "-q"]
        t = time.perf_counter()
        r = subprocess.run(cmd, capture_output=True, text=True)
        wall = time.perf_counter() - t
        if r.returncode != 0:
            sys.exit(f"vs_vtk: {' '.join(cmd)} failed ({r.returncode}): {r.stderr.strip()}")
        summary = json.load(open(os.path.join(report, "summary.json")))
        per = {k: {"ms_per_frame": v["ms_per_frame"], "total_ms": v["total_ms"]}
               for k, v in summary["renderers"].items()}
        return {"command": "splat popping ch2 " + " ".join(SWEEP), "wall_s": wall,
                "views": summary["sweep"]["views"], "renderers": per,
                "analysis_total_ms": summary["timings"]["total_ms"]}

    def accuracy(self):
        """bench_accuracy ch2 mri-head 256^2, azimuths 30 and 45 (COMMON accuracy check;
        --truth point: the point-sampled reference the baseline was measured against):
        {renderer label: [RMSE per azimuth]}."""
        exe = f"{self.bin}/bench_accuracy"
        if not os.access(exe, os.X_OK) or not os.path.exists(CH2):
            return None
        r = subprocess.run([exe, CH2, "mri-head", "--size", "256", "--azimuths", "30,45",
                            "--truth", "point"],
                           capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(f"vs_vtk: bench_accuracy failed: {r.stderr.strip()}")
        out = {}
        for line in r.stdout.splitlines():
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if len(cells) == 6 and cells[1] in ACCURACY_BASELINE:
                out.setdefault(cells[1], []).append(float(cells[2]))
        return out


def file_id(spec):
    """What identifies a volume file's content for the cache: size and modification time."""
    if spec and os.path.exists(spec):
        st = os.stat(spec)
        return [st.st_size, int(st.st_mtime)]
    return None


# Level of detail (Quality::lod) for the rows where voxels are smaller than pixels: `--lod 1`
# always, `--lod auto` (error-driven) when the build has it.
LOD_ROWS = [("ch2", 256), ("phantom:256", 256), ("phantom:512", 512)]
LOD_AUTO_ROWS = [("ch2", 256), ("ch2", 512), ("ch2", 1024), ("phantom:512", 512),
                 ("ch2 0.5 mm", 512)]

# The pixel-filtered reference: Gaussian pixel filter of FILTER_SIGMA pixels (docs/accuracy.md
# "Aliasing and EWA"), for the (volume, size) rows where voxels are smaller than pixels, frames
# listed (of the 12-frame rotation; 1 = azimuth 30, 4 = azimuth 120). ch2 256^2: 0.76 pixels per
# voxel, 15 s per filtered frame (4 x 4 rays per pixel); phantom:512 512^2: 0.58, 46 s per frame (8
# x 8), under chrt on the 2-core machine.
FILTER_SIGMA = 0.5
FILTERED = {("ch2", 256): [1, 4], ("phantom:256", 256): [1, 4], ("phantom:512", 512): [1, 4]}

# Aliasing cases (splat alone, no VTK): (name, volume, transfer function ("bench": the
# benchmark's), mode, image size, [(renderer, options)]). X-ray below a pixel per voxel is
# where EWA applies (`--ewa auto` turns it on there); the dvr case shows it off.
EWA_SETTINGS = [("axis", [("--ewa", "off")]), ("axis", [("--ewa", "on")]),
                ("axis", [("--ewa", "auto")]), ("sheet", [("--ewa", "off")]),
                ("sheet", [("--ewa", "on")]), ("axis", [("--lod", "1")]),
                ("axis", [("--lod", "auto")])]
ALIASING = [
    ("marschner-lobb:128", "synthetic:marschner-lobb:128", "gray-ramp", "xray", 128, EWA_SETTINGS),
    ("phantom:256", "synthetic:phantom:256", "ct-soft", "xray", 256, EWA_SETTINGS),
    ("ch2", CH2, "bench", "dvr", 256, [("axis", [("--ewa", "off")]), ("axis", [("--ewa", "on")]),
                                       ("axis", [("--ewa", "auto")])]),
]
ALIASING_QUICK = [("marschner-lobb:32", "synthetic:marschner-lobb:32", "gray-ramp", "xray", 32,
                   [("axis", [("--ewa", "off")]), ("axis", [("--ewa", "on")])])]

# The popping sweep of ch2 over 0-90 degrees at 1-degree steps, timed as a whole job.
SWEEP = ["--tf", "mri-head", "--size", "256x256", "--from", "0", "--to", "90", "--step", "1"]

# The accuracy check: bench_accuracy ch2 mri-head --size 256 --azimuths 30,45 as recorded when
# the performance work on the splatters began; every later change must keep these or lower them.
ACCURACY_BASELINE = {"axis": [5.69e-4, 6.06e-4], "sheet, slab 1": [3.51e-4, 3.57e-4],
                     "sheet, slab 0.5": [3.93e-4, 3.99e-4]}

VOLUMES = {
    "ch2": CH2,
    "phantom:256": "synthetic:phantom:256",
    "phantom:512": "synthetic:phantom:512",
    "ch2 0.5 mm": None,  # FINER
}

# Volumes made by resampling another one `factor` times finer on the same world extent
# (refine_metaimage): "ch2 0.5 mm" is ch2's 1 mm grid trilinearly interpolated at half-voxel
# steps (361 x 433 x 361, 8x the voxels). splat's error against its reference is not measured
# for them (the reference ray caster would take minutes per frame); VTK's is.
FINER = {"ch2 0.5 mm": ("ch2", 2)}


def metaimage_header(raw):
    """The "Key = Value" header of a MetaImage with LOCAL data, and where the data start."""
    end = raw.index(b"ElementDataFile = LOCAL\n") + len(b"ElementDataFile = LOCAL\n")
    return dict(line.split(" = ", 1) for line in raw[:end].decode().splitlines()), end


def write_metaimage(path, header, data):
    keys = ["ObjectType", "NDims", "BinaryData", "BinaryDataByteOrderMSB", "CompressedData",
            "TransformMatrix", "Offset", "ElementSpacing", "DimSize", "ElementType"]
    text = "".join(f"{k} = {header[k]}\n" for k in keys if k in header)
    with open(path, "wb") as f:
        f.write((text + "ElementDataFile = LOCAL\n").encode())
        f.write(data)


def vtk_world_frame(mha, info):
    """Rewrites the exported MetaImage in splat's world frame for VTK. bench_frames export
    writes ITK's LPS convention (x and y negated, TransformMatrix diag(-1, -1, 1) for a
    volume splat holds axis-aligned), which vtkMetaImageReader does not apply: VTK would
    place the volume beside the camera splat's frames describe. Splat's own frame (origin,
    positive spacing, identity directions) is what the cameras are in."""
    with open(mha, "rb") as f:
        raw = f.read()
    header, end = metaimage_header(raw)
    m = [float(x) for x in header.get("TransformMatrix", "1 0 0 0 1 0 0 0 1").split()]
    flip = (-1.0, -1.0, 1.0)
    direction = [[m[3 * a + r] * flip[r] for r in range(3)] for a in range(3)]
    if any(abs(direction[a][r] - (a == r)) > 1e-9 for a in range(3) for r in range(3)):
        sys.exit(f"vs_vtk: {mha}: oblique or permuted directions are not supported")
    header["TransformMatrix"] = "1 0 0 0 1 0 0 0 1"
    header["Offset"] = " ".join(f"{x:.17g}" for x in info["origin"])
    write_metaimage(mha, header, raw[end:])


def refine_metaimage(src, dst, factor):
    """Writes `dst`, the float MetaImage `src` (as bench_frames export writes it) sampled
    `factor` times finer along each axis by trilinear interpolation, on the same world box:
    (n - 1) factor + 1 samples per axis, spacing / factor, the same offset and directions
    (the original samples are kept, every value lies between its neighbours)."""
    import numpy as np
    with open(src, "rb") as f:
        raw = f.read()
    header, end = metaimage_header(raw)
    dims = [int(x) for x in header["DimSize"].split()]
    spacing = [float(x) / factor for x in header["ElementSpacing"].split()]
    v = np.frombuffer(raw, dtype="<f4", offset=end).reshape(dims[2], dims[1], dims[0])
    for axis in range(3):
        n = v.shape[axis]
        t = np.arange((n - 1) * factor + 1) / factor
        i0 = np.minimum(np.floor(t).astype(int), n - 2)
        w = (t - i0).astype(np.float32)
        shape = [1, 1, 1]
        shape[axis] = len(t)
        w = w.reshape(shape)
        v = np.take(v, i0, axis=axis) * (1 - w) + np.take(v, i0 + 1, axis=axis) * w
    header["DimSize"] = " ".join(str(n) for n in v.shape[::-1])
    header["ElementSpacing"] = " ".join(f"{s:.17g}" for s in spacing)
    write_metaimage(dst, header, v.astype("<f4").tobytes())


def label(r):
    """A row's splat renderer as the tables name it."""
    rend = r["renderer"] if r["renderer"] == "axis" else f"{r['renderer']} slab {r['slab']:g}"
    if r.get("quality", "default").startswith("warp="):  # factorised sheets, edge tiles
        rend = f"{r['renderer']} --warp-tolerance {r['quality'][len('warp='):]}"
    elif r.get("quality", "default") != "default":  # the preset sets the slab itself
        rend = f"{r['renderer']} --quality {r['quality']}"
    return rend + (f" lod {r['lod']}" if str(r.get("lod", "0")) != "0" else "")


def plan(quick, lod_auto, presets_only=False):
    """(volume, size, threads, renderer, slab, VTK step, level of detail[, --quality preset
    or warp=T for --warp-tolerance T]) per row."""
    if quick:
        return [("ch2", 256, 2, "axis", 1.0, 1.0, "0"), ("ch2", 256, 2, "axis", 1.0, 1.0, "0", "fast")]
    if presets_only:
        return [r for s in (256, 512) for r in preset_rows(s)]
    rows = [("ch2", s, 2, "axis", 1.0, 1.0) for s in (256, 512, 1024)]
    rows += [("ch2", 512, 2, "axis", 1.0, 0.5), ("ch2", 512, 2, "axis", 1.0, 0.25),
             ("ch2", 512, 2, "sheet", 1.0, 0.25),
             ("ch2", 512, 1, "axis", 1.0, 1.0), ("ch2", 512, 1, "sheet", 1.0, 0.25)]
    rows += [("phantom:256", s, 2, "axis", 1.0, 1.0) for s in (256, 512, 1024)]
    rows += [("phantom:512", 512, 2, "axis", 1.0, 1.0)]
    rows += [("ch2 0.5 mm", 512, 2, "axis", 1.0, 1.0)]
    rows = [r + ("0",) for r in rows]
    rows += [(v, s, 2, "axis", 1.0, 1.0, "1") for v, s in LOD_ROWS]
    if lod_auto:
        rows += [(v, s, 2, "axis", 1.0, 1.0, "auto") for v, s in LOD_AUTO_ROWS]
    rows += [r for s in (256, 512) for r in preset_rows(s)[1:]]
    # Factorised sheets with per-splat edge tiles (docs/speed-vs-accuracy.md).
    rows += [("ch2", s, 2, "axis", 1.0, 1.0, "0", "warp=0.01") for s in (256, 512, 1024)]
    rows += [("phantom:512", 512, 2, "axis", 1.0, 1.0, "0", "warp=0.01")]
    return rows


def preset_rows(size):
    """The --quality rows of ch2 at size^2: today's default and the fast preset, axis."""
    return [("ch2", size, 2, "axis", 1.0, 1.0, "0"), ("ch2", size, 2, "axis", 1.0, 1.0, "0", "fast")]


def fmt_rate(x):
    return f"{x / 1e6:.0f} M/s"


def fmt_duration(s):
    return f"{s:.0f} s" if s < 120 else f"{s / 60:.0f} min"


def fmt_e(x):
    return "–" if x is None else f"{x:.1e}"


def accuracy_check(result):
    """bench_accuracy's RMSE on ch2 (mri-head, 256², azimuths 30 and 45) against the recorded
    ACCURACY_BASELINE, as one line: a change that makes a splatter less accurate shows here."""
    acc = result.get("accuracy")
    if not acc:
        return None
    ok, parts = True, []
    for name, base in ACCURACY_BASELINE.items():
        got = acc.get(name)
        if not got:
            ok = False
            parts.append(f"{name}: missing")
            continue
        ok = ok and all(g <= b * 1.005 for g, b in zip(got, base))
        parts.append(f"{name} {' / '.join(f'{g:.2e}' for g in got)} "
                     f"(baseline {' / '.join(f'{b:.2e}' for b in base)})")
    return ("**Accuracy check** (`bench_accuracy` ch2 mri-head 256², azimuths 30, 45): "
            + "; ".join(parts) + (": not worse than the baseline." if ok
                                  else ": WORSE than the baseline."))


def markdown(result):
    rows, fill, mem = result["rows"], result["fill"], result["memory"]
    limit = {r["threads"]: r["px_per_s"] for r in fill["runs"]}
    run = result["run"]
    out = [f"Measured in one run of `{run['command']}` ({fmt_duration(run['seconds'])} in all; "
           f"{run['when']}, commit `{run['commit']}`, {run['cores']} cores, load average "
           f"{run['load_before']:.1f} before and {run['load_after']:.1f} after; "
           f"{'real-time priority (`chrt -f 50`)' if run['realtime'] else 'normal priority'}). "
           "Generated by the command; `python3 tools/bench/update_perf_doc.py perf.md` puts it "
           "here.",
           ""]
    out.append("| volume | image | px per voxel | threads | splat renderer | VTK step (voxels) "
               "| splat ms | VTK ms | splat / VTK | splat RMSE, point ref. | splat RMSE, filtered "
               "ref. | VTK RMSE | splat vs VTK | splats | footprint px/s | fill limit |")
    out.append("|---|---|---:|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for r in rows:
        out.append(
            f"| {r['volume']} | {r['size']}² | {r.get('pixels_per_voxel', 0):.2f} "
            f"| {r['threads']} | {label(r)} | {r['vtk_step']:g} "
            f"| {r['splat_ms']:.0f} | {r['vtk_ms']:.0f} | **{r['ratio']:.2f}×** "
            f"| {fmt_e(r['splat_rmse'])} | {fmt_e(r.get('splat_rmse_filtered'))} "
            f"| {r['vtk_rmse']:.1e} | {r['splat_vs_vtk_rmse']:.1e} "
            f"| {r.get('splats_rendered', r['splats']) / 1e6:.2f} M "
            f"| {fmt_rate(r['footprint_px_per_s'])} "
            f"| {fmt_rate(limit.get(r['threads'], 0))} |")
    out.append("")
    fr = sorted({(r["volume"], r["size"], tuple(r["filtered_frames"])) for r in rows
                 if r.get("filtered_frames")})
    out.append("Errors are RMSE of RGB over black. *Point ref.*: against splat's reference ray "
               f"caster with one ray per pixel centre, frame{'s' if len(result['error_frames']) > 1 else ''} "
               f"{', '.join(map(str, result['error_frames']))} "
               f"of the {result['frames']}-frame rotation (images up to {result['error_max_size']}²). "
               f"*Filtered ref.*: against the pixel-filtered reference (`--renderer reference "
               f"--pixel-filter {FILTER_SIGMA:g}`, [Aliasing and EWA](accuracy.md#aliasing-and-ewa)), "
               "the judge where voxels are smaller than pixels, computed for " +
               ("; ".join(f"{v} {s}² frame{'s' if len(f) > 1 else ''} {', '.join(map(str, f))}"
                          for v, s, f in fr) if fr else "no row in this run") +
               " (20–84 reference frames each, cached between runs); "
               "“–”: not measured. Rows `lod L` render with level of detail (`--lod L`); their "
               "“splats” column counts the level rendered.")
    out.append("")
    out.append("Work per frame (splat, medians over the last round): splats culled before or "
               "during the sweep, footprint-box pixels rasterised, and the stage times "
               "(axis: project and bin run per slab inside the sweep and are reported together).")
    out.append("")
    out.append("| volume | image | threads | splat renderer | culled splats | footprint px "
               "| project ms | bin ms | tiles ms | fill time at the limit ms |")
    out.append("|---|---|---|---|---:|---:|---:|---:|---:|---:|")
    for r in rows:
        st = r["stages_ms"]
        lim = limit.get(r["threads"], 0)
        out.append(
            f"| {r['volume']} | {r['size']}² | {r['threads']} | {label(r)} "
            f"| {r['culled_splats'] / 1e6:.2f} M | {r['footprint_pixels'] / 1e6:.1f} M "
            f"| {st['project_ms']:.0f} | {st['bin_ms']:.0f} | {st['tiles_ms']:.0f} "
            f"| {1e3 * r['footprint_pixels'] / lim if lim else 0:.0f} |")
    out.append("")
    samples = fill.get("samples", {})
    out.append(f"Fill limit (`build/bin/bench_fill --box {fill['box']}`, a minimal AVX2 "
               "footprint-accumulate kernel, 7×7-pixel boxes into a 32×32 tile; the fastest of "
               "runs at the start, middle and end of the benchmark): " +
               ", ".join(f"{fmt_rate(r['px_per_s'])} on {r['threads']} thread"
                         f"{'s' if r['threads'] > 1 else ''}"
                         + (f" (runs: {', '.join(fmt_rate(x) for x in samples[str(r['threads'])])})"
                            if str(r["threads"]) in samples else "")
                         for r in fill["runs"]) + ".")
    if mem:
        out.append("")
        line = (f"Memory (`/usr/bin/time -f %M`): `splat --version` {mem['baseline_kib'] / 1024:.0f} MiB, "
                f"`splat render ch2 --size 512x512` (axis) {mem['render_kib'] / 1024:.0f} MiB = "
                f"baseline + {mem['over_baseline_in_volumes']:.1f}× the volume's "
                f"{mem['volume_float_kib'] / 1024:.0f} MiB of floats")
        if "render_lod_auto_kib" in mem:
            line += (f"; with `--lod auto` {mem['render_lod_auto_kib'] / 1024:.0f} MiB = baseline + "
                     f"{mem['lod_auto_over_baseline_in_volumes']:.1f}×")
        out.append(line + ".")
    if not result.get("lod_auto"):
        out.append("")
        out.append("`--lod auto` rows: skipped, this build's `--lod` does not accept `auto`.")
    al = result.get("aliasing") or []
    if al:
        out.append("")
        out.append(f"**Aliasing: EWA and level of detail against the filtered reference** "
                   f"(splat alone; frame 1 of the rotation, azimuth {360 / result['frames']:g}°, "
                   f"elevation {ELEVATION:g}°; ms: median over the {result['frames']}-frame "
                   "rotation, 2 threads; *point ref.* row: the point-sampled reference's own "
                   "error against the filtered one, i.e. the aliasing):")
        out.append("")
        out.append("| volume, mode, image | px per voxel | splat renderer | options | ms/frame "
                   "| RMSE, point ref. | RMSE, filtered ref. |")
        out.append("|---|---:|---|---|---:|---:|---:|")
        for c in al:
            head = f"{c['case']}, {c['mode']}, {c['size']}²"
            out.append(f"| {head} | {c['pixels_per_voxel']:.2f} | point ref. | – "
                       f"| {c['reference_ms']:.0f} | – | {c['point_ref_vs_filtered']:.3g} |")
            for r in c["rows"]:
                opts = " ".join(f"`{o} {v}`" for o, v in r["options"])
                rend = r["renderer"] + (" slab 1" if r["renderer"] == "sheet" else "")
                if "skipped" in r:
                    out.append(f"| {head} | | {rend} | {opts} | – | – | – ({r['skipped']}) |")
                    continue
                lvl = r.get("lod_levels", [0])
                if any(lvl):
                    opts += f" (level {'/'.join(map(str, lvl))})"
                out.append(f"| {head} | | {rend} | {opts} | {r['ms']:.0f} "
                           f"| {r['rmse_point']:.3g} | {r['rmse_filtered']:.3g} |")
    ref = result.get("reference_time")
    sweep = result.get("sweep")
    if sweep or ref:
        out.append("")
        out.append("**Whole-job time.**")
        out.append("")
    if sweep:
        per = sweep["renderers"]
        out.append(f"`{sweep['command']} --threads 2` ({sweep['views']} views, every renderer): "
                   f"**{sweep['wall_s']:.0f} s** wall for the whole job (the analyser's own render "
                   f"total {sweep['analysis_total_ms'] / 1e3:.0f} s).")
        out.append("")
        out.append("| renderer | median ms per frame | total s |")
        out.append("|---|---:|---:|")
        for k, v in per.items():
            out.append(f"| {k} | {v['ms_per_frame']:.0f} | {v['total_ms'] / 1e3:.1f} |")
    elif result.get("sweep_skipped"):
        out.append("The popping sweep was skipped in this run (`--no-sweep`).")
    if ref:
        out.append("")
        out.append("The reference ray caster per ch2 256² frame (`mri-head`, frames " +
                   ", ".join(str(f["frame"]) for f in ref) + "): " +
                   ", ".join(f"{f['ms'] / 1e3:.2f} s wall / {f['cpu_ms'] / 1e3:.2f} s CPU"
                             for f in ref) + " (2 threads).")
    comp = result.get("filtered_computed") or []
    if comp:
        out.append("")
        out.append("Filtered references used (σ = "
                   f"{FILTER_SIGMA:g} pixels; s × s rays per pixel where the doubling stopped, "
                   "its last relative change; time of the run that made it, cached ones from an "
                   "earlier run):")
        out.append("")
        out.append("| volume | mode | image | frame | s | last change | wall s | CPU s | |")
        out.append("|---|---|---|---:|---:|---:|---:|---:|---|")
        seen = set()
        for c in comp:
            k = (c["volume"], c["mode"], c["size"], c["frame"])
            if k in seen:
                continue
            seen.add(k)
            vol = "ch2" if c["volume"] == CH2 else c["volume"].replace("synthetic:", "")
            out.append(f"| {vol} | {c['mode']} | {c['size']}² | {c['frame']} "
                       f"| {c['pixel_samples']} | {c['pixel_filter_change']:.2g} "
                       f"| {c['ms'] / 1e3:.0f} | {c['cpu_ms'] / 1e3:.0f} "
                       f"| {'cached' if c['cached'] else 'computed'} |")
    check = accuracy_check(result)
    if check:
        out.append("")
        out.append(check)
    parts = result.get("part_seconds") or {}
    if parts:
        out.append("")
        out.append("Run time by part: " + ", ".join(f"{k} {v:.0f} s" for k, v in parts.items())
                   + ".")
    return "\n".join(out) + "\n"


def git_commit():
    r = subprocess.run(["git", "describe", "--always", "--dirty"], capture_output=True, text=True)
    return r.stdout.strip() or "unknown"


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--quick", action="store_true", help="CI smoke run (< 60 s)")
    p.add_argument("--build", default="build", help="CMake build folder (default: build)")
    p.add_argument("--json", help="write the results here")
    p.add_argument("--markdown", help="write the tables here (default: stdout only)")
    p.add_argument("--doc", help="also replace the generated block of this document, e.g. "
                   "splat/docs/performance.md (tools/bench/update_perf_doc.py)")
    p.add_argument("--keep", action="store_true", help="keep the images (prints their folder)")
    p.add_argument("--rounds", type=int, default=None,
                   help="splat/VTK interleaved rounds per row (default 2, --quick 1)")
    p.add_argument("--error-max-size", type=int, default=512,
                   help="largest image side whose splat error is measured (the reference ray "
                        "caster is slow; default 512)")
    p.add_argument("--presets-only", action="store_true",
                   help="only the --quality rows (ch2 at 256² and 512², default and fast)")
    p.add_argument("--no-sweep", action="store_true",
                   help="skip the popping sweep (ch2 0-90 degrees at 256^2, minutes)")
    p.add_argument("--no-filtered", action="store_true",
                   help="skip the pixel-filtered references (and the aliasing table)")
    p.add_argument("--cache", help="folder of the cached filtered references "
                   "(default BUILD/bench-cache)")
    p.add_argument("--from-json", metavar="FILE",
                   help="no run: write the tables of an earlier run's --json FILE again")
    args = p.parse_args()
    if args.from_json:
        with open(args.from_json) as f:
            table = markdown(json.load(f))
        sys.stdout.write(table)
        if args.markdown:
            with open(args.markdown, "w") as f:
                f.write(table)
        if args.doc:
            sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
            import update_perf_doc
            update_perf_doc.update(args.doc, table)
        return 0
    ensure_vtk()
    args.frames = 4 if args.quick else 12
    if args.rounds is None:
        args.rounds = 1 if args.quick else 2
    args.error_frames = [1] if args.quick else [1, 4]
    args.cache = args.cache or os.path.join(args.build, "bench-cache")
    bench = Bench(args)
    start = time.perf_counter()
    load_before = os.getloadavg()[0]
    parts = {}

    def part(name, fn):
        t = time.perf_counter()
        print(f"vs_vtk: {name}", file=sys.stderr)
        value = fn()
        parts[name] = time.perf_counter() - t
        return value

    try:
        bench.lod_auto = bench.supports_lod_auto()
        fills = [part("fill limit", bench.fill)]
        rows = part("splat and VTK", lambda: [bench.config(*row)
                                              for row in plan(args.quick, bench.lod_auto,
                                                              args.presets_only)])
        result = {"transfer_function": TF, "elevation": ELEVATION, "frames": args.frames,
                  "rounds": args.rounds, "error_frames": args.error_frames,
                  "error_max_size": args.error_max_size, "vtk_fine_step": VTK_FINE_STEP,
                  "filter_sigma": FILTER_SIGMA, "lod_auto": bench.lod_auto, "rows": rows}
        fills.append(bench.fill())
        result["memory"] = None if args.quick else part("memory", bench.memory)
        if not args.no_filtered:
            cases = ALIASING_QUICK if args.quick else ALIASING
            result["aliasing"] = part("aliasing", lambda: [bench.aliasing(c) for c in cases])
        if not args.quick:
            result["reference_time"] = part("reference time", bench.reference_time)
            result["accuracy"] = part("accuracy", bench.accuracy)
            if args.no_sweep:
                result["sweep_skipped"] = True
            else:
                result["sweep"] = part("popping sweep", bench.sweep)
        fills.append(bench.fill())
        result["fill"] = bench.fill_best(fills)
        result["filtered_computed"] = bench.computed
        result["part_seconds"] = parts
        result["run"] = {
            "command": "bash tools/bench.sh " + " ".join(os.environ.get("BENCH_ARGS", " ".join(
                sys.argv[1:])).split()),
            "seconds": time.perf_counter() - start,
            "when": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
            "commit": git_commit(), "cores": os.cpu_count(),
            "load_before": load_before, "load_after": os.getloadavg()[0],
            "realtime": os.sched_getscheduler(0) == os.SCHED_FIFO}
        for r in rows:
            r["pixels_per_voxel"] = bench.pixels_per_voxel.get((r["volume"], r["size"]), 0)
    finally:
        if args.keep:
            print(f"vs_vtk: images kept in {bench.tmp}", file=sys.stderr)
        else:
            shutil.rmtree(bench.tmp, ignore_errors=True)
    table = markdown(result)
    sys.stdout.write(table)
    if args.markdown:
        with open(args.markdown, "w") as f:
            f.write(table)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(result, f, indent=1)
    if args.doc:
        sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
        import update_perf_doc
        update_perf_doc.update(args.doc, table)
    print(f"vs_vtk: done in {time.perf_counter() - start:.0f} s", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
