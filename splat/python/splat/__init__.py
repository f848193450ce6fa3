"""splat: splatting volume renderer, from Python (docs/python.md).

Volumes are NumPy arrays indexed [z, y, x] (x fastest in memory, as scikit-image and
SimpleITK); spacing and origin are given (x, y, z). Keyword arguments are the command line's
long options with '-' written '_' (``--pixel-size 0.5`` -> ``pixel_size=0.5``, ``--size 512x512``
-> ``size=(512, 512)``, ``--shade`` -> ``shade=True``); they accept and refuse exactly what
the flags do, with the same one-line messages. Images are H x W x 4 float32 arrays,
premultiplied RGBA, row 0 on top: the pixels ``splat render ... -o x.exr`` writes.

Every render and analysis releases the GIL (threads render in parallel), takes
``progress=callable(done, total, what)`` (return False to stop: splat.Cancelled), and stops
within a tile on Ctrl-C (KeyboardInterrupt), writing nothing.
"""
from __future__ import annotations

import json
import numbers
import os
import warnings

import numpy as np

from . import _splat
from ._splat import (Cancelled, Error, FileError, Gaussians, InputError, Mesh, PoppingResult,
                     StudyResult, TransferFunction, Volume, default_window, flip_map,
                     iso_surface, list_dicom_series, load_gaussians, read_image,
                     render_gaussians, study_knobs, synthetic_names, write_heatmap, write_image)

__version__ = _splat.__version__

__all__ = [
    "Cancelled", "Error", "FileError", "Gaussians", "InputError", "Mesh", "PoppingResult",
    "Scene", "StudyResult", "TransferFunction", "Volume", "compare", "default_window",
    "flip_map", "from_nibabel", "iso_surface", "list_dicom_series", "load", "load_gaussians",
    "load_options", "load_scene", "popping", "read_image", "render", "render_gaussians",
    "render_options", "render_scene", "rotate", "save_scene", "study", "study_knobs",
    "synthetic", "synthetic_names", "write_heatmap", "write_image", "zarr_level",
]

# Options taking "WxH" / "XxYxZ" text; every other sequence is joined with commas.
_X_JOINED = {"size", "dims"}


def _name(key: str) -> str:
    """A keyword's option name: pixel_size -> pixel-size, from_ -> from."""
    return key.rstrip("_").replace("_", "-")


def _number(v) -> str:
    if isinstance(v, (bool, np.bool_)):
        raise InputError(f"expected a number, got {v!r}")
    if isinstance(v, numbers.Integral):
        return str(int(v))
    if isinstance(v, numbers.Real):
        return repr(float(v))
    raise InputError(f"expected a number, got {v!r}")


def _text(key: str, value) -> str:
    if isinstance(value, str):
        return value
    if isinstance(value, (numbers.Real, np.generic)) and not isinstance(value, (bool, np.bool_)):
        return _number(value)
    if isinstance(value, (list, tuple, np.ndarray)):
        if key in _X_JOINED:
            return "x".join(str(int(v)) for v in value)
        return ",".join(v if isinstance(v, str) else _number(v) for v in value)
    raise InputError(f"{key}=: unsupported value {value!r}")


def _argv(options: dict) -> tuple[list[tuple[str, str]], str]:
    """Keyword arguments as (option name, text) pairs, read by the library's option table,
    and a transfer function object as the project's JSON (read like a scene file's inline
    "tf")."""
    argv: list[tuple[str, str]] = []
    tf_json = ""
    for key, value in options.items():
        if value is None:
            continue
        if key == "tf" and isinstance(value, dict):  # a scene file's inline transfer function
            tf_json = json.dumps(value)
            continue
        if key == "tf" and not isinstance(value, str):
            tf = value if isinstance(value, TransferFunction) else TransferFunction(value)
            tf_json = tf.to_json()
            continue
        name = _name(key)
        if isinstance(value, (bool, np.bool_)):
            if value:
                argv.append((name, "true"))
            continue
        if (key == "clip_plane" and isinstance(value, (list, tuple)) and value
                and all(isinstance(v, (list, tuple, np.ndarray, str)) for v in value)):
            for v in value:  # repeatable: clip_plane=[(x, y, z, nx, ny, nz), ...]
                argv.append((name, _text(key, v)))
            continue
        argv.append((name, _text(key, value)))
    return argv, tf_json


