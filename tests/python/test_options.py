# The option table (splat/options.h) from Python: every keyword and every scene-file key read
# through the extension accepts and refuses the values its command-line flag does, with the same
# one-line message; and the extension links the library alone (no MPI, no IceT, no command-line
# code).
import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import splat
from splat import _splat

SPEC = "synthetic:phantom:8"


def trial_values(kind: str, default: str, is_path: bool) -> list:
    """The default, and values the option's type or checks refuse (as tests/test_options.cpp)."""
    values = [default] if default else []
    if kind == "flag":
        return [True]
    if kind == "real":
        return values + ["abc", "1e999"]
    if kind == "integer":
        return values + ["1.5", "100000"]
    if kind == "unsigned":
        return values + ["-1"]
    return values + ([] if is_path else ["?"])


def keyword(name: str) -> str:
    k = name.replace("-", "_")
    return k + "_" if k == "from" else k


def test_keywords_accept_and_refuse_like_the_flags(cli, tmp):
    phantom = splat.load(SPEC)
    out = tmp / "x.exr"
    refused = 0
    for name, kind, default, option_set, is_path in _splat._option_specs():
        if option_set not in ("volume", "render"):
            continue  # image options are no keywords; the sweep's: test_analysis.py
        for value in trial_values(kind, default, is_path):
            size = {} if name == "size" else {"size": (8, 8)}
            try:
                if option_set == "volume":
                    splat.render(splat.load(SPEC, **{keyword(name): value}), size=(8, 8))
                else:
                    splat.render(phantom, **size, **{keyword(name): value})
                continue  # accepted: the library's reading, which tests/test_options.cpp
                # runs against the flag and the scene key
            except splat.Error as e:
                error = str(e)
            args = ["render", SPEC, "-o", out] + ([] if name == "size" else ["--size", "8x8"])
            args += [f"--{name}"] if value is True else [f"--{name}", value]
            p = cli(*args, check=False)
            where = f"--{name} {value}: {p.stderr}"
            refused += 1
            assert p.returncode != 0, where
            assert p.stderr.strip().splitlines()[-1] == "splat: error: " + error, where
    assert refused > 40


def test_scene_keys_read_by_the_extension_say_what_the_command_line_says(cli, tmp):
    out = tmp / "x.exr"
    scene = tmp / "scene.json"
    refused = 0
    for name, kind, default, option_set, is_path in _splat._option_specs():
        if option_set not in ("volume", "render"):
            continue
        for value in trial_values(kind, default, is_path):
            keys = {"command": "render", "volume": SPEC, name: value}
            if name != "size":
                keys["size"] = "8x8"
            scene.write_text(json.dumps(keys))
            try:
                splat.render_scene(scene)
                continue  # accepted: tests/test_options.cpp runs the library's reading
                # against the command line's
            except splat.Error as e:
                error = str(e)
            p = cli("render", "--scene", scene, "-o", out, check=False)
            where = f"{name}: {value!r}: {p.stderr}"
            refused += 1
            assert p.returncode != 0, where
            assert p.stderr.strip().splitlines()[-1] == "splat: error: " + error, where
    assert refused > 40


def test_scenes_written_from_python_read_back(tmp):
    path = tmp / "view.json"
    splat.save_scene(path, SPEC, size=(16, 12), azimuth=30, shade=True, tf="ct-bone")
    written = json.loads(path.read_text())
    assert written["command"] == "render"
    assert written["volume"]["path"] == SPEC
    assert written["size"] == [16, 12] and written["azimuth"] == 30 and written["shade"] is True
    scene = splat.load_scene(path)
    assert scene["volume"] == SPEC and scene["size"] == "16x12" and scene["shade"] is True
    image = splat.render_scene(path)
    direct = splat.render(splat.load(SPEC), size=(16, 12), azimuth=30, shade=True, tf="ct-bone")
    assert np.array_equal(image, direct)
    # Keywords override the scene's keys, as flags do.
    assert splat.render_scene(path, size=(8, 8)).shape == (8, 8, 4)
    with pytest.raises(splat.InputError, match="--slab"):
        splat.save_scene(path, SPEC, slab="abc")


def test_the_extension_links_no_mpi_icet_or_command_line():
    ext = Path(_splat.__file__)
    ldd = shutil.which("ldd")
    if ldd is None:
        pytest.skip("no ldd")
    libraries = subprocess.run([ldd, str(ext)], capture_output=True, text=True,
                               check=True).stdout.lower()
    assert "libc.so" in libraries  # ldd read it
    for banned in ("libmpi", "icet", "libvtk"):
        assert banned not in libraries, banned
    # CLI11 is header-only: its classes (namespace CLI) would show in the symbols.
    assert b"N3CLI" not in ext.read_bytes()
