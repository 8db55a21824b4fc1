"""exsynth._native.diffuse_direction_field / preset_direction_field through
the binding: results on the bundled bunny, options, progress and cancel, and
every bad input with a message naming it."""
import numpy as np
import pytest

from exsynth import _native


def vertex_normals(verts, faces):
    """Area-weighted unit normals, written in numpy (not the engine's)."""
    a, b, c = (verts[faces[:, k]] for k in range(3))
    cross = np.cross(b - a, c - a)
    n = np.zeros_like(verts)
    for k in range(3):
        np.add.at(n, faces[:, k], cross)
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def painted(verts, count=12, seed=0):
    """A few painted vertices with random (not tangent) directions."""
    rng = np.random.default_rng(seed)
    given = np.zeros_like(verts)
    idx = rng.choice(len(verts), count, replace=False)
    given[idx] = rng.normal(size=(count, 3))
    return given, idx


def assert_unit_tangent(field, verts, faces):
    assert field.dtype == np.float32 and field.shape == verts.shape and field.flags["C_CONTIGUOUS"]
    assert np.all(np.isfinite(field))
    np.testing.assert_allclose(np.linalg.norm(field, axis=1), 1.0, atol=1e-5)
    n = vertex_normals(verts, faces)
    assert np.abs(np.einsum("ij,ij->i", field, n)).max() < 1e-4


def cylinder(seg=32, rings=8, radius=0.5, height=2.0):
    """Open tube around the z axis."""
    t = 2 * np.pi * np.arange(seg) / seg
    z = np.linspace(0, height, rings)
    verts = np.array([[radius * np.cos(a), radius * np.sin(a), h] for h in z for a in t])
    faces = []
    for r in range(rings - 1):
        for s in range(seg):
            a, b = r * seg + s, r * seg + (s + 1) % seg
            faces += [[a, b, b + seg], [a, b + seg, a + seg]]
    return verts, np.array(faces, np.int32)


def test_diffused_field_on_the_bunny_is_unit_tangent_and_keeps_the_strokes(bunny):
    verts, faces = bunny
    given, idx = painted(verts)
    field = _native.diffuse_direction_field(verts, faces, given)
    assert_unit_tangent(field, verts, faces)
    n = vertex_normals(verts, faces)
    proj = given[idx] - np.einsum("ij,ij->i", given[idx], n[idx])[:, None] * n[idx]
    proj /= np.linalg.norm(proj, axis=1, keepdims=True)
    np.testing.assert_allclose(field[idx], proj, atol=1e-5)


def test_dtypes_options_and_determinism(bunny):
    verts, faces = bunny
    given, _ = painted(verts, seed=1)
    a = _native.diffuse_direction_field(verts, faces, given)
    b = _native.diffuse_direction_field(verts.astype(np.float32), faces.astype(np.int64), given.astype(np.float32))
    np.testing.assert_allclose(a, b, atol=1e-5)
    np.testing.assert_array_equal(a, _native.diffuse_direction_field(verts, faces, given, seed=5))
    uniform = _native.diffuse_direction_field(verts, faces, given, weights="uniform")
    assert_unit_tangent(uniform, verts, faces)
    assert not np.array_equal(a, uniform)


def test_unpainted_part_gets_the_projected_fallback_axis(cube):
    verts, faces = cube
    # A second cube, nobody paints it.
    verts2 = np.vstack([verts, verts + [3, 0, 0]])
    faces2 = np.vstack([faces, faces + 8]).astype(np.int32)
    given = np.zeros_like(verts2)
    given[0] = [1, 0, 0]
    field = _native.diffuse_direction_field(verts2, faces2, given, fallback_axis=(0, 2, 0))
    assert np.all(np.isfinite(field))
    n = vertex_normals(verts2, faces2)[8:]
    expected = np.array([0, 1, 0]) - n[:, 1:2] * n
    expected /= np.linalg.norm(expected, axis=1, keepdims=True)
    np.testing.assert_allclose(field[8:], expected, atol=1e-5)


def test_progress_and_cancel(bunny):
    verts, faces = bunny
    given, _ = painted(verts)
    ctx = _native.ExecContext()
    _native.diffuse_direction_field(verts, faces, given, ctx=ctx)
    assert ctx.progress == 1.0 and ctx.stage.startswith("direction field")
    stopped = _native.ExecContext()
    stopped.cancel()
    with pytest.raises(_native.CancelledError):
        _native.diffuse_direction_field(verts, faces, given, ctx=stopped)


@pytest.mark.parametrize("preset", ["around_axis", "along_axis", "along_curve"])
def test_presets_on_the_bunny_are_unit_tangent(bunny, preset):
    verts, faces = bunny
    curve = [[-0.1, 0.1, 0.0], [0.0, 0.15, 0.02], [0.1, 0.1, 0.0]]  # a list is fine
    field = _native.preset_direction_field(verts, faces, preset, axis=(0, 1, 0), curve=curve)
    assert_unit_tangent(field, verts, faces)