def _option_doc(table) -> str:
    lines = []
    for keyword, flag, help_text, default in table:
        d = f" (default {default})" if default not in ("", "[]") else ""
        lines.append(f"  {keyword}: {help_text}{d}   [{flag}]")
    return "\n".join(lines)


def render_options() -> list[str]:
    """The keyword names render, Scene, popping and study take (the CLI's render options)."""
    return [k for k, *_ in _splat._render_options()]


def load_options() -> list[str]:
    """The keyword names load takes (the CLI's volume options)."""
    return [k for k, *_ in _splat._load_options() if k != "volume"]


def load(path: str, **options) -> Volume:
    return _splat._load(str(path), _argv(options)[0])


load.__doc__ = f"""load(path, **options) -> Volume

Loads every format the CLI reads: .nii/.nii.gz (NIfTI-1/2, ANALYZE), .nrrd/.nhdr, .mhd/.mha,
.raw/.raw.gz, .dcm, a folder of DICOM files or 2-D slices, or 'synthetic:NAME[:N]'.
Options (the CLI's volume options):
{_option_doc([t for t in _splat._load_options() if t[0] != 'volume'])}
"""


def zarr_level(path: str, **options) -> int:
    """The level of the OME-Zarr image `path` that splat's level-of-detail rule picks for the
    view of `options` (render's keywords: size, lod, mode, renderer, camera ...), as
    `splat render` reads by default (docs/input-files.md "Choosing a level"):
    load(path, zarr_level=zarr_level(path, **options)) reads only that level's chunks."""
    argv, tf_json = _argv(options)
    return _splat._zarr_level(str(path), argv, tf_json)


def synthetic(name: str, size: int | None = None) -> Volume:
    """A synthetic volume, as load('synthetic:NAME[:N]'): see synthetic_names()."""
    return load(f"synthetic:{name}" + (f":{int(size)}" if size else ""))


def from_nibabel(img, *, background_value: float | None = None,
                 nan_policy: str = "error") -> Volume:
    """A Volume from a nibabel image: its data ([x, y, z], scaled by scl_slope/scl_inter as
    nibabel does) placed by img.affine with the loaders' rule (axis flips and permutations
    applied, an oblique rest named in notes), so that from_nibabel(nibabel.load(f)) equals
    splat.load(f). 4-D images: the first volume."""
    proxy = img.dataobj
    slope = getattr(proxy, "slope", 1.0)
    inter = getattr(proxy, "inter", 0.0)
    trivial = (slope in (1.0, None) or np.isnan(slope) or slope == 0) and inter in (0.0, None)
    data = np.asanyarray(proxy) if trivial else img.get_fdata()
    if data.ndim == 4:
        warnings.warn("from_nibabel: a 4-D image; its first volume is used", stacklevel=2)
        data = data[..., 0]
    source = f"nibabel {type(img).__name__} {np.asarray(data).dtype}"
    return _splat._from_affine(data, np.asarray(img.affine, dtype=np.float64), source,
                               background_value, nan_policy)


def _is_gaussians(scene) -> bool:
    """A Gaussians, or the path of a .ply or a 'gaussians:NAME' generator."""
    if isinstance(scene, Gaussians):
        return True
    if isinstance(scene, (str, os.PathLike)):
        name = os.fspath(scene)
        return name.lower().endswith(".ply") or name.startswith("gaussians:")
    return False


def _gaussians(scene) -> Gaussians:
    return scene if isinstance(scene, Gaussians) else load_gaussians(os.fspath(scene))


