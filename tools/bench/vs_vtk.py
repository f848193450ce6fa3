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

Usage:
  python3 tools/bench/vs_vtk.py [--quick] [--build build] [--json FILE] [--markdown FILE]
Needs build/bin/{bench_frames,bench_fill,splat} (cmake --build build --target bench_frames
bench_fill splat_cli) and python3-vtk9; without a display it re-runs itself under
xvfb-run (Debian: xvfb). Exit status: 0 done, 1 a step failed, 77 VTK (or a display) is not
available (the benchmark is skipped; VTK is never a dependency of the library or tests).
--quick (a CI smoke run, < 60 s): ch2 at 256^2, 4 frames, one round, one error frame.
"""
import argparse
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
    """VTK's fixed-point CPU ray caster set up like the issue's user would: the same
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

    def splat(self, spec, renderer, size, threads, frames, save, out, slab=1.0, lod=0.0):
        os.makedirs(out, exist_ok=True)
        return run_json([f"{self.bin}/bench_frames", "render", spec, self.tf, "--renderer",
                         renderer, "--slab", str(slab), "--size", str(size), "--threads",
                         str(threads), "--frames", str(frames), "--elevation", str(ELEVATION),
                         "--save", ",".join(map(str, save)), "--out", out,
                         "--warmup", "0" if renderer == "reference" else "1"]
                        + (["--lod", str(lod)] if lod > 0 else []))

    def compare(self, a, b, size):
        return run_json([f"{self.bin}/bench_frames", "compare", a, b, str(size), str(size)])

    def config(self, name, size, threads, renderer="axis", slab=1.0, vtk_step=1.0, lod=0.0):
        """One row: splat (renderer, slab, level of detail) and VTK (vtk_step voxels) on
        `name` at size^2."""
        a = self.args
        spec, mha, info = self.volume(name, VOLUMES[name])
        frames, save = a.frames, a.error_frames
        tag = f"{name}_{size}_{threads}_{renderer}_{slab}_{vtk_step}_{lod}".replace(":", "_")
        splat_ms, vtk_ms, splat_runs = [], [], []
        vtk = Vtk(mha, info, size, threads)
        cameras = None
        for rnd in range(a.rounds):
            run = self.splat(spec, renderer, size, threads, frames, save if rnd == 0 else [],
                             self.path(tag, "splat"), slab, lod)
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
        if key not in self.refs:
            ref_dir = self.path(f"{name}_{size}_ref".replace(":", "_"), "splat")
            t = time.perf_counter()
            if splat_errors:
                self.splat(spec, "reference", size, threads, frames, save, ref_dir)
            ref_s = time.perf_counter() - t
            fine_dir = self.path(f"{name}_{size}_ref".replace(":", "_"), "vtk")
            os.makedirs(fine_dir, exist_ok=True)
            for f in cameras:
                if f["frame"] in save:
                    vtk.render(f, VTK_FINE_STEP)
                    vtk.save(os.path.join(fine_dir, f"frame_{f['frame']}.rgb8"))
            self.refs[key] = (ref_dir, fine_dir, ref_s)
        ref_dir, fine_dir, _ = self.refs[key]
        err_splat, err_vtk, cross = [], [], []
        for k in save:
            s_img = self.path(tag, "splat", f"frame_{k}.f32")
            v_img = self.path(tag, "vtk", f"frame_{k}.rgb8")
            if splat_errors:
                err_splat.append(self.compare(s_img, os.path.join(ref_dir, f"frame_{k}.f32"),
                                              size))
            err_vtk.append(self.compare(v_img, os.path.join(fine_dir, f"frame_{k}.rgb8"), size))
            cross.append(self.compare(s_img, os.path.join(fine_dir, f"frame_{k}.rgb8"), size))
        last = splat_runs[-1]["frames"]
        fp = statistics.median(f["footprint_pixels"] / (f["ms"] * 1e-3) for f in last)
        stage = {s: statistics.median(f[s] for f in last)
                 for s in ("project_ms", "order_ms", "bin_ms", "tiles_ms")}
        row = {
            "volume": name, "size": size, "threads": threads, "renderer": renderer,
            "slab": slab, "lod": lod, "vtk_step": vtk_step, "frames": frames, "rounds": a.rounds,
            "splat_ms": statistics.median(splat_ms), "vtk_ms": statistics.median(vtk_ms),
            "splat_rmse": statistics.mean(e["rmse"] for e in err_splat) if err_splat else None,
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

    def memory(self):
        """Peak RSS (KiB, /usr/bin/time -f %M) of `splat --version` and of an axis-aligned
        `splat render ch2 --size 512x512` with the benchmark's transfer function."""
        timer = "/usr/bin/time"
        if not os.access(timer, os.X_OK) or not os.path.exists(CH2):
            return None
        out = {}
        for key, cmd in (("baseline_kib", [f"{self.bin}/splat", "--version"]),
                         ("render_kib", [f"{self.bin}/splat", "render", CH2, "--tf", self.tf,
                                         "--size", "512x512", "--threads", "2", "-o",
                                         self.path("memory", "ch2.png")])):
            r = subprocess.run([timer, "-f", "%M"] + cmd, capture_output=True, text=True)
            if r.returncode != 0:
                sys.exit(f"vs_vtk: {' '.join(cmd)} failed: {r.stderr.strip()}")
            out[key] = int(r.stderr.strip().splitlines()[-1])
        ch2 = self.volumes.get("ch2")
        out["volume_float_kib"] = ch2[2]["float_bytes"] // 1024 if ch2 else 181 * 217 * 181 * 4 // 1024
        out["over_baseline_in_volumes"] = (out["render_kib"] - out["baseline_kib"]) / out["volume_float_kib"]
        return out


# Level of detail (Quality::lod) for the rows where voxels are smaller than pixels.
LOD = 1.0
LOD_ROWS = [("ch2", 256), ("phantom:256", 256), ("phantom:512", 512)]

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
    return rend + (f" lod {r['lod']:g}" if r.get("lod", 0) > 0 else "")


def plan(quick):
    """(volume, size, threads, renderer, slab, VTK step, level of detail) per row."""
    if quick:
        return [("ch2", 256, 2, "axis", 1.0, 1.0, 0.0)]
    rows = [("ch2", s, 2, "axis", 1.0, 1.0) for s in (256, 512, 1024)]
    rows += [("ch2", 512, 2, "axis", 1.0, 0.5), ("ch2", 512, 2, "axis", 1.0, 0.25),
             ("ch2", 512, 2, "sheet", 1.0, 0.25),
             ("ch2", 512, 1, "axis", 1.0, 1.0), ("ch2", 512, 1, "sheet", 1.0, 0.25)]
    rows += [("phantom:256", s, 2, "axis", 1.0, 1.0) for s in (256, 512, 1024)]
    rows += [("phantom:512", 512, 2, "axis", 1.0, 1.0)]
    rows += [("ch2 0.5 mm", 512, 2, "axis", 1.0, 1.0)]
    rows = [r + (0.0,) for r in rows]
    rows += [(v, s, 2, "axis", 1.0, 1.0, LOD) for v, s in LOD_ROWS]
    return rows


def fmt_rate(x):
    return f"{x / 1e6:.0f} M/s"


def markdown(result):
    rows, fill, mem = result["rows"], result["fill"], result["memory"]
    limit = {r["threads"]: r["px_per_s"] for r in fill["runs"]}
    out = ["| volume | image | threads | splat renderer | VTK step (voxels) | splat ms | VTK ms "
           "| splat / VTK | splat RMSE | VTK RMSE | splat vs VTK | splats | footprint px/s "
           "| fill limit |",
           "|---|---|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        rend = label(r)
        out.append(
            f"| {r['volume']} | {r['size']}² | {r['threads']} | {rend} | {r['vtk_step']:g} "
            f"| {r['splat_ms']:.0f} | {r['vtk_ms']:.0f} | **{r['ratio']:.2f}×** "
            f"| {'–' if r['splat_rmse'] is None else format(r['splat_rmse'], '.1e')} "
            f"| {r['vtk_rmse']:.1e} | {r['splat_vs_vtk_rmse']:.1e} "
            f"| {r.get('splats_rendered', r['splats']) / 1e6:.2f} M "
            f"| {fmt_rate(r['footprint_px_per_s'])} "
            f"| {fmt_rate(limit.get(r['threads'], 0))} |")
    out.append("")
    out.append("Work per frame (splat, medians over the last round): splats culled before or "
               "during the sweep, footprint-box pixels rasterised, and the stage times "
               "(axis: project and bin run per slab inside the sweep and are reported together).")
    out.append("")
    out.append("| volume | image | threads | splat renderer | culled splats | footprint px "
               "| project ms | bin ms | tiles ms | fill time at the limit ms |")
    out.append("|---|---|---|---|---:|---:|---:|---:|---:|---:|")
    for r in rows:
        rend = label(r)
        st = r["stages_ms"]
        lim = limit.get(r["threads"], 0)
        out.append(
            f"| {r['volume']} | {r['size']}² | {r['threads']} | {rend} "
            f"| {r['culled_splats'] / 1e6:.2f} M | {r['footprint_pixels'] / 1e6:.1f} M "
            f"| {st['project_ms']:.0f} | {st['bin_ms']:.0f} | {st['tiles_ms']:.0f} "
            f"| {1e3 * r['footprint_pixels'] / lim if lim else 0:.0f} |")
    out.append("")
    out.append(f"Fill limit (`build/bin/bench_fill --box {fill['box']}`, a minimal AVX2 "
               "footprint-accumulate kernel, 7×7-pixel boxes into a 32×32 tile): " +
               ", ".join(f"{fmt_rate(r['px_per_s'])} on {r['threads']} thread"
                         f"{'s' if r['threads'] > 1 else ''}" for r in fill["runs"]) + ".")
    if mem:
        out.append("")
        out.append(f"Memory (`/usr/bin/time -f %M`): `splat --version` {mem['baseline_kib'] / 1024:.0f} MiB, "
                   f"`splat render ch2 --size 512x512` (axis) {mem['render_kib'] / 1024:.0f} MiB = "
                   f"baseline + {mem['over_baseline_in_volumes']:.1f}× the volume's "
                   f"{mem['volume_float_kib'] / 1024:.0f} MiB of floats.")
    return "\n".join(out) + "\n"


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--quick", action="store_true", help="CI smoke run (< 60 s)")
    p.add_argument("--build", default="build", help="CMake build folder (default: build)")
    p.add_argument("--json", help="write the results here")
    p.add_argument("--markdown", help="write the table here (default: stdout only)")
    p.add_argument("--keep", action="store_true", help="keep the images (prints their folder)")
    p.add_argument("--rounds", type=int, default=None,
                   help="splat/VTK interleaved rounds per row (default 2, --quick 1)")
    p.add_argument("--error-max-size", type=int, default=512,
                   help="largest image side whose splat error is measured (the reference ray "
                        "caster is slow; default 512)")
    args = p.parse_args()
    ensure_vtk()
    args.frames = 4 if args.quick else 12
    if args.rounds is None:
        args.rounds = 1 if args.quick else 2
    args.error_frames = [1] if args.quick else [1, 4]
    bench = Bench(args)
    start = time.perf_counter()
    try:
        rows = [bench.config(*row) for row in plan(args.quick)]
        result = {"transfer_function": TF, "elevation": ELEVATION, "frames": args.frames,
                  "rounds": args.rounds, "error_frames": args.error_frames,
                  "vtk_fine_step": VTK_FINE_STEP, "rows": rows, "fill": bench.fill(),
                  "memory": None if args.quick else bench.memory(),
                  "seconds": time.perf_counter() - start}
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
    return 0


if __name__ == "__main__":
    sys.exit(main())
