# SPDX-License-Identifier: GPL-3.0-or-later
"""The math of direction-field painting and of the field overlay
(exsynth.field_brush, exsynth.field_glyphs), without Blender."""

import numpy as np
import pytest

from exsynth import _native, field_brush, field_glyphs


def grid(n=21, size=2.0):
    """A flat (n x n)-vertex grid in the z = 0 plane, centred, triangulated."""
    xs = np.linspace(-size / 2, size / 2, n)
    x, y = np.meshgrid(xs, xs)
    verts = np.stack([x.ravel(), y.ravel(), np.zeros(n * n)], axis=1)
    i = np.arange(n - 1)
    a = (i[:, None] * n + i[None, :]).ravel()
    tris = np.concatenate([np.stack([a, a + 1, a + n + 1], 1), np.stack([a, a + n + 1, a + n], 1)])
    return verts, tris


# ---- tangent from the screen motion -------------------------------------------
def test_tangent_from_view_looking_straight_down_is_the_motion():
    t = field_brush.tangent_from_view([0.3, 0.4, 0.0], normal=[0, 0, 1], view_dir=[0, 0, -1])
    np.testing.assert_allclose(t, [0.6, 0.8, 0.0], atol=1e-12)


def test_tangent_from_view_on_a_tilted_plane_projects_back_onto_the_stroke():
    # A plane tilted 60 degrees about x, seen from above: the tangent lies in
    # the plane, and seen along the view ray (dropping z) it runs the stroke's way.
    normal = np.array([0.0, -np.sin(np.radians(60)), np.cos(np.radians(60))])
    for motion in ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.6, -0.8, 0.0]):
        t = field_brush.tangent_from_view(motion, normal, view_dir=[0, 0, -1])
        assert abs(np.dot(t, normal)) < 1e-12 and abs(np.linalg.norm(t) - 1) < 1e-12
        screen = t[:2] / np.linalg.norm(t[:2])
        np.testing.assert_allclose(screen, np.array(motion[:2]) / np.linalg.norm(motion[:2]), atol=1e-12)


def test_tangent_from_view_at_grazing_angle_projects_orthogonally():
    # The view ray almost in the tangent plane: orthogonal projection, still unit and tangent.
    normal = np.array([0.0, 1.0, 0.0])
    t = field_brush.tangent_from_view([0.2, 0.1, 0.0], normal, view_dir=[0.0, 0.05, -1.0])
    np.testing.assert_allclose(t, [1.0, 0.0, 0.0], atol=1e-12)


def test_tangent_from_view_of_no_motion_is_zero():
    assert not np.any(field_brush.tangent_from_view([0, 0, 0], [0, 0, 1], [0, 0, -1]))
    # Grazing view, motion along the normal: nothing of it lies in the surface.
    assert not np.any(field_brush.tangent_from_view([0, 0.3, 0.0], [0, 1, 0], [0.0, 0.05, -1]))


# ---- falloff -----------------------------------------------------------------
def test_falloff_is_one_at_the_centre_smooth_and_zero_outside():
    d = np.linspace(0.0, 2.0, 201)
    w = field_brush.falloff(d, 1.0)
    assert w[0] == 1.0 and np.all(w[d >= 1.0] == 0.0)
    assert np.all(np.diff(w) <= 0)  # monotone
    assert field_brush.falloff(0.5, 1.0) == pytest.approx(0.75 ** 2)
    # Zero slope at the rim: the weight just inside is second-order small.
    assert field_brush.falloff(0.999, 1.0) < 1e-5


@pytest.mark.parametrize("radius", [0.0, -1.0, float("nan"), float("inf")])
def test_falloff_refuses_a_bad_radius(radius):
    with pytest.raises(ValueError, match="brush radius must be a positive number"):
        field_brush.falloff(0.1, radius)


# ---- mirror ----------------------------------------------------------------------
@pytest.mark.parametrize("axis", [0, 1, 2])
def test_mirror_reflects_position_and_direction_on_one_axis(axis):
    p, d = field_brush.mirror([1.0, 2.0, 3.0], [0.1, 0.2, 0.3], axis)
    expect_p, expect_d = np.array([1.0, 2.0, 3.0]), np.array([0.1, 0.2, 0.3])
    expect_p[axis] *= -1
    expect_d[axis] *= -1
    np.testing.assert_array_equal(p, expect_p)
    np.testing.assert_array_equal(d, expect_d)
    # Twice is the identity.
    np.testing.assert_array_equal(field_brush.mirror(p, d, axis)[0], [1.0, 2.0, 3.0])