def _gaussian_argv(options: dict) -> list[tuple[str, str]]:
    argv, tf_json = _argv(options)
    if tf_json:
        raise InputError("tf= does not apply to a Gaussian scene (its colours are its own)")
    return argv


def render(volume: Volume, *, progress=None, return_stats: bool = False, **options):
    if _is_gaussians(volume):
        return _splat._render_gaussians(_gaussians(volume), _gaussian_argv(options), progress,
                                        return_stats)
    argv, tf_json = _argv(options)
    return _splat._render(volume, argv, tf_json, progress, return_stats)


_RENDER_DOC = _option_doc(_splat._render_options())

render.__doc__ = f"""render(volume, *, progress=None, return_stats=False, **options) -> ndarray

One frame: an H x W x 4 float32 array (premultiplied RGBA, row 0 on top), the pixels of
`splat render VOLUME [options] -o x.exr`. return_stats=True: (image, stats dict).
volume may be a Gaussian scene (splat.Gaussians, a .ply path or 'gaussians:NAME'): renderer
3dgs (default), 3dgs-pixel, sheet or reference, the camera options, slab (world units),
ref_tolerance and threads apply.
progress: callable(done, total, what) -> bool|None; False stops (splat.Cancelled).
Options (the CLI's render options):
{_RENDER_DOC}
"""


def load_scene(path: str) -> dict:
    """A scene file (docs/command-line.md "Scene files"), read by the library as `splat render
    --scene FILE` reads it, as keyword arguments: {"volume": spec, keyword: value, ...} (values
    as the option's text, relative paths resolved against the file's folder, an inline
    transfer function as a dict); a value its option refuses raises splat.InputError with the
    command line's line. Keys of the command line's own options (output, frames, ...) are no
    keywords: left out with a warning."""
    command, rows, others = _splat._read_scene(str(path))
    del command
    out: dict = {}
    for key, texts, obj in rows:
        if obj:
            out[key] = json.loads(obj)
        elif texts == ["true"] or texts == ["false"]:
            out[key] = texts[0] == "true"
        elif len(texts) == 1:
            out[key] = texts[0]
        elif texts:
            out[key] = list(texts)
    if others:
        warnings.warn(f"{path}: keys of the command line's own options, ignored: "
                      + ", ".join(others), stacklevel=2)
    return out


def _scene_keywords(path: str, overrides: dict) -> tuple[str, dict, dict]:
    """A scene file's volume, load keywords and render keywords, with `overrides` applied."""
    scene = load_scene(path)
    scene.update(overrides)
    volume = scene.pop("volume", None)
    if not volume:
        raise InputError(f'{path}: no "volume" (the volume or Gaussian scene to render)')
    loads = {k: scene.pop(k) for k in load_options() if k in scene}
    keywords = set(render_options())
    return volume, loads, {k: v for k, v in scene.items() if k in keywords}


def render_scene(path: str, *, progress=None, return_stats: bool = False, **overrides):
    """render_scene(path, **overrides): the frame `splat render --scene FILE` draws: the scene's
    volume loaded with its volume options and rendered with its render options (the options
    of the written image, such as window, concern files only); keyword arguments override the
    scene's, as flags do. A scene of a Gaussian scene: splat.render_gaussians."""
    volume, loads, keywords = _scene_keywords(path, overrides)
    if volume.endswith(".ply") or volume.startswith("gaussians:"):
        raise InputError(f"{path}: '{volume}' is a Gaussian scene: render it with "
                         "splat.render_gaussians(splat.load_gaussians(...)) or `splat render`")
    return render(load(volume, **loads), progress=progress, return_stats=return_stats,
                  **keywords)


def save_scene(path: str, volume: str, *, command: str = "render", **options) -> None:
    """Writes a scene file by the library, as `--write-scene` does: "volume" (made absolute)
    and every option of `command` (render, popping, ...) at the given keyword's value or its
    default. Values are checked as the flags are (splat.InputError)."""
    argv, tf_json = _argv(options)
    _splat._write_scene(str(path), command, str(volume), argv, tf_json)


