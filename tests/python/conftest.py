# The Python module's tests (docs/python.md), run by ctest as python.pytest with
# PYTHONPATH=build/python and SPLAT_EXE (the CLI they compare with).
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import splat

CH2 = Path("/usr/share/mricron/templates/ch2.nii.gz")
SRC = Path(os.environ.get("SPLAT_SOURCE", Path(__file__).resolve().parents[2]))


def _exe() -> str:
    exe = os.environ.get("SPLAT_EXE")
    if not exe:
        exe = str(SRC / "build" / "bin" / "splat")
    assert Path(exe).exists(), f"the splat CLI ({exe}) is needed: set SPLAT_EXE"
    return exe


@pytest.fixture(scope="session")
def cli():
    """Runs `splat ARGS...`; returns the CompletedProcess (text)."""
    exe = _exe()

    def run(*args, check=True):
        p = subprocess.run([exe, *map(str, args)], capture_output=True, text=True)
        if check and p.returncode != 0:
            raise AssertionError(f"splat {' '.join(map(str, args))}: {p.returncode}\n{p.stderr}")
        return p

    return run


@pytest.fixture
def tmp(tmp_path):
    return tmp_path


@pytest.fixture(scope="session")
def phantom():
    return splat.synthetic("phantom", 24)


def same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    """Bit-for-bit equality of two float32 arrays (NaN payloads and -0 included)."""
    a = np.ascontiguousarray(a, dtype=np.float32)
    b = np.ascontiguousarray(b, dtype=np.float32)
    return a.shape == b.shape and np.array_equal(a.view(np.uint32), b.view(np.uint32))


def run_python(code: str, timeout=120) -> subprocess.CompletedProcess:
    """Runs `code` in a fresh interpreter with the same module path."""
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=timeout, env=dict(os.environ))
