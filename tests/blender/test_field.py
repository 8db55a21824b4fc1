# SPDX-License-Identifier: GPL-3.0-or-later
"""Direction Field: the operator (presets, diffusing painted vectors), its
all-or-nothing behaviour, its error messages, and `./exsynth run field`."""

import bpy
import numpy as np
import pytest

from exsynth import _native, cli, jobs
from exsynth.operators import field as field_ops
from helpers import BUNNY_OBJ, add_camera, add_faceless_mesh, scene_state

FIELD = "exsynth_field"


def vectors(obj, name=FIELD):
    attr = obj.data.attributes[name]
    assert (attr.domain, attr.data_type) == ('POINT', 'FLOAT_VECTOR')
    out = np.empty(3 * len(obj.data.vertices), np.float32)
    attr.data.foreach_get("vector", out)
    return out.reshape(-1, 3)


def vertex_normals(obj):
    obj.data.update()
    n = np.empty(3 * len(obj.data.vertices), np.float32)
    obj.data.vertices.foreach_get("normal", n)
    return n.reshape(-1, 3)


def area_normals(obj):
    """Area-weighted vertex normals: the ones the engine's field is tangent to."""
    mesh = obj.data
    mesh.calc_loop_triangles()
    co = np.empty(3 * len(mesh.vertices), np.float64)
    mesh.vertices.foreach_get("co", co)
    tris = np.empty(3 * len(mesh.loop_triangles), np.int32)
    mesh.loop_triangles.foreach_get("vertices", tris)
    co, tris = co.reshape(-1, 3), tris.reshape(-1, 3)
    face = np.cross(co[tris[:, 1]] - co[tris[:, 0]], co[tris[:, 2]] - co[tris[:, 0]])
    n = np.zeros_like(co)
    for k in range(3):
        np.add.at(n, tris[:, k], face)
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def set_vectors(obj, name, values):
    attr = obj.data.attributes.get(name) or obj.data.attributes.new(name, 'FLOAT_VECTOR', 'POINT')
    attr.data.foreach_set("vector", np.ascontiguousarray(values, np.float32).ravel())


def settings():
    return bpy.context.scene.exsynth


def state(obj):
    """Scene plus the mesh's attributes and their values."""
    s = scene_state()
    s["attributes"] = sorted((a.name, a.domain, a.data_type) for a in obj.data.attributes)
    attr = obj.data.attributes.get(FIELD)
    s["field"] = vectors(obj).tobytes() if attr is not None and attr.domain == 'POINT' else None
    return s


def test_preset_around_z_is_unit_tangent_and_horizontal(bunny):
    settings().field_preset, settings().field_axis = 'AROUND_AXIS', 'Z'
    assert bpy.ops.exsynth.direction_field() == {'FINISHED'}
    field = vectors(bunny)
    assert field.shape == (len(bunny.data.vertices), 3) and np.all(np.isfinite(field))
    np.testing.assert_allclose(np.linalg.norm(field, axis=1), 1.0, atol=1e-4)
    assert np.abs(np.einsum("ij,ij->i", field, area_normals(bunny))).max() < 1e-3
    # Blender's own vertex normals are angle-weighted, so they differ a little
    # on a coarse mesh (1.8 k vertices): tangent to within a few degrees.
    normals = vertex_normals(bunny)
    dots = np.abs(np.einsum("ij,ij->i", field, normals))
    assert np.median(dots) < 0.02 and np.percentile(dots, 99) < 0.15
    # Around z: horizontal wherever the surface is steep (a horizontal tangent
    # exists there and the projection keeps it nearly so).
    steep = np.abs(normals[:, 2]) < 0.2
    assert np.median(np.abs(field[steep, 2])) < 0.1
    assert np.median(np.abs(field[:, 2])) < 0.25


def test_preset_along_axis_follows_the_axis(bunny):
    settings().field_preset, settings().field_axis = 'ALONG_AXIS', 'X'
    assert bpy.ops.exsynth.direction_field() == {'FINISHED'}
    field, normals = vectors(bunny), vertex_normals(bunny)
    ok = np.abs(normals[:, 0]) < 0.5  # where x lies well within the tangent plane
    assert np.all(field[ok, 0] > 0.5)


