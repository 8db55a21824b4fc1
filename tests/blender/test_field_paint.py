# SPDX-License-Identifier: GPL-3.0-or-later
"""Paint Direction Field on real meshes: the tool's stroke application
(PaintSession, the part the modal operator drives), erase, mirror, comb,
cancel and undo; its bad inputs; the field overlay's data and toggle. The
modal tool itself, with simulated mouse strokes, runs in gui_smoke.py."""

import bpy
import numpy as np
import pytest

from exsynth import field_brush, overlay
from exsynth.operators import field_paint_session
from helpers import add_camera, add_faceless_mesh, scene_state

FIELD, PAINT = "exsynth_field", "exsynth_paint"


def vectors(obj, name):
    out = np.empty(3 * len(obj.data.vertices), np.float32)
    obj.data.attributes[name].data.foreach_get("vector", out)
    return out.reshape(-1, 3)


def world(obj):
    co = np.empty(3 * len(obj.data.vertices), np.float32)
    obj.data.vertices.foreach_get("co", co)
    m = np.array(obj.matrix_world)
    return co.reshape(-1, 3) @ m[:3, :3].T + m[:3, 3]


def state(obj):
    s = scene_state()
    s["attributes"] = {a.name: (a.domain, a.data_type, vectors(obj, a.name).tobytes() if a.data_type == 'FLOAT_VECTOR'
                                and a.domain == 'POINT' else None) for a in obj.data.attributes
                       if not a.name.startswith(".")}
    return s


@pytest.fixture
def sphere():
    """A UV sphere of radius 1, moved and scaled non-uniformly (world distances differ from local)."""
    bpy.ops.mesh.primitive_uv_sphere_add(segments=48, ring_count=24, radius=1.0, location=(2.0, 1.0, -1.0))
    obj = bpy.context.active_object
    obj.scale = (1.5, 1.0, 1.0)
    bpy.context.view_layer.update()
    return obj


def stroke(session, obj, start, end, samples=12, radius=0.3, mode='PAINT', mirror=()):
    """A stroke between two world points on the surface: each sample at the
    nearest vertex, its direction the stroke's, as the tool computes them."""
    w = world(obj)
    session.begin_stroke()
    for p in np.linspace(start, end, samples):
        centre = w[np.argmin(np.linalg.norm(w - p, axis=1))]
        session.apply(centre, np.subtract(end, start), radius, mode, mirror)
    session.end_stroke()


def test_a_stroke_paints_and_diffuses_along_its_direction(sphere):
    session = field_paint_session.PaintSession(sphere, PAINT)
    # Around the equator's front (world -y side), running along world x.
    stroke(session, sphere, (1.0, 0.0, -1.0), (3.0, 0.0, -1.0))
    session.finish()
    assert session.diffuser.runs == 1  # the release's diffusion is not repeated by finish()
    paint, field = vectors(sphere, PAINT), vectors(sphere, FIELD)
    painted = np.any(paint != 0, axis=1)
    assert 20 < painted.sum() < len(paint) / 2
    # Painted directions: world x (local x too: the scale is along x) laid into each tangent plane.
    co = np.empty(3 * len(sphere.data.vertices), np.float32)
    sphere.data.vertices.foreach_get("co", co)
    sphere.data.calc_loop_triangles()
    tris = np.empty(3 * len(sphere.data.loop_triangles), np.int32)
    sphere.data.loop_triangles.foreach_get("vertices", tris)
    normals = field_brush.vertex_normals(co.reshape(-1, 3), tris.reshape(-1, 3))
    expect = field_brush.project_tangent([1.0, 0.0, 0.0], normals[painted])
    assert np.min(np.sum(paint[painted] * expect, axis=1)) > 0.999
    np.testing.assert_allclose(np.linalg.norm(paint[painted], axis=1), 1.0, atol=1e-5)
    # The diffused field: unit everywhere, along x near the stroke.
    np.testing.assert_allclose(np.linalg.norm(field, axis=1), 1.0, atol=1e-4)
    near = np.linalg.norm(world(sphere) - (2.0, 0.0, -1.0), axis=1) < 0.6
    assert np.mean(field[near] @ np.array([1.0, 0.0, 0.0])) > 0.9


