"""Volume analogies through the binding, on the bundled bunny."""
import numpy as np
import pytest

from exsynth import _native


def inside(sdf, h):
    return float((sdf < 0).sum()) * h**3


@pytest.mark.heavy  # 15-50 s under ASan; the C++ tier covers the analogy there
def test_dilation_pair_grows_the_voxelized_bunny(bunny):
    pair = _native.make_exemplar_pair("dilate", resolution=32)
    h = pair["voxel_size"]  # 2 / 32: the pair spans [-1, 1]^3
    verts, faces = bunny
    # Scale the bunny so that 40 voxels of the pair's size span it.
    verts = verts * (40 * h / (verts.max(0) - verts.min(0)).max())
    b = _native.voxelize(verts, faces, resolution=40, padding=4)["sdf"]
    res = _native.synthesize_analogy(pair["a"], pair["a_prime"], b, voxel_size=h)
    bp = res["b_prime"]
    assert bp.shape == b.shape and bp.dtype == np.float32
    assert res["culled"] > 0 and res["searched"] > 0
    # The pair dilates by 0.15 (2.4 voxels): B' should be B's exact offset
    # surface B - 0.15 (measured: volume within 3.2 %, 88 % of voxels agree).
    exact = b - 0.15
    assert inside(bp, h) == pytest.approx(inside(exact, h), rel=0.05)
    assert ((exact < 0) != (bp < 0)).sum() < 0.15 * (exact < 0).sum()
    # It grows outward: almost nothing inside B is outside B'.
    assert ((b < 0) & (bp > 0)).sum() < 0.01 * (b < 0).sum()


def test_a_pair_that_changes_nothing_is_an_error():
    rng = np.random.default_rng(0)
    b = rng.random((12, 12, 12), dtype=np.float32)
    with pytest.raises(_native.InvalidInputError, match="does not differ from A"):
        _native.synthesize_analogy(b, b, b, cull_distance=0)