def test_mirrored_samples_cover_every_combination():
    samples = field_brush.mirrored_samples([1.0, 2.0, 3.0], [1.0, 1.0, 1.0], [0, 2])
    points = sorted(tuple(p) for p, _ in samples)
    assert points == sorted([(1, 2, 3), (-1, 2, 3), (1, 2, -3), (-1, 2, -3)])
    assert len(field_brush.mirrored_samples([1, 2, 3], [1, 0, 0], [])) == 1
    with pytest.raises(ValueError, match="mirror axis"):
        field_brush.mirror([0, 0, 0], [1, 0, 0], 3)


# ---- the brush on constraints --------------------------------------------------
def brush_setup():
    verts, tris = grid()
    normals = field_brush.vertex_normals(verts, tris)
    return verts, tris, normals, np.zeros((len(verts), 3), np.float32)


def test_paint_sets_the_stroke_direction_inside_the_radius_only():
    verts, _, normals, c = brush_setup()
    # A direction with a normal component: it is projected into the plane.
    changed = field_brush.apply_brush(c, None, verts, normals, [0, 0, 0], 0.35, [1.0, 1.0, 0.5])
    dist = np.linalg.norm(verts, axis=1)
    inside = dist < 0.35
    assert set(changed) == set(np.nonzero(inside)[0]) and len(changed) > 5
    np.testing.assert_allclose(c[inside], np.tile([np.sqrt(0.5), np.sqrt(0.5), 0.0], (inside.sum(), 1)), atol=1e-6)
    assert not np.any(c[~inside])


def test_paint_turns_painted_directions_by_the_falloff_and_ignores_the_field():
    verts, _, normals, c = brush_setup()
    c[:] = (1.0, 0.0, 0.0)  # an earlier stroke along x everywhere
    field = np.tile(np.array([0.0, 0.0, 0.0], np.float32), (len(verts), 1))
    field_brush.apply_brush(c, field, verts, normals, [0, 0, 0], 0.5, [0.0, 1.0, 0.0])
    dist = np.linalg.norm(verts, axis=1)
    inside = np.nonzero(dist < 0.5)[0]
    # The angle from x towards the stroke's y grows with the weight.
    angle = np.arctan2(c[inside, 1], c[inside, 0])
    w = field_brush.falloff(dist[inside], 0.5)
    expect = np.arctan2(w, 1 - w)  # normalize((1 - w) x + w y)
    np.testing.assert_allclose(angle, expect, atol=1e-6)
    assert np.allclose(c[np.argmin(dist)], [0, 1, 0])  # the centre takes the stroke's direction


def test_paint_on_free_vertices_does_not_copy_the_old_field():
    verts, _, normals, c = brush_setup()
    field = np.tile(np.array([1.0, 0.0, 0.0], np.float32), (len(verts), 1))
    field_brush.apply_brush(c, field, verts, normals, [0, 0, 0], 0.5, [0.0, 1.0, 0.0])
    painted = np.any(c != 0, axis=1)
    np.testing.assert_allclose(c[painted], np.tile([0, 1, 0], (painted.sum(), 1)), atol=1e-6)


def test_erase_frees_every_painted_vertex_within_the_radius():
    verts, _, normals, c = brush_setup()
    c[:] = (1.0, 0.0, 0.0)
    changed = field_brush.apply_brush(c, None, verts, normals, [0.5, 0.0, 0.0], 0.3, [0, 1, 0], mode="ERASE")
    inside = np.linalg.norm(verts - [0.5, 0, 0], axis=1) < 0.3
    assert not np.any(c[inside]) and np.all(c[~inside, 0] == 1.0)
    assert set(changed) == set(np.nonzero(inside)[0])
    # Erasing where nothing is painted changes nothing.
    assert len(field_brush.apply_brush(c, None, verts, normals, [0.5, 0.0, 0.0], 0.3, [0, 1, 0], mode="ERASE")) == 0


def test_comb_drags_directions_a_little_per_sample():
    verts, _, normals, c = brush_setup()
    field = np.tile(np.array([1.0, 0.0, 0.0], np.float32), (len(verts), 1))
    centre = int(np.argmin(np.linalg.norm(verts, axis=1)))
    angles = []
    for _ in range(12):
        field_brush.apply_brush(c, field, verts, normals, [0, 0, 0], 0.5, [0.0, 1.0, 0.0], mode="COMB")
        angles.append(np.degrees(np.arctan2(c[centre, 1], c[centre, 0])))
    # Each sample adds COMB_RATE of the stroke's direction at the centre.
    assert angles[0] == pytest.approx(np.degrees(np.arctan(field_brush.COMB_RATE)), abs=1e-4)
    assert np.all(np.diff(angles) > 0) and angles[-1] > 70  # turns towards the stroke, never past it
    np.testing.assert_allclose(np.linalg.norm(c[np.any(c != 0, axis=1)], axis=1), 1.0, atol=1e-6)