def test_mirror_paints_the_mirrored_side_with_the_mirrored_direction(sphere):
    session = field_paint_session.PaintSession(sphere, PAINT)
    # On the local +x side (world x = 2 + 1.5), running along local +z then mirrored across local x.
    session.begin_stroke()
    for z in np.linspace(-0.3, 0.3, 8):
        local = np.array([np.sqrt(1 - z * z), 0.0, z])
        centre = np.array(sphere.matrix_world) @ np.append(local, 1.0)
        session.apply(centre[:3], (0.2, 0.0, 1.0), 0.25, 'PAINT', mirror_axes=[0])
    session.end_stroke()
    paint = vectors(sphere, PAINT)
    co = np.empty(3 * len(sphere.data.vertices), np.float32)
    sphere.data.vertices.foreach_get("co", co)
    co = co.reshape(-1, 3)
    right, left = np.any(paint != 0, axis=1) & (co[:, 0] > 0), np.any(paint != 0, axis=1) & (co[:, 0] < 0)
    assert right.sum() > 5 and abs(int(left.sum()) - int(right.sum())) <= 2
    # Mirrored across x: the x component flips sign, z stays.
    assert np.mean(paint[right, 2]) > 0.8 and np.mean(paint[left, 2]) > 0.8
    assert np.mean(paint[right, 0]) * np.mean(paint[left, 0]) <= 0.0


def test_erase_removes_constraints_and_comb_bends_the_field(sphere):
    session = field_paint_session.PaintSession(sphere, PAINT)
    stroke(session, sphere, (1.0, 0.0, -1.0), (3.0, 0.0, -1.0))
    before = np.count_nonzero(np.any(session.constraints != 0, axis=1))
    stroke(session, sphere, (1.6, 0.0, -1.0), (2.4, 0.0, -1.0), mode='ERASE', radius=0.25)
    after = np.count_nonzero(np.any(session.constraints != 0, axis=1))
    assert 0 < after < before
    session.finish()
    field_x = vectors(sphere, FIELD).copy()
    # Comb upwards (world z) over the front: directions turn towards z there.
    near = np.linalg.norm(world(sphere) - (2.0, 0.0, -1.0), axis=1) < 0.3
    stroke(session, sphere, (2.0, 0.0, -1.3), (2.0, 0.0, -0.7), mode='COMB', samples=16)
    session.finish()
    combed = vectors(sphere, FIELD)
    assert np.mean(np.abs(combed[near, 2])) > np.mean(np.abs(field_x[near, 2])) + 0.3


def test_in_tool_undo_and_stroke_cancel(sphere):
    session = field_paint_session.PaintSession(sphere, PAINT)
    stroke(session, sphere, (1.0, 0.0, -1.0), (3.0, 0.0, -1.0))
    first = session.constraints.copy()
    stroke(session, sphere, (2.0, 0.0, -2.0), (2.0, 0.0, 0.0))
    assert session.undo_stroke()
    np.testing.assert_array_equal(session.constraints, first)
    np.testing.assert_array_equal(vectors(sphere, PAINT), first)
    session.begin_stroke()
    session.apply(world(sphere)[0], (1.0, 0.0, 0.0), 0.5)
    session.cancel_stroke()
    np.testing.assert_array_equal(session.constraints, first)
    assert session.undo_stroke() and not session.undo_stroke()
    assert not np.any(session.constraints)


def test_cancel_restores_the_attributes(sphere):
    # Existing field and paint: put back value for value.
    bpy.context.scene.exsynth.field_preset = 'AROUND_AXIS'
    assert bpy.ops.exsynth.direction_field() == {'FINISHED'}
    before = state(sphere)
    session = field_paint_session.PaintSession(sphere, PAINT)
    stroke(session, sphere, (1.0, 0.0, -1.0), (3.0, 0.0, -1.0))
    session.finish()
    assert state(sphere) != before and session.changed()
    session.restore()
    assert state(sphere) == before


def test_cancel_removes_attributes_it_created(sphere):
    before = state(sphere)
    session = field_paint_session.PaintSession(sphere, PAINT)
    stroke(session, sphere, (1.0, 0.0, -1.0), (3.0, 0.0, -1.0))
    session.finish()
    assert PAINT in sphere.data.attributes and FIELD in sphere.data.attributes
    session.restore()
    assert state(sphere) == before


