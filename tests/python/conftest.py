"""Shared fixtures for the Python-module tier (plain /usr/bin/python3, no bpy)."""
from pathlib import Path

import numpy as np
import pytest

ASSETS = Path(__file__).resolve().parents[2] / "assets"


def pytest_configure(config):
    # The sanitizer tier (./exsynth test --sanitize) runs with -m "not heavy":
    # tests that take more than ~20 s under ASan (measured) carry this mark.
    config.addinivalue_line("markers", "heavy: too slow for the sanitizer tier (still run in tier 2)")


def load_obj(path):
    """Tiny OBJ reader for tests (v and f lines, polygons fanned)."""
    verts, faces = [], []
    for line in Path(path).read_text().splitlines():
        parts = line.split()
        if not parts:
            continue
        if parts[0] == "v":
            verts.append([float(t) for t in parts[1:4]])
        elif parts[0] == "f":
            idx = [int(t.split("/")[0]) - 1 for t in parts[1:]]
            faces += [[idx[0], idx[k], idx[k + 1]] for k in range(1, len(idx) - 1)]
    return np.array(verts, np.float64), np.array(faces, np.int32)


def enclosed_volume(verts, faces):
    a, b, c = (verts[faces[:, k]] for k in range(3))
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def box(lo=(0, 0, 0), hi=(1, 1, 1)):
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    verts = np.array([[hi[0] if i & 1 else lo[0], hi[1] if i & 2 else lo[1], hi[2] if i & 4 else lo[2]]
                      for i in range(8)])
    quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
    faces = np.array([[q[0], q[1], q[2]] for q in quads] + [[q[0], q[2], q[3]] for q in quads], np.int32)
    return verts, faces


@pytest.fixture(scope="session")
def bunny():
    return load_obj(ASSETS / "meshes" / "bunny.obj")


@pytest.fixture
def cube():
    return box()