def test_around_axis_on_a_cylinder_follows_the_circles():
    verts, faces = cylinder()
    field = _native.preset_direction_field(verts, faces, "around_axis", axis=[0, 0, 1])
    circle = np.stack([-verts[:, 1], verts[:, 0], np.zeros(len(verts))], 1)
    circle /= np.linalg.norm(circle, axis=1, keepdims=True)
    # Open rims tilt the normal a little; the rings inside are exact.
    inner = slice(32, len(verts) - 32)
    np.testing.assert_allclose(field[inner], circle[inner], atol=1e-5)
    along = _native.preset_direction_field(verts, faces, "along_axis", axis=[0, 0, 3])
    np.testing.assert_allclose(along[inner], np.tile([0, 0, 1], (len(verts) - 64, 1)), atol=1e-5)


BAD_DIFFUSE = [
    # (description, change to (verts, faces, given), kwargs, words the message must contain)
    ("given with the wrong row count", lambda v, f, g: (v, f, g[:-1]), {}, ["'given'", "8 by 3"]),
    ("given with 2 columns", lambda v, f, g: (v, f, g[:, :2].copy()), {}, ["'given'", "8 by 3"]),
    ("integer given", lambda v, f, g: (v, f, g.astype(np.int32)), {}, ["'given'", "float32"]),
    ("NaN in given", lambda v, f, g: (v, f, np.where(np.arange(8)[:, None] == 5, np.nan, g)), {},
     ["row 5 of 'given'", "not finite"]),
    ("all-zero given", lambda v, f, g: (v, f, np.zeros_like(g)), {},
     ["no non-zero vectors", "paint at least one stroke or use a preset"]),
    ("given along the normal", lambda v, f, g: (v, f, np.where(np.arange(8)[:, None] == 0, vertex_normals(v, f), 0.0)),
     {},
     ["along the surface normal"]),
    ("NaN vertex", lambda v, f, g: (np.where(np.arange(8)[:, None] == 3, np.nan, v), f, g), {},
     ["vertex 3", "not finite"]),
    ("face out of range", lambda v, f, g: (v, np.where(np.arange(12)[:, None] == 2, 40, f), g), {},
     ["face 2", "40"]),
    ("unknown option", None, {"smoothness": 3}, ["unknown option 'smoothness'", "weights"]),
    ("bad weights", None, {"weights": "cotan"}, ["weights", "'cotangent' or 'uniform'"]),
    ("zero fallback axis", None, {"fallback_axis": (0, 0, 0)}, ["fallback_axis", "non-zero"]),
    ("short fallback axis", None, {"fallback_axis": (0, 1)}, ["fallback_axis", "3 numbers"]),
]


@pytest.mark.parametrize("case", BAD_DIFFUSE, ids=[c[0] for c in BAD_DIFFUSE])
def test_bad_diffuse_input_is_rejected_with_a_message_naming_it(case, cube):
    _, change, kwargs, words = case
    verts, faces = cube
    given = np.zeros_like(verts)
    given[1] = [1, 0, 0]
    if change:
        verts, faces, given = change(verts, faces, given)
    with pytest.raises(_native.InvalidInputError) as info:
        _native.diffuse_direction_field(verts, faces, given, **kwargs)
    for w in words:
        assert w in str(info.value), str(info.value)


BAD_PRESET = [
    ("unknown preset", {"preset": "spiral"}, ["'around_axis', 'along_axis' or 'along_curve'", "spiral"]),
    ("zero axis", {"axis": (0, 0, 0)}, ["'axis'", "non-zero"]),
    ("NaN axis", {"axis": (0, np.nan, 1)}, ["'axis'", "finite"]),
    ("axis of 2 numbers", {"axis": (0, 1)}, ["'axis'", "3 numbers"]),
    ("along_curve without a curve", {"preset": "along_curve"}, ["'curve' is required"]),
    ("one-point curve", {"preset": "along_curve", "curve": [[0, 0, 0]]}, ["at least 2 points, got 1"]),
    ("2-column curve", {"preset": "along_curve", "curve": np.zeros((4, 2))}, ["'curve'", "N by 3"]),
    ("NaN curve", {"preset": "along_curve", "curve": [[0, 0, 0], [1, np.nan, 0]]}, ["row 1 of 'curve'", "not finite"]),
    ("curve of one repeated point", {"preset": "along_curve", "curve": [[1, 1, 1]] * 3}, ["same point"]),
]


@pytest.mark.parametrize("case", BAD_PRESET, ids=[c[0] for c in BAD_PRESET])
def test_bad_preset_input_is_rejected_with_a_message_naming_it(case, cube):
    _, kwargs, words = case
    with pytest.raises(_native.InvalidInputError) as info:
        _native.preset_direction_field(*cube, **kwargs)
    for w in words:
        assert w in str(info.value), str(info.value)