def test_undo_after_painting_restores_the_field(sphere):
    bpy.ops.ed.undo_push(message="before painting")
    session = field_paint_session.PaintSession(sphere, PAINT)
    stroke(session, sphere, (1.0, 0.0, -1.0), (3.0, 0.0, -1.0))
    session.finish()
    bpy.ops.ed.undo_push(message="Paint Direction Field")
    assert FIELD in bpy.data.objects[sphere.name].data.attributes
    bpy.ops.ed.undo()
    assert FIELD not in bpy.data.objects["Sphere"].data.attributes


# ---- bad inputs -------------------------------------------------------------
def run_expecting_error(match):
    before = scene_state()
    with pytest.raises(RuntimeError, match=match):
        bpy.ops.exsynth.paint_direction_field()
    assert scene_state() == before


def test_no_active_object(sphere):
    bpy.context.view_layer.objects.active = None
    run_expecting_error(r"no active object\. Select the mesh to paint")


def test_not_a_mesh(sphere):
    bpy.context.view_layer.objects.active = add_camera()
    run_expecting_error(r"'Cam' is a camera, not a mesh")


def test_no_faces():
    add_faceless_mesh()
    run_expecting_error(r"'Dots' has no faces")


def test_painted_attribute_of_another_kind(sphere):
    sphere.data.attributes.new(PAINT, 'FLOAT', 'POINT')
    run_expecting_error(r"'exsynth_paint' of 'Sphere' is float on the point domain")


def test_headless_call_says_it_is_interactive(sphere):
    run_expecting_error(r"interactive")


def test_zero_brush_radius_changes_nothing(sphere):
    before = state(sphere)
    session = field_paint_session.PaintSession(sphere, PAINT)
    for radius in (0.0, -1.0, float("nan")):
        with pytest.raises(ValueError, match="brush radius must be a positive number"):
            session.apply(world(sphere)[0], (1.0, 0.0, 0.0), radius)
    assert not np.any(session.constraints) and state(sphere) == before


# ---- the overlay's data ------------------------------------------------------
def test_overlay_toggle_adds_and_removes_the_draw_handler(sphere):
    settings = bpy.context.scene.exsynth
    assert not overlay.enabled()
    settings.field_overlay = True
    assert overlay.enabled()
    settings.field_overlay = False
    assert not overlay.enabled()


def test_overlay_draws_only_the_side_facing_the_view(sphere):
    import math
    from types import SimpleNamespace as NS

    from mathutils import Euler, Matrix, Vector

    settings = bpy.context.scene.exsynth
    settings.field_preset, settings.field_axis = 'AROUND_AXIS', 'Z'
    assert bpy.ops.exsynth.direction_field() == {'FINISHED'}
    sphere.location, sphere.scale = (3.0, 0.0, 0.0), (1.0, 2.0, 0.5)  # the test runs in object space
    bpy.context.view_layer.update()
    geo = overlay.geometry(sphere, settings)
    # A view from +X, 10 units from the sphere's centre, looking at it (a
    # camera rotated (90°, 0, 90°) looks along -X).
    view_to_world = Matrix.Translation(Vector((13.0, 0.0, 0.0))) @ Euler((math.pi / 2, 0.0, math.pi / 2)).to_matrix().to_4x4()
    for perspective in (True, False):
        shown = overlay.visible(geo, sphere, NS(view_matrix=view_to_world.inverted(), is_perspective=perspective))
        tails = shown["segments"][0::2]
        assert 0.3 * len(geo["segments"]) < len(shown["segments"]) < 0.7 * len(geo["segments"])
        assert np.all(tails[:, 0] > -0.1)  # object space: the +X half, seen from +X
        # Around Z the poles are singular: square to the view, most are left out.
        assert len(geo["singular"]) >= 2 and len(shown["singular"]) <= len(geo["singular"]) // 2


def test_overlay_geometry_follows_the_field_and_survives_odd_objects(sphere):
    settings = bpy.context.scene.exsynth
    ctx = bpy.context
    assert overlay.field_object(ctx) is None  # no field yet
    settings.field_preset, settings.field_axis = 'AROUND_AXIS', 'Z'
    assert bpy.ops.exsynth.direction_field() == {'FINISHED'}
    assert overlay.field_object(ctx) == sphere
    settings.field_overlay_max_strokes = 200
    geo = overlay.geometry(sphere, settings)
    seg = geo["segments"]
    assert 0 < len(seg) // 2 <= 200
    d = seg[1::2] - seg[0::2]
    assert np.all(np.abs(d[:, 2]) < 0.5 * np.linalg.norm(d, axis=1) + 1e-6)  # mostly horizontal around z
    # Around z on a sphere: the two poles are singular.
    assert len(geo["singular"]) >= 2
    bpy.context.view_layer.objects.active = add_camera()
    assert overlay.field_object(ctx) is None
    bpy.data.objects.remove(sphere)
    bpy.context.view_layer.objects.active = None
    assert overlay.field_object(ctx) is None


