"""exsynth._native.voxelize through the binding: results, GIL release,
progress, cancel, and every bad input with a message naming it."""
import threading
import time

import numpy as np
import pytest

from exsynth import _native
from conftest import box, enclosed_volume


def test_bunny_volume_and_layout(bunny):
    verts, faces = bunny
    res = _native.voxelize(verts, faces, resolution=96, padding=3)
    d, s, h = res["density"], res["sdf"], res["voxel_size"]
    assert d.dtype == np.float32 and d.flags["C_CONTIGUOUS"]
    assert d.shape == s.shape
    # The longest axis has resolution + 2 * padding voxels; arrays are (Z, Y, X).
    longest = int(np.argmax(verts.max(0) - verts.min(0)))
    assert d.shape[2 - longest] == 96 + 6
    assert 0.0 <= d.min() and d.max() <= 1.0
    truth = enclosed_volume(verts, faces)
    assert abs(d.sum(dtype=np.float64) * h**3 - truth) < 0.005 * truth
    # origin is the centre of voxel [0, 0, 0]: the padded grid is centred on the bbox.
    lo, hi = verts.min(0), verts.max(0)
    centre = res["origin"] + h * (np.array(d.shape[::-1]) - 1) / 2
    np.testing.assert_allclose(centre, (lo + hi) / 2, atol=1e-6)


@pytest.mark.parametrize("options", [dict(resolution=40, padding=3), dict(voxel_size=0.013, padding=0)])
def test_voxel_grid_is_the_grid_voxelize_makes(bunny, options):
    verts, faces = bunny
    res = _native.voxelize(verts, faces, compute_sdf=False, **options)
    v32 = verts.astype(np.float32)  # the voxelizer's mesh holds float32 positions
    grid = _native.voxel_grid(v32.min(0), v32.max(0), **options)
    assert grid["shape"] == res["density"].shape
    assert grid["voxel_size"] == res["voxel_size"]
    assert grid["origin"] == tuple(res["origin"])


@pytest.mark.parametrize("lo, hi, message", [
    ((1, 0, 0), (0, 1, 1), "lo <= hi"),
    ((0, 0, 0), (0, 0, 0), "zero size"),
    ((0, 0), (1, 1, 1), "'lo' must be 3 numbers"),
    ((0, 0, 0), (1, np.nan, 1), "'hi' must be finite"),
])
def test_voxel_grid_refuses_a_bad_box(lo, hi, message):
    with pytest.raises(ValueError, match=message):
        _native.voxel_grid(lo, hi)


def test_float32_int64_inputs_give_the_same_result(bunny):
    verts, faces = bunny
    a = _native.voxelize(verts.astype(np.float32), faces.astype(np.int64), resolution=24)
    b = _native.voxelize(verts.astype(np.float32), faces, resolution=24)
    np.testing.assert_array_equal(a["density"], b["density"])
    np.testing.assert_array_equal(a["sdf"], b["sdf"])


def test_sdf_is_positive_outside_and_measures_distance():
    verts, faces = box((-1, -1, -1), (1, 1, 1))
    res = _native.voxelize(verts, faces, resolution=20, padding=5)
    sdf, h, o = res["sdf"], res["voxel_size"], res["origin"]
    z, y, x = np.indices(sdf.shape)
    p = o + h * np.stack([x, y, z], -1)
    # Exact distance to a cube, signed.
    q = np.abs(p) - 1
    exact = np.linalg.norm(np.maximum(q, 0), axis=-1) + np.minimum(q.max(-1), 0)
    np.testing.assert_allclose(sdf, exact, atol=1e-5)


def test_compute_sdf_false_returns_none(cube):
    res = _native.voxelize(*cube, resolution=8, compute_sdf=False)
    assert res["sdf"] is None


def test_progress_cancel_and_gil_release(bunny):
    verts, faces = bunny
    ctx = _native.ExecContext()
    seen = []
    out = {}

    def work():
        try:
            out["res"] = _native.voxelize(verts, faces, resolution=400, ctx=ctx)
        except _native.CancelledError as e:
            out["err"] = e

    t = threading.Thread(target=work)
    t.start()
    # This loop only runs while the worker is inside C++ if the GIL is released.
    deadline = time.time() + 60
    while t.is_alive() and ctx.progress < 0.1 and time.time() < deadline:
        seen.append(ctx.stage)
        time.sleep(0.001)
    ctx.cancel()
    t.join()
    assert isinstance(out.get("err"), _native.CancelledError)
    assert isinstance(out["err"], _native.Error)
    assert ctx.cancelled and ctx.progress < 1.0
    assert any(s.startswith("voxelize") for s in seen)


def test_same_seed_same_output(bunny):
    a = _native.voxelize(*bunny, resolution=32, seed=3)
    b = _native.voxelize(*bunny, resolution=32, seed=3)
    np.testing.assert_array_equal(a["density"], b["density"])
    np.testing.assert_array_equal(a["sdf"], b["sdf"])


