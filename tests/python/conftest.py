"""Shared fixtures of the Python module's tests: the repository's data, the tailor command, a
scratch folder (pytest's tmp_path) and meshes made in numpy."""
import os
import pathlib
import subprocess

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
DATA = ROOT / "tests" / "data"
SPOT = ROOT / "examples" / "spot.obj"
GRAVEL = ROOT / "examples" / "gravel.png"


@pytest.fixture(scope="session")
def tailor_binary():
    """The tailor command built beside the module (ctest passes it in TAILOR_BINARY)."""
    path = os.environ.get("TAILOR_BINARY")
    if not path or not os.path.exists(path):
        pytest.skip("TAILOR_BINARY is not set (ctest sets it)")
    return path


def run_cli(binary, *args):
    """Runs the tailor command; returns (exit code, stdout, stderr)."""
    done = subprocess.run([binary, *map(str, args)], capture_output=True, text=True)
    return done.returncode, done.stdout, done.stderr


def bumpy_grid(n):
    """An n x n grid of vertices over a wavy height field: 2 (n - 1)^2 counter-clockwise faces."""
    x, y = np.meshgrid(np.linspace(0, 4, n), np.linspace(0, 4, n), indexing="ij")
    z = 0.3 * np.sin(2.5 * x) * np.cos(3.0 * y) + 0.1 * np.sin(7 * x + 3 * y)
    positions = np.stack([x, y, z], axis=-1).reshape(-1, 3).astype(np.float32)
    i = (np.arange(n - 1)[:, None] * n + np.arange(n - 1)[None, :]).ravel()
    a, b, c, d = i, i + n, i + n + 1, i + 1
    faces = np.concatenate([np.stack([a, b, c], -1), np.stack([a, c, d], -1)]).astype(np.uint32)
    return positions, faces
