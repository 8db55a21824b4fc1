"""exsynth._native.model_thickness: the thickness Geometric Texture's default
pattern size comes from, against shapes of known thickness (the brute-force
reference on exact triangle distances is in tests/cpp/test_thickness.cpp)."""
import numpy as np
import pytest

from exsynth import _native

from conftest import ASSETS, box, load_obj


def cylinder(r, length, n=48):
    a = 2 * np.pi * np.arange(n) / n
    ring = np.stack([r * np.cos(a), r * np.sin(a)], axis=1)
    verts = np.concatenate([np.c_[ring, np.zeros(n)], np.c_[ring, np.full(n, length)],
                            [[0, 0, 0], [0, 0, length]]])
    faces = []
    for i in range(n):
        j = (i + 1) % n
        faces += [[i, j, n + j], [i, n + j, n + i], [2 * n, j, i], [2 * n + 1, n + i, n + j]]
    return verts, np.array(faces, np.int32)


def test_slab_and_cylinder_measure_their_thin_side():
    slab = _native.model_thickness(*box((0, 0, 0), (2.0, 1.5, 0.2)), resolution=96)
    assert slab["thickness"] == pytest.approx(0.2, abs=slab["voxel_size"])
    tube = _native.model_thickness(*cylinder(0.25, 3.0), resolution=96)
    assert tube["thickness"] == pytest.approx(0.5, abs=1.5 * tube["voxel_size"])
    for r in (slab, tube):
        assert r["low"] <= r["median"] <= r["high"] and r["samples"] > 500
        assert r["median"] == r["thickness"]  # the default percentile is the median
        assert r["pattern_size"] == pytest.approx(2 * r["thickness"])


def test_percentile_picks_among_the_samples():
    verts, faces = cylinder(0.25, 3.0)
    lo = _native.model_thickness(verts, faces, resolution=64, percentile=0)
    hi = _native.model_thickness(verts, faces, resolution=64, percentile=100)
    mid = _native.model_thickness(verts, faces, resolution=64)
    assert lo["thickness"] <= mid["low"] <= mid["thickness"] <= mid["high"] <= hi["thickness"]


def test_thin_limbs_measure_thinner_than_the_bounding_box():
    """The armadillo (thin limbs and ears): its median thickness is well
    below half of its longest side, the old default pattern size."""
    verts, faces = load_obj(ASSETS / "meshes" / "armadillo.obj")
    r = _native.model_thickness(verts, faces, resolution=96)
    longest = float((verts.max(axis=0) - verts.min(axis=0)).max())
    assert 0.05 * longest < r["thickness"] < 0.3 * longest
    assert r["low"] < r["thickness"] < r["high"]


def test_bad_input_names_the_argument():
    verts, faces = box()
    with pytest.raises(_native.InvalidInputError, match="resolution"):
        _native.model_thickness(verts, faces, resolution=8)
    with pytest.raises(_native.InvalidInputError, match="percentile"):
        _native.model_thickness(verts, faces, percentile=150)
    flat = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float), np.array([[0, 1, 2]], np.int32)
    with pytest.raises(_native.InvalidInputError, match="no inside"):
        _native.model_thickness(*flat, resolution=32)
