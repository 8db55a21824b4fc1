"""Volume files and isosurfaces through the binding."""
import numpy as np
import pytest

from exsynth import _native
from conftest import enclosed_volume


def test_vdb_round_trip_keeps_values_and_transform(tmp_path, bunny):
    res = _native.voxelize(*bunny, resolution=24)
    path = str(tmp_path / "bunny.vdb")
    _native.write_vdb(path, {"density": res["density"], "sdf": res["sdf"]}, res["origin"], res["voxel_size"])
    back = _native.read_vdb(path)
    assert set(back["grids"]) == {"density", "sdf"}
    assert back["voxel_size"] == pytest.approx(res["voxel_size"])
    sdf = back["grids"]["sdf"]  # every sdf voxel is active, so the box is the whole grid
    np.testing.assert_allclose(sdf, res["sdf"], atol=1e-6)
    np.testing.assert_allclose(back["origin"], res["origin"], atol=1e-9)
    np.testing.assert_allclose(back["grids"]["density"], res["density"], atol=1e-6)


def test_vec3_and_multichannel_grids(tmp_path):
    rng = np.random.default_rng(0)
    color = rng.random((4, 5, 6, 3), dtype=np.float32) + 0.1
    path = str(tmp_path / "c.vdb")
    _native.write_vdb(path, {"color": color}, [1.0, 2.0, 3.0], 0.5)
    back = _native.read_vdb(path, ["color"])
    np.testing.assert_allclose(back["grids"]["color"], color, atol=1e-6)
    np.testing.assert_allclose(back["origin"], [1.0, 2.0, 3.0])


@pytest.mark.parametrize("grids, words", [
    ({}, ["grids", "empty"]),
    ({"d": np.zeros((2, 2), np.float32)}, ["'d'", "(Z, Y, X)"]),
    ({"d": np.full((2, 2, 2), np.nan, np.float32)}, ["'d'", "NaN"]),
    ({"d": [[1.0]]}, ["'d'", "(Z, Y, X)"]),  # a list is converted by NumPy, then its shape is checked
    ({"d": "dense"}, ["'d'", "NumPy array"]),
])
def test_write_vdb_rejects_bad_grids(tmp_path, grids, words):
    with pytest.raises(_native.InvalidInputError) as info:
        _native.write_vdb(str(tmp_path / "x.vdb"), grids, [0, 0, 0], 1.0)
    for w in words:
        assert w in str(info.value)


def test_write_vdb_rejects_bad_transform(tmp_path):
    g = {"d": np.ones((2, 2, 2), np.float32)}
    with pytest.raises(_native.InvalidInputError, match="voxel_size"):
        _native.write_vdb(str(tmp_path / "x.vdb"), g, [0, 0, 0], 0.0)
    with pytest.raises(_native.InvalidInputError, match="origin"):
        _native.write_vdb(str(tmp_path / "x.vdb"), g, [0, 0], 1.0)


def test_read_vdb_names_missing_file_and_grid(tmp_path):
    with pytest.raises(_native.IoError, match="nope.vdb"):
        _native.read_vdb(str(tmp_path / "nope.vdb"))
    path = str(tmp_path / "a.vdb")
    _native.write_vdb(path, {"density": np.ones((2, 2, 2), np.float32)}, [0, 0, 0], 1.0)
    with pytest.raises(_native.InvalidInputError, match="temperature"):
        _native.read_vdb(path, ["temperature"])


def test_isosurface_of_voxelized_bunny_encloses_its_volume(bunny):
    verts, faces = bunny
    res = _native.voxelize(verts, faces, resolution=64)
    v, t = _native.isosurface(res["sdf"], res["origin"], res["voxel_size"])
    assert v.dtype == np.float32 and t.dtype == np.int32 and t.max() < len(v)
    truth = enclosed_volume(verts, faces)
    assert enclosed_volume(v.astype(np.float64), t) == pytest.approx(truth, rel=0.03)
    # Same surface from the density at 0.5 with outside = below.
    v2, t2 = _native.isosurface(res["density"], res["origin"], res["voxel_size"], isovalue=0.5, invert=True)
    assert enclosed_volume(v2.astype(np.float64), t2) == pytest.approx(truth, rel=0.03)


def test_isosurface_rejects_bad_input():
    with pytest.raises(_native.InvalidInputError, match="volume"):
        _native.isosurface(np.zeros((3, 3), np.float32), [0, 0, 0], 1.0)
    with pytest.raises(_native.InvalidInputError, match="adaptivity"):
        _native.isosurface(np.zeros((3, 3, 3), np.float32), [0, 0, 0], 1.0, adaptivity=2.0)


def test_gaussian_pyramid_halves_and_keeps_constants():
    vol = np.full((9, 8, 7), 0.25, np.float32)
    levels = _native.gaussian_pyramid(vol, levels=3)
    assert [lv.shape for lv in levels] == [(9, 8, 7), (5, 4, 4), (3, 2, 2)]
    for lv in levels:
        np.testing.assert_allclose(lv, 0.25, atol=1e-6)
    with pytest.raises(_native.InvalidInputError, match="levels"):
        _native.gaussian_pyramid(vol, levels=0)


def test_file_errors_are_oserrors(tmp_path):
    """I/O failures are OSError (IoError), not bad input (InvalidInputError)."""
    with pytest.raises(_native.IoError, match="not found") as missing:
        _native.read_vdb(str(tmp_path / "nope.vdb"))
    assert isinstance(missing.value, OSError) and isinstance(missing.value, _native.Error)
    with pytest.raises(OSError, match="cannot write vdb file"):
        _native.write_vdb(str(tmp_path), {"density": np.ones((2, 2, 2), np.float32)}, (0, 0, 0), 1.0)