def test_preset_along_curve_in_mesh_space(bunny):
    # A straight line along world Y; the bunny is moved and scaled, so the
    # points must be brought into its local space (where Y is still Y).
    curve = bpy.data.curves.new("Line", 'CURVE')
    spline = curve.splines.new('POLY')
    spline.points.add(1)
    spline.points.foreach_set("co", [3.0, -5.0, 1.0, 1.0, 3.0, 5.0, 1.0, 1.0])
    curve_obj = bpy.data.objects.new("Line", curve)
    bpy.context.collection.objects.link(curve_obj)
    settings().field_preset, settings().field_curve = 'ALONG_CURVE', curve_obj
    assert bpy.ops.exsynth.direction_field() == {'FINISHED'}
    field, normals = vectors(bunny), vertex_normals(bunny)
    # World Y in the bunny's local space (the OBJ import rotates the object).
    local = np.linalg.inv(np.array(bunny.matrix_world)[:3, :3]) @ np.array([0.0, 1.0, 0.0])
    local /= np.linalg.norm(local)
    ok = np.abs(normals @ local) < 0.5
    assert np.median(np.abs(field[ok] @ local)) > 0.9


def test_diffuse_keeps_the_painted_directions(bunny):
    n = len(bunny.data.vertices)
    normals = vertex_normals(bunny)
    painted = np.zeros((n, 3), np.float32)
    idx = np.array([0, n // 3, 2 * n // 3])
    painted[idx] = (1.0, 0.0, 0.0)
    set_vectors(bunny, "exsynth_paint", painted)
    settings().field_mode = 'DIFFUSE'
    assert bpy.ops.exsynth.direction_field() == {'FINISHED'}
    field = vectors(bunny)
    np.testing.assert_allclose(np.linalg.norm(field, axis=1), 1.0, atol=1e-4)
    p = painted[idx] - np.einsum("ij,ij->i", painted[idx], normals[idx])[:, None] * normals[idx]
    p /= np.linalg.norm(p, axis=1, keepdims=True)
    assert np.all(np.einsum("ij,ij->i", field[idx], p) > 0.99)
    assert vectors(bunny, "exsynth_paint").tobytes() == painted.tobytes()  # input untouched


def test_overwrite_then_cancel_keeps_the_old_field(bunny):
    old = np.tile(np.float32([0.25, 0.5, 0.75]), (len(bunny.data.vertices), 1))
    set_vectors(bunny, FIELD, old)
    before = state(bunny)
    jobs.job_started_hooks.append(lambda ctx: ctx.cancel())
    assert bpy.ops.exsynth.direction_field() == {'CANCELLED'}
    assert state(bunny) == before
    jobs.job_started_hooks.clear()
    assert bpy.ops.exsynth.direction_field() == {'FINISHED'}
    assert not np.allclose(vectors(bunny), old)


@pytest.mark.parametrize("existing", [False, True])
def test_failure_after_writing_is_rolled_back(bunny, monkeypatch, existing):
    if existing:
        set_vectors(bunny, FIELD, np.ones((len(bunny.data.vertices), 3)))
    before = state(bunny)

    def fail(*args):
        raise OSError("disk full (test)")

    monkeypatch.setattr(field_ops, "summary", fail)
    with pytest.raises(RuntimeError, match="disk full"):
        bpy.ops.exsynth.direction_field()
    assert state(bunny) == before


def run_expecting_error(match, obj=None):
    before = state(obj) if obj is not None else scene_state()
    with pytest.raises(RuntimeError, match=match):
        bpy.ops.exsynth.direction_field()
    assert (state(obj) if obj is not None else scene_state()) == before


def test_no_active_mesh(bunny):
    bpy.context.view_layer.objects.active = None
    run_expecting_error(r"no active object\. Select the mesh")
    cam = add_camera()
    bpy.context.view_layer.objects.active = cam
    run_expecting_error(r"'Cam' is a camera, not a mesh")


def test_mesh_without_faces():
    obj = add_faceless_mesh()
    run_expecting_error(r"'Dots' has no faces", obj)


def test_painted_attribute_missing(bunny):
    settings().field_mode = 'DIFFUSE'
    run_expecting_error(r"no attribute 'exsynth_paint' to diffuse\. Add one", bunny)


def test_painted_attribute_of_the_wrong_kind(bunny):
    bunny.data.attributes.new("exsynth_paint", 'FLOAT', 'POINT')
    settings().field_mode = 'DIFFUSE'
    run_expecting_error(r"'exsynth_paint' of 'bunny' is float on the point domain.*Vector attribute", bunny)
    bunny.data.attributes.new("corner_paint", 'FLOAT_VECTOR', 'CORNER')
    settings().field_paint_attribute = "corner_paint"
    run_expecting_error(r"float_vector on the corner domain", bunny)


def test_painted_attribute_all_zero(bunny):
    set_vectors(bunny, "exsynth_paint", np.zeros((len(bunny.data.vertices), 3)))
    settings().field_mode = 'DIFFUSE'
    run_expecting_error(r"no non-zero vectors; paint at least one stroke or use a preset", bunny)


def test_existing_field_of_another_kind(bunny):
    bunny.data.attributes.new(FIELD, 'FLOAT_COLOR', 'CORNER')
    run_expecting_error(r"already has an attribute 'exsynth_field' of another kind.*Rename or remove", bunny)


def test_curve_missing_or_not_a_curve(bunny):
    settings().field_preset = 'ALONG_CURVE'
    run_expecting_error(r"needs a curve\. Pick a curve object", bunny)
    # The panel's picker only offers curves, but a script can set anything
    # (attribute assignment: Blender 4.5 refuses an Object through
    # scene.exsynth["field_curve"] once the property exists).
    cam = add_camera()
    bpy.context.scene.exsynth.field_curve = cam
    run_expecting_error(r"'Cam' is a camera, not a curve", bunny)


# ---- CLI ------------------------------------------------------------------------
def obj_faces(path):
    lines = open(path).read().splitlines()
    faces = [[int(t.split("/")[0]) - 1 for t in l.split()[1:]] for l in lines if l.startswith("f ")]
    tris = [(f[0], f[i], f[i + 1]) for f in faces for i in range(1, len(f) - 1)]
    return np.array(tris, np.int64)


def obj_vertices(path):
    lines = open(path).read().splitlines()
    return np.array([l.split()[1:4] for l in lines if l.startswith("v ")], np.float64)


def test_cli_preset_writes_v_by_3(tmp_path, capsys):
    out = tmp_path / "sub" / "field.npy"
    assert cli.main(["field", "--mesh", BUNNY_OBJ, "--preset", "around_axis", "--axis", "y",
                     "--out", str(out)]) == 0
    field = np.load(out)
    verts = obj_vertices(BUNNY_OBJ)
    assert field.dtype == np.float32 and field.shape == verts.shape
    np.testing.assert_allclose(np.linalg.norm(field, axis=1), 1.0, atol=1e-4)
    assert "field:" in capsys.readouterr().out
    # The OBJ's own vertex order and coordinates: the engine on the file's arrays.
    expected = _native.preset_direction_field(verts, obj_faces(BUNNY_OBJ), "around_axis", axis=(0, 1, 0))
    np.testing.assert_allclose(field, expected, atol=1e-5)


def test_cli_paint(tmp_path):
    verts = obj_vertices(BUNNY_OBJ)
    paint = np.zeros_like(verts, dtype=np.float32)
    paint[::500] = (0.0, 0.0, 1.0)
    np.save(tmp_path / "paint.npy", paint)
    out = tmp_path / "field.npy"
    assert cli.main(["field", "--mesh", BUNNY_OBJ, "--paint", str(tmp_path / "paint.npy"),
                     "--out", str(out)]) == 0
    assert np.load(out).shape == verts.shape


def test_cli_bad_arguments(tmp_path, capsys):
    out = str(tmp_path / "f.npy")
    assert cli.main(["field", "--mesh", BUNNY_OBJ, "--preset", "along_curve", "--out", out]) == 2
    assert "needs --curve" in capsys.readouterr().err
    np.save(tmp_path / "bad.npy", np.zeros((3, 3), np.float32))
    assert cli.main(["field", "--mesh", BUNNY_OBJ, "--paint", str(tmp_path / "bad.npy"), "--out", out]) == 2
    assert "one vector per vertex" in capsys.readouterr().err
    np.save(tmp_path / "zero.npy", np.zeros_like(obj_vertices(BUNNY_OBJ), dtype=np.float32))
    assert cli.main(["field", "--mesh", BUNNY_OBJ, "--paint", str(tmp_path / "zero.npy"), "--out", out]) == 2
    assert "no non-zero vectors" in capsys.readouterr().err