def textured_bunny(bunny, preset, resolution=64):
    """The bunny (OBJ: y up) with a pair at half its size, field around y."""
    verts, faces = bunny
    pair = _native.make_exemplar_pair(preset, resolution=resolution // 2)
    h = pair["voxel_size"]
    verts = verts * (resolution * h / (verts.max(0) - verts.min(0)).max())
    vox = _native.voxelize(verts, faces, resolution=resolution, padding=6)
    field = _native.preset_direction_field(verts, faces, "around_axis", axis=(0, 1, 0))
    frames = _native.volume_frames(vox["sdf"], vox["origin"], h, verts, field)
    res = _native.synthesize_analogy(pair["a"], pair["a_prime"], vox["sdf"], field_a=pair["field"],
                                     field_b=frames["t"], voxel_size=h)
    return vox, frames, res


def surface_area(sdf, origin, h):
    v, t = _native.isosurface(sdf, origin, h)
    a, b, c = (v[t[:, k]] for k in range(3))
    return 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum()


@pytest.mark.heavy  # 15-50 s under ASan; the C++ tier covers the analogy there
def test_field_aligned_grooves_run_around_the_bunny(bunny):
    vox, frames, res = textured_bunny(bunny, "grooves")
    bp, h = res["b_prime"], vox["voxel_size"]
    assert res["coherent"] > res["searched"] // 2
    # On B's surface, B' changes along B = T x N (across the grooves) more
    # than along T (the field, around y): measured from the result's sdf.
    gz, gy, gx = np.gradient(bp)
    grad = np.stack([gx, gy, gz], -1)
    near = np.abs(vox["sdf"]) < h
    along = np.abs((grad * frames["t"]).sum(-1))[near].mean()
    across = np.abs((grad * frames["b"]).sum(-1))[near].mean()
    assert across > 1.5 * along  # measured 1.96
    # Grooves cut in: material more than a voxel inside B is gone (measured 5.0 % of B).
    assert ((vox["sdf"] < -h) & (bp > 0)).sum() > 0.025 * (vox["sdf"] < 0).sum()


@pytest.mark.heavy  # 15-50 s under ASan; the C++ tier covers the analogy there
def test_field_aligned_spikes_grow_out_of_the_bunny(bunny):
    vox, frames, res = textured_bunny(bunny, "spikes")
    bp, b, h = res["b_prime"], vox["sdf"], vox["voxel_size"]
    assert surface_area(bp, vox["origin"], h) > 1.1 * surface_area(b, vox["origin"], h)  # measured 1.22
    grown = (b > 2 * h) & (bp < 0)  # material two voxels or more outside B (measured 0.72 % of B)
    assert grown.sum() > 0.003 * (b < 0).sum()


@pytest.mark.heavy  # 15-50 s under ASan; the C++ tier covers the analogy there
def test_field_aligned_analogy_is_deterministic(bunny):
    _, _, one = textured_bunny(bunny, "pits", resolution=40)
    _, _, two = textured_bunny(bunny, "pits", resolution=40)
    np.testing.assert_array_equal(one["b_prime"], two["b_prime"])


def test_a_region_restricts_what_is_learnt():
    pair = _native.make_exemplar_pair("spikes", resolution=16)
    h, a = pair["voxel_size"], pair["a"]
    args = dict(field_a=pair["field"], field_b=pair["field"], voxel_size=h)
    below = np.zeros_like(a)
    below[:4] = 1  # the air under the slab: A' is A there
    with pytest.raises(_native.InvalidInputError, match="inside a_region"):
        _native.synthesize_analogy(a, pair["a_prime"], a, a_region=below, **args)
    with pytest.raises(_native.InvalidInputError, match="a_region must have 1 channel on A's grid"):
        _native.synthesize_analogy(a, pair["a_prime"], a, a_region=np.ones((4, 4, 4), np.float32), **args)
    everywhere = _native.synthesize_analogy(a, pair["a_prime"], a, a_region=np.ones_like(a), **args)
    default = _native.synthesize_analogy(a, pair["a_prime"], a, **args)
    np.testing.assert_array_equal(everywhere["b_prime"], default["b_prime"])


def test_bad_fields():
    pair = _native.make_exemplar_pair("spikes", resolution=16)
    h = pair["voxel_size"]
    b = pair["a"]
    with pytest.raises(_native.InvalidInputError, match="both field_a and field_b"):
        _native.synthesize_analogy(pair["a"], pair["a_prime"], b, field_a=pair["field"], voxel_size=h)
    with pytest.raises(_native.InvalidInputError, match=r"field_b.*\(Z, Y, X, 3\)"):
        _native.synthesize_analogy(pair["a"], pair["a_prime"], b, field_a=pair["field"],
                                   field_b=np.zeros((16, 16, 16), np.float32), voxel_size=h)
    with pytest.raises(_native.InvalidInputError, match="field_b is zero or not finite"):
        _native.synthesize_analogy(pair["a"], pair["a_prime"], b, field_a=pair["field"],
                                   field_b=np.zeros((16, 16, 16, 3), np.float32), voxel_size=h)
    with pytest.raises(_native.InvalidInputError, match="'field_b'.*non-finite"):
        _native.synthesize_analogy(pair["a"], pair["a_prime"], b, field_a=pair["field"],
                                   field_b=np.full((16, 16, 16, 3), np.nan, np.float32), voxel_size=h)


@pytest.mark.parametrize("kwargs, words", [
    ({"a_prime": np.zeros((8, 8, 9), np.float32)}, ["same size"]),
    ({"b": np.zeros((8, 8), np.float32)}, ["'b'", "(Z, Y, X)"]),
    ({"b": np.full((8, 8, 8), np.nan, np.float32)}, ["'b'", "non-finite"]),
    ({"fine_size": 4}, ["fine_size"]),
    ({"voxel_size": 0.0}, ["voxel_size"]),
])
def test_bad_inputs(kwargs, words):
    args = {"a": np.zeros((8, 8, 8), np.float32), "a_prime": np.zeros((8, 8, 8), np.float32),
            "b": np.zeros((8, 8, 8), np.float32)}
    args.update(kwargs)
    with pytest.raises(_native.InvalidInputError) as info:
        _native.synthesize_analogy(args.pop("a"), args.pop("a_prime"), args.pop("b"), **args)
    for w in words:
        assert w in str(info.value)


def test_cancel():
    ctx = _native.ExecContext()
    ctx.cancel()
    pair = _native.make_exemplar_pair("spikes", resolution=16)
    with pytest.raises(_native.CancelledError):
        _native.synthesize_analogy(pair["a"], pair["a_prime"], pair["a"], voxel_size=pair["voxel_size"], ctx=ctx)


def test_volume_frames_on_the_bunny_follow_its_field(bunny):
    verts, faces = bunny
    vox = _native.voxelize(verts, faces, resolution=32)
    field = _native.preset_direction_field(verts, faces, "around_axis", axis=(0, 1, 0))
    fr = _native.volume_frames(vox["sdf"], vox["origin"], vox["voxel_size"], verts, field)
    t, n, b = fr["t"], fr["n"], fr["b"]
    assert t.shape == vox["sdf"].shape + (3,)
    np.testing.assert_allclose(np.linalg.norm(t, axis=-1), 1, atol=1e-4)
    np.testing.assert_allclose((t * n).sum(-1), 0, atol=1e-4)
    np.testing.assert_allclose(b, np.cross(t, n), atol=1e-4)
    # Around the y axis: T has (almost) no y component near the surface, away from the axis.
    near = np.abs(vox["sdf"]) < vox["voxel_size"]
    assert np.median(np.abs(t[near][:, 1])) < 0.2


def test_volume_frames_reject_bad_input():
    sdf = np.ones((4, 4, 4), np.float32)
    with pytest.raises(_native.InvalidInputError, match="points"):
        _native.volume_frames(sdf, [0, 0, 0], 1.0, np.zeros((3, 2)), np.zeros((3, 3)))
    with pytest.raises(_native.InvalidInputError, match="no voxels within"):
        _native.volume_frames(sdf * 10, [0, 0, 0], 1.0, np.zeros((3, 3)), np.ones((3, 3)))


def test_a_span_gives_each_call_its_share_of_one_progress_bar(bunny):
    verts, faces = bunny
    ctx = _native.ExecContext()
    ctx.set_span(0.5, 0.75)
    assert ctx.progress == 0.5
    _native.voxelize(verts, faces, resolution=16, ctx=ctx)
    assert ctx.progress == pytest.approx(0.75)  # the call's 100 % is the span's end