def test_comb_without_a_field_or_paint_acts_as_paint():
    verts, _, normals, c = brush_setup()
    field_brush.apply_brush(c, None, verts, normals, [0, 0, 0], 0.3, [0.0, 1.0, 0.0], mode="COMB")
    painted = np.any(c != 0, axis=1)
    np.testing.assert_allclose(c[painted], np.tile([0, 1, 0], (painted.sum(), 1)), atol=1e-6)


def test_paint_opposite_to_a_painted_direction_half_way_takes_the_stroke():
    verts, _, normals, c = brush_setup()
    c[:] = (1.0, 0.0, 0.0)
    # At weight exactly 0.5 the blend of x and -x cancels: the stroke's direction wins.
    r = 0.5 / np.sqrt(1 - np.sqrt(0.5))  # falloff(0.5, r) == 0.5
    one = c[:1]
    field_brush.apply_brush(one, None, verts[:1] * 0 + [[0.5, 0, 0]], normals[:1], [0, 0, 0], r, [-1.0, 0, 0])
    c = one
    assert np.all(np.isfinite(c)) and np.linalg.norm(c[0]) == pytest.approx(1.0)


@pytest.mark.parametrize("kwargs, match", [
    ({"radius": 0.0}, "brush radius"),
    ({"mode": "SMUDGE"}, "mode must be one of"),
    ({"strength": 0.0}, "strength must be in"),
])
def test_bad_brush_arguments_change_nothing(kwargs, match):
    verts, _, normals, c = brush_setup()
    args = {"radius": 0.3, "mode": "PAINT", "strength": 1.0} | kwargs
    with pytest.raises(ValueError, match=match):
        field_brush.apply_brush(c, None, verts, normals, [0, 0, 0], args["radius"], [1, 0, 0],
                                mode=args["mode"], strength=args["strength"])
    assert not np.any(c)


def test_a_painted_stroke_diffuses_into_a_field_along_it():
    # Through the engine, as the tool does: a stroke along x across the grid.
    verts, tris, normals, c = brush_setup()
    for x in np.linspace(-0.8, 0.8, 17):
        field_brush.apply_brush(c, None, verts, normals, [x, 0.0, 0.0], 0.2, [1.0, 0.0, 0.0])
    field = _native.diffuse_direction_field(verts, tris, c)
    assert np.mean(field[:, 0]) > 0.99


# ---- overlay geometry ------------------------------------------------------------
def test_stroke_indices_spread_evenly_and_respect_the_maximum():
    verts, tris = grid(41)  # 4 square units, 1681 vertices
    idx, spacing = field_glyphs.stroke_indices(verts, tris, 100)
    assert spacing == pytest.approx(0.2) and 50 <= len(idx) <= 100 and len(set(idx)) == len(idx)
    # Evenly: every chosen vertex's nearest chosen neighbour is about one spacing away.
    p = verts[idx]
    d = np.linalg.norm(p[:, None] - p[None], axis=2) + np.eye(len(p)) * 9
    assert np.all(d.min(axis=1) > 0.5 * spacing) and np.all(d.min(axis=1) < 2.5 * spacing)
    # Denser vertices in one corner do not get more strokes there.
    extra = np.random.default_rng(0).uniform(-1.0, -0.5, (4000, 2))
    dense = np.concatenate([verts, np.c_[extra, np.zeros(4000)]])
    idx2, _ = field_glyphs.stroke_indices(dense, tris, 100)
    assert abs(len(idx2) - len(idx)) <= 5
    assert len(field_glyphs.stroke_indices(verts, tris, 10000)[0]) <= 10000
    with pytest.raises(ValueError):
        field_glyphs.stroke_indices(verts, tris, 0)


def test_strokes_run_from_the_lifted_vertex_along_the_field():
    verts, tris = grid(5)
    normals = field_brush.vertex_normals(verts, tris)
    field = np.tile([0.0, 2.0, 0.0], (len(verts), 1))  # not unit: drawn at the given length anyway
    field[3] = 0.0  # undefined: left out of the strokes
    seg = field_glyphs.strokes(verts, normals, field, np.arange(len(verts)), length=0.1, lift=0.01)
    assert seg.shape == (2 * (len(verts) - 1), 3)
    tails, heads = seg[0::2], seg[1::2]
    np.testing.assert_allclose(heads - tails, np.tile([0, 0.1, 0], (len(tails), 1)), atol=1e-6)
    np.testing.assert_allclose(tails[:, 2], 0.01, atol=1e-7)


