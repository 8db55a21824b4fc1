"""Same output on 1 and on 8 threads (the machine has 2 cores): with_threads runs the engine's
parallel loops on exactly n threads, so these compare schedules the default never produces."""
import numpy as np
import pytest

from exsynth import _native


def on_1_and_8(fn):
    return _native.with_threads(1, fn), _native.with_threads(8, fn)


def test_voxelize_and_isosurface(bunny):
    one, many = on_1_and_8(lambda: _native.voxelize(*bunny, resolution=40, seed=3))
    np.testing.assert_array_equal(one["density"], many["density"])
    np.testing.assert_array_equal(one["sdf"], many["sdf"])
    v1, t1 = _native.with_threads(1, lambda: _native.isosurface(one["sdf"], one["origin"], one["voxel_size"]))
    v8, t8 = _native.with_threads(8, lambda: _native.isosurface(one["sdf"], one["origin"], one["voxel_size"]))
    np.testing.assert_array_equal(v1, v8)
    np.testing.assert_array_equal(t1, t8)


def test_direction_field_and_frames(bunny):
    verts, faces = bunny
    given = np.zeros_like(verts)
    given[::97] = [1.0, 0.0, 0.0]
    one, many = on_1_and_8(lambda: _native.diffuse_direction_field(verts, faces, given))
    np.testing.assert_array_equal(one, many)
    vox = _native.voxelize(verts, faces, resolution=32)
    f1, f8 = on_1_and_8(lambda: _native.volume_frames(vox["sdf"], vox["origin"], vox["voxel_size"], verts, one))
    for k in ("t", "n", "b"):
        np.testing.assert_array_equal(f1[k], f8[k])


def test_solid_and_image():
    ex = np.random.default_rng(4).random((24, 24, 3)).astype(np.float32)
    s1, s8 = on_1_and_8(lambda: _native.synthesize_solid(ex, size=16, levels=2, seed=7))
    np.testing.assert_array_equal(s1["solid"], s8["solid"])
    i1, i8 = on_1_and_8(lambda: _native.synthesize_image(ex, width=32, height=32, levels=2, seed=7))
    np.testing.assert_array_equal(i1["image"], i8["image"])


def test_pair_and_field_aligned_analogy():
    p1, p8 = on_1_and_8(lambda: _native.make_exemplar_pair("spikes", resolution=24, jitter=0.2, seed=5))
    np.testing.assert_array_equal(p1["a_prime"], p8["a_prime"])
    pair = _native.make_exemplar_pair("spikes", resolution=24)
    h = pair["voxel_size"]
    c = (np.arange(30) - 14.5) * h
    z, y, x = np.meshgrid(c, c, c, indexing="ij")
    b = (np.sqrt(x * x + y * y + z * z) - 10 * h).astype(np.float32)
    r = np.hypot(x, y) + 1e-9
    field = np.stack([-y / r, x / r, np.zeros_like(x)], -1).astype(np.float32)
    run = lambda: _native.synthesize_analogy(pair["a"], pair["a_prime"], b, field_a=pair["field"], field_b=field,
                                             voxel_size=h)
    a1, a8 = on_1_and_8(run)
    np.testing.assert_array_equal(a1["b_prime"], a8["b_prime"])
    assert a1["searched"] == a8["searched"] and a1["coherent"] == a8["coherent"]


def test_threads_argument_is_checked():
    with pytest.raises(_native.InvalidInputError, match="'threads' must be an integer between 1 and 256"):
        _native.with_threads(0, lambda: None)
    with pytest.raises(_native.InvalidInputError, match="'fn' must be callable"):
        _native.with_threads(2, 5)
    assert _native.with_threads(3, lambda: 42) == 42