def test_compat_names_the_gpu_shaders_for_this_blender():
    from exsynth import compat

    expect = "UNIFORM_COLOR" if bpy.app.version >= (4, 0, 0) else "3D_UNIFORM_COLOR"
    assert compat.builtin_shader_name("UNIFORM_COLOR") == expect
    assert compat.builtin_shader_name("POLYLINE_SMOOTH_COLOR").endswith("POLYLINE_SMOOTH_COLOR")


def test_overlay_follows_the_toggle_of_an_opened_file(sphere, tmp_path):
    settings = bpy.context.scene.exsynth
    settings.field_overlay = True
    path = str(tmp_path / "overlay_on.blend")
    bpy.ops.wm.save_as_mainfile(filepath=path, copy=True)
    settings.field_overlay = False
    assert not overlay.enabled()
    bpy.ops.wm.open_mainfile(filepath=path)
    assert overlay.enabled() and bpy.context.scene.exsynth.field_overlay
    bpy.ops.wm.read_homefile(use_empty=True)
    assert not overlay.enabled()


def test_overlay_geometry_of_a_faceless_or_hidden_mesh():
    obj = add_faceless_mesh()
    attr = obj.data.attributes.new(FIELD, 'FLOAT_VECTOR', 'POINT')
    attr.data.foreach_set("vector", np.tile([1.0, 0.0, 0.0], 3).astype(np.float32))
    settings = bpy.context.scene.exsynth
    assert overlay.field_object(bpy.context) == obj
    geo = overlay.geometry(obj, settings)
    assert len(geo["segments"]) == 6 and len(geo["singular"]) == 0
    obj.hide_set(True)
    assert overlay.field_object(bpy.context) is None


def test_strokes_start_only_over_the_open_viewport_not_its_sidebar():
    from types import SimpleNamespace as NS

    from exsynth.operators import field_paint

    # A 3D viewport 1000 x 600 at (100, 50) whose sidebar (300 wide) and header overlap its main region.
    window = NS(type='WINDOW', x=100, y=50, width=1000, height=600)
    sidebar = NS(type='UI', x=800, y=50, width=300, height=570)
    header = NS(type='HEADER', x=100, y=620, width=1000, height=30)
    hidden = NS(type='TOOLS', x=100, y=50, width=1, height=600)  # a closed toolbar is 1 pixel wide
    area = NS(type='VIEW_3D', regions=[header, hidden, sidebar, window], spaces=NS(active=NS(region_3d="rv3d")))
    context = NS(area=area)

    def at(x, y):
        return field_paint._view_region(context, NS(mouse_x=x, mouse_y=y))

    assert at(400, 300) == (window, "rv3d", 300, 250)
    assert at(100, 300) == (window, "rv3d", 0, 250)  # over the closed toolbar
    assert at(900, 300) is None  # over the sidebar
    assert at(400, 630) is None  # over the header
    assert at(50, 300) is None  # outside the area
    assert field_paint._view_region(NS(area=None), NS(mouse_x=400, mouse_y=300)) is None


def _paint_shortcuts():
    keymap = bpy.context.window_manager.keyconfigs.addon.keymaps.get("3D View")
    return [k for k in keymap.keymap_items if k.idname == "exsynth.paint_direction_field"] if keymap else []


def test_shift_alt_p_starts_the_paint_tool_and_clashes_with_nothing():
    import exsynth

    (item,) = _paint_shortcuts()
    assert (item.type, item.value, item.shift, item.alt, item.ctrl) == ('P', 'PRESS', True, True, False)
    default = bpy.context.window_manager.keyconfigs.default
    clashes = [(km.name, k.idname) for km in default.keymaps for k in km.keymap_items
               if k.active and (k.type, k.shift, k.alt, k.ctrl, k.oskey) == ('P', True, True, False, False)]
    assert clashes == []
    exsynth.unregister()
    try:
        assert _paint_shortcuts() == []  # disabling the add-on takes its shortcut away
    finally:
        exsynth.register()
    assert len(_paint_shortcuts()) == 1