class Scene:
    """Scene(volume, **options): the view-independent state of a rendering (classification,
    kernel tables), built once; render(**per_frame) draws any view with any renderer from it
    (renderer, camera, order, background, slab, ...; a per-scene knob such as tf or classify
    needs a new Scene). Thread-safe: several threads may render one Scene at once."""

    def __init__(self, volume: Volume, **options):
        self.options = dict(options)
        if _is_gaussians(volume):
            # A Gaussian scene has no view-independent state to build: frames render from it.
            self.volume = _gaussians(volume)
            _gaussian_argv(self.options)  # refuse what cannot apply, now
            self._scene = None
            return
        self.volume = volume
        argv, tf_json = _argv(self.options)
        self._scene = _splat._Scene(volume, argv, tf_json)

    def _frame(self, frame: dict) -> tuple[list[str], str]:
        return _argv({**self.options, **frame})

    def render(self, *, progress=None, return_stats: bool = False, **frame):
        """One frame from the Scene; keyword arguments as splat.render's override the
        Scene's for this frame."""
        if self._scene is None:
            return _splat._render_gaussians(self.volume,
                                            _gaussian_argv({**self.options, **frame}), progress,
                                            return_stats)
        argv, tf_json = self._frame(frame)
        return self._scene.render(argv, tf_json, progress, return_stats, False)

    def iso_depth(self, *, progress=None, **frame) -> np.ndarray:
        """Iso mode: per pixel the world distance to the first hit of the level (H x W;
        NaN where the ray misses)."""
        if self._scene is None:
            raise InputError("iso_depth applies to volumes, not Gaussian scenes")
        argv, tf_json = self._frame(frame)
        image = self._scene.render(argv, tf_json, progress, False, True)
        depth = image[..., 0].copy()
        depth[image[..., 3] == 0] = np.nan
        return depth

    def rotate(self, frames: int = 36, *, from_: float = 0.0, to: float | None = None,
               sweep: str = "azimuth", path: str | None = None, parallel_frames: int = 0,
               progress=None, batch: int = 8):
        """Frames of a turn about the volume (as `splat rotate`): `frames` views spaced
        evenly from from_ to `to`, both included (default: a loop, from_ + 360 (frames - 1) /
        frames), in azimuth or elevation, or along a camera path JSON file; yields the images
        in order, rendered `batch` views at a time."""
        if to is None:
            to = from_ + 360.0 * (int(frames) - 1) / max(1, int(frames))
        if self._scene is None:
            yield from self._rotate_gaussians(int(frames), float(from_), float(to), sweep, path,
                                              progress)
            return
        for first in range(0, int(frames), max(1, int(batch))):
            yield from self._scene.sequence(sweep, float(from_), float(to), int(frames),
                                            path or "", int(parallel_frames), first,
                                            max(1, int(batch)), progress)

    def _rotate_gaussians(self, frames, from_, to, sweep, path, progress):
        if path:
            raise InputError("rotate(path=) applies to volumes; render a Gaussian scene's "
                             "views with render(azimuth=..., elevation=...)")
        if sweep not in ("azimuth", "elevation"):
            raise InputError("--sweep must be azimuth or elevation")
        for n in range(frames):
            angle = from_ + (to - from_) * n / (frames - 1) if frames > 1 else from_
            yield self.render(progress=progress, **{sweep: angle})

    @property
    def splat_count(self) -> int:
        """Splats the classification kept (a Gaussian scene: its Gaussians)."""
        if self._scene is None:
            return len(self.volume)
        return self._scene.splat_count

    @property
    def transfer(self) -> TransferFunction:
        """The transfer function, resolved to absolute densities."""
        if self._scene is None:
            raise InputError("a Gaussian scene has no transfer function")
        return self._scene.transfer


Scene.__init__.__doc__ = "Scene(volume, **options); options as splat.render's:\n" + _RENDER_DOC