BAD_INPUTS = [
    # (description, vertices, faces, kwargs, exception, words the message must contain)
    ("float16 vertices", lambda v: v.astype(np.float16), None, {}, _native.InvalidInputError, ["vertices", "float32"]),
    ("2-column vertices", lambda v: v[:, :2].copy(), None, {}, _native.InvalidInputError, ["vertices", "V by 3"]),
    ("float faces", None, lambda f: f.astype(np.float32), {}, _native.InvalidInputError, ["faces", "int32"]),
    ("quad faces", None, lambda f: np.zeros((4, 4), np.int32), {}, _native.InvalidInputError, ["faces", "F by 3"]),
    ("NaN vertex", lambda v: np.where(np.arange(len(v))[:, None] == 2, np.nan, v), None, {},
     _native.InvalidInputError, ["vertex 2", "not finite"]),
    ("Inf vertex", lambda v: np.where(np.arange(len(v))[:, None] == 5, np.inf, v), None, {},
     _native.InvalidInputError, ["vertex 5", "not finite"]),
    ("face index out of range", None, lambda f: np.where(np.arange(len(f))[:, None] == 4, 99, f), {},
     _native.InvalidInputError, ["face 4", "99"]),
    ("negative face index", None, lambda f: np.where(np.arange(len(f))[:, None] == 1, -3, f), {},
     _native.InvalidInputError, ["face 1"]),
    ("empty mesh", lambda v: np.zeros((0, 3)), lambda f: np.zeros((0, 3), np.int32), {},
     _native.InvalidInputError, ["no vertices"]),
    ("no faces", None, lambda f: np.zeros((0, 3), np.int32), {}, _native.InvalidInputError, ["no faces"]),
    ("zero resolution", None, None, {"resolution": 0}, _native.InvalidInputError, ["resolution"]),
    ("negative resolution", None, None, {"resolution": -4}, _native.InvalidInputError, ["resolution"]),
    ("negative voxel size", None, None, {"voxel_size": -0.1}, _native.InvalidInputError, ["voxel_size"]),
    ("supersample 0", None, None, {"supersample": 0}, _native.InvalidInputError, ["supersample"]),
    ("over the memory budget", None, None, {"resolution": 2000, "memory_budget": 1 << 20},
     _native.OverBudgetError, ["memory budget", "resolution"]),
]


@pytest.mark.parametrize("case", BAD_INPUTS, ids=[c[0] for c in BAD_INPUTS])
def test_bad_input_is_rejected_with_a_message_naming_it(case, cube):
    _, fv, ff, kwargs, exc, words = case
    verts, faces = cube
    verts = fv(verts) if fv else verts
    faces = ff(faces) if ff else faces
    with pytest.raises(exc) as info:
        _native.voxelize(verts, faces, **kwargs)
    for w in words:
        assert w in str(info.value), f"{w!r} not in {str(info.value)!r}"


def test_exception_classes_map_to_python_builtins():
    assert issubclass(_native.InvalidInputError, ValueError)
    assert issubclass(_native.OverBudgetError, MemoryError)
    for cls in (_native.InvalidInputError, _native.OverBudgetError, _native.CancelledError):
        assert issubclass(cls, _native.Error) and issubclass(cls, RuntimeError)


def test_cancelled_context_stops_before_work(cube):
    ctx = _native.ExecContext()
    ctx.cancel()
    with pytest.raises(_native.CancelledError):
        _native.voxelize(*cube, resolution=8, ctx=ctx)


@pytest.mark.parametrize("vertices, faces, message", [
    (np.array([[0, 0, 0], [np.nan, 0, 0], [0, 1, 0]], np.float32), [[0, 1, 2]], r"vertex 1 of --b is not finite \(nan\)"),
    (np.eye(3), [[0, 1, 3]], "face 0 of --b refers to vertex 3 but the mesh has 3 vertices"),
    (np.eye(3), np.zeros((0, 3), np.int32), "--b has no faces"),
])
def test_validate_mesh_names_the_problem(vertices, faces, message):
    with pytest.raises(_native.InvalidInputError, match=message):
        _native.validate_mesh(np.asarray(vertices, np.float64), np.asarray(faces, np.int32), "--b")
    _native.validate_mesh(np.eye(3), np.array([[0, 1, 2]], np.int32))


def test_a_millionth_sized_mesh_voxelizes_and_meshes(bunny, tmp_path):
    """Voxels of ~1e-8 units: OpenVDB cannot hold such a transform, the engine
    meshes in index space; writing a .vdb is refused with what to do."""
    verts, faces = bunny
    tiny = verts * 1e-6
    grid = _native.voxelize(tiny, faces, resolution=24)
    assert grid["voxel_size"] < 1e-6
    v, f = _native.isosurface(grid["sdf"], grid["origin"], grid["voxel_size"])
    assert len(f) > 100
    extent = v.max(axis=0) - v.min(axis=0)
    np.testing.assert_allclose(extent, tiny.max(axis=0) - tiny.min(axis=0), rtol=0.15)
    with pytest.raises(_native.InvalidInputError, match="too small for an OpenVDB file.*scale the model up"):
        _native.write_vdb(str(tmp_path / "tiny.vdb"), {"sdf": grid["sdf"]}, grid["origin"], grid["voxel_size"])
    assert not (tmp_path / "tiny.vdb").exists()
