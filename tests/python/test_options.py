# The option table (splat/options.h) from Python: every keyword accepts and refuses the values
# its command-line flag does, with the same one-line message; and the extension links the
# library alone (no MPI, no IceT, no command-line code).
import shutil
import subprocess
from pathlib import Path

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