def rotate(volume: Volume, frames: int = 36, *, from_: float = 0.0, to: float | None = None,
           sweep: str = "azimuth", path: str | None = None, parallel_frames: int = 0,
           progress=None, **options):
    """Scene(volume, **options).rotate(...): an iterator of frames (`splat rotate`)."""
    return Scene(volume, **options).rotate(frames, from_=from_, to=to, sweep=sweep, path=path,
                                           parallel_frames=parallel_frames, progress=progress)


def compare(test, reference, *, flip: bool = True, ppd: float = 67.02064327658226) -> dict:
    """The CLI's `splat compare` metrics of `test` against `reference` (H x W x 4 or 3
    arrays, or image file names): rmse, psnr, max_abs, mean_abs_foreground,
    foreground_pixels and flip (mean LDR-FLIP at `ppd` pixels per degree; NaN when
    flip=False)."""
    display = (".png", ".jpg", ".jpeg", ".gif")
    # Display files hold sRGB values: FLIP decodes them first, as the CLI does.
    srgb = all(isinstance(x, str) and x.lower().endswith(display) for x in (test, reference))
    if isinstance(test, str):
        test = read_image(test)
    if isinstance(reference, str):
        reference = read_image(reference)
    return _splat._compare(test, reference, flip, ppd, srgb)


def popping(volume: Volume, *, progress=None, **options) -> PoppingResult:
    if _is_gaussians(volume):
        return _splat._popping_gaussians(_gaussians(volume), _gaussian_argv(options), progress)
    argv, tf_json = _argv(options)
    return _splat._popping(volume, argv, tf_json, progress)


popping.__doc__ = f"""popping(volume, *, progress=None, **options) -> PoppingResult

`splat popping`: renders a sweep with each renderer from one Scene, measures T, J, e, FLIP
per interval, finds and refines events. Sweep options (`from` is written from_):
""" + "\n".join(f"  {k.replace('-', '_') + ('_' if k == 'from' else '')}: {h}"
                for k, h in _splat._popping_options()) + f"""
Render options as splat.render's (renderer is replaced by renderers=).
volume may be a Gaussian scene (splat.Gaussians, a .ply path or 'gaussians:NAME'):
renderers= 3dgs, 3dgs-pixel, sheet, reference (default all four); the events are predicted
where two overlapping Gaussians' centre depths swap (result.predicted_switches).
result.write_report(folder) writes report.html, metrics.csv and summary.json.
"""


def study(volume: Volume, *, sweep=(), views=(), repeats: int = 5, warmup: int = 1,
          truth_step: float = 0.125, truth_tolerance: float = 1e-5, ppd: float = 67.0,
          convergence: bool = False, cache_dir: str | None = None, truth: str = "auto",
          progress=None, **options) -> StudyResult:
    """`splat study`: every combination of the swept knobs (sweep={'slab': [0.5, 1, 2]} or
    ['slab=0.5,1,2', ...]; knobs: study_knobs()), timed and compared with the reference ray
    caster; views: [(azimuth, elevation), ...]. truth: the reference each setting is judged
    against, 'point' | 'filtered' | 'auto' (filtered where the frames are: EWA on, e.g. xray
    below a pixel per voxel; each point's 'truth_filter' says which). Render options as
    splat.render's.
    result.write_report(folder) writes study.csv, study.json, pareto.svg, pareto.png."""
    if isinstance(sweep, dict):
        sweeps = [f"{k.replace('_', '-')}=" + ",".join(_text(k, v) if not isinstance(v, str)
                                                       else v for v in vs)
                  for k, vs in sweep.items()]
    else:
        sweeps = list(sweep)
    views = [(float(a), float(e)) for a, e in views]
    argv, tf_json = _argv(options)
    return _splat._study(volume, argv, tf_json, sweeps, views, int(repeats), int(warmup),
                         float(truth_step), float(truth_tolerance), float(ppd),
                         bool(convergence), cache_dir or "", str(truth), progress)