def test_facing_keeps_the_marks_on_the_viewed_side_of_a_sphere():
    rng = np.random.default_rng(3)
    n = rng.normal(size=(400, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    p = 2.0 * n  # a sphere of radius 2, outward normals
    eye = np.array([0.0, 0.0, 10.0])
    front = field_glyphs.facing(p, n, eye=eye)
    # Brute force: a point is seen when the ray from the eye meets the sphere there first.
    for i in range(len(p)):
        d = (p[i] - eye) / np.linalg.norm(p[i] - eye)
        b = np.dot(d, eye)
        t_first = -b - np.sqrt(b * b - (np.dot(eye, eye) - 4.0))
        assert front[i] == bool(np.isclose(t_first, np.linalg.norm(p[i] - eye), atol=1e-9)), i
    ortho = field_glyphs.facing(p, n, toward_viewer=(0.0, 0.0, 1.0))
    np.testing.assert_array_equal(ortho, n[:, 2] > 0)
    assert field_glyphs.facing(np.zeros((0, 3)), np.zeros((0, 3)), eye=eye).shape == (0,)


def test_vertex_indices_find_a_vortex_a_saddle_and_nothing_in_a_uniform_field():
    verts, tris = grid(20)
    normals = field_brush.vertex_normals(verts, tris)
    centre = np.array([0.031, 0.017, 0.0])  # off the grid's vertices and edges
    x, y = verts[:, 0] - centre[0], verts[:, 1] - centre[1]
    cases = {"uniform": (np.ones_like(x), np.zeros_like(x), 0),
             "vortex": (-y, x, 1), "source": (x, y, 1), "saddle": (x, -y, -1)}
    for name, (fx, fy, index) in cases.items():
        field = np.stack([fx, fy, np.zeros_like(x)], 1)
        ind = field_glyphs.vertex_indices(tris, field, normals)
        nonzero = np.nonzero(ind)[0]
        if index == 0:
            assert len(nonzero) == 0, name
        else:
            # The corners of the triangle holding the centre see it, nobody else.
            assert 3 <= len(nonzero) <= 4 and np.all(ind[nonzero] == index), name
            assert np.all(np.linalg.norm(verts[nonzero] - centre, axis=1) < 0.2), name


def test_vertex_indices_find_a_singularity_on_a_vertex_whatever_its_vector():
    # A sink centred exactly on a vertex, whose own vector is opposite one of
    # its neighbours' (the case a per-triangle index misses: a half-turn step).
    verts, tris = grid(21)
    normals = field_brush.vertex_normals(verts, tris)
    field = -np.stack([verts[:, 0], verts[:, 1], np.zeros(len(verts))], 1)
    middle = int(np.argmin(np.linalg.norm(verts, axis=1)))
    for own in ([0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]):
        field[middle] = own
        ind = field_glyphs.vertex_indices(tris, field, normals)
        # Found at the vertex; a neighbour its own vector points away from may be marked too.
        found = np.nonzero(ind)[0]
        assert ind[middle] == 1 and np.all(np.linalg.norm(verts[found] - verts[middle], axis=1) < 0.15), own  # the one-ring (diagonals 0.14)


def test_singular_points_mark_undefined_vertices_and_clashes():
    verts, tris = grid(6)
    normals = field_brush.vertex_normals(verts, tris)
    field = np.tile([1.0, 0.0, 0.0], (len(verts), 1))
    field[verts[:, 0] > 0.3] = (-1.0, 0.0, 0.0)  # head-on along a line: a clash, not a vortex
    field[0] = np.nan
    marks = field_glyphs.singular_points(verts, tris, field, normals, lift=0.0)
    singular, clashes = marks["singular"], marks["clashes"]
    assert len(marks["singular_normals"]) == len(singular) and len(marks["clash_normals"]) == len(clashes)
    np.testing.assert_allclose(marks["clash_normals"][:, 2], 1.0, atol=1e-6)  # the grid lies in z = 0
    assert any(np.allclose(p, verts[0]) for p in singular)
    assert len(clashes) > 0 and np.all(np.abs(clashes[:, 0] - 0.4) < 0.25)
    edges = field_glyphs.mesh_edges(tris)
    assert len(edges) == len(np.unique(np.sort(np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]]),
                                                       axis=1), axis=0))
