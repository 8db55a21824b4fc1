# SPDX-License-Identifier: GPL-3.0-or-later
"""Smoke test of the modal (UI) path, which `blender -b` cannot exercise:
invoke from a 3D viewport, watch progress, finish; invoke again, press Esc
mid-run, check the scene is unchanged; then open the sidebar's ExSynth tab
(the Solid Texture panels must draw) and run Solid Texture modally; run
Geometric Texture, Point Texture and Surface Texture modally (their panels
must draw) and undo them; then paint a direction field: the overlay draws, a simulated
stroke turns the field its way, Esc ends, undo restores it, and a
screenshot goes to $EXSYNTH_SCREENSHOT (default build/gui_paint.png). Needs a display, e.g. (xvfb package):

    EXSYNTH_ADDON_DIR=build/addon xvfb-run -a -s "-screen 0 1280x800x24" \
        blender --factory-startup --enable-event-simulate --python tests/blender/gui_smoke.py

Not collected by pytest (no test_ prefix). Exits 0 on success, 1 on failure.
"""

import os
import sys
import time
import traceback

import addon_utils
import bpy
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.environ.get("EXSYNTH_ADDON_DIR", os.path.join(ROOT, "build", "addon")))


def _raise(exc):
    raise exc


addon_utils.enable("exsynth", default_set=True, handle_error=_raise)
from exsynth import compat, jobs  # noqa: E402  (needs the path set above)
from exsynth.ui import pattern_preview  # noqa: E402

# EXSYNTH_GUI_FROM=paint_start runs only the last part (when working on it).
state = {"step": os.environ.get("EXSYNTH_GUI_FROM", "start"), "ctx": None, "t0": 0.0}
FROM_START = state["step"] == "start"
jobs.job_started_hooks.append(lambda ctx: state.update(ctx=ctx))


def names():
    return sorted(o.name for o in bpy.data.objects)


def invoke_in_viewport(operator="voxelize"):
    win = bpy.context.window_manager.windows[0]
    area = next(a for a in win.screen.areas if a.type == 'VIEW_3D')
    region = next(r for r in area.regions if r.type == 'WINDOW')
    with bpy.context.temp_override(window=win, screen=win.screen, area=area, region=region):
        return getattr(bpy.ops.exsynth, operator)('INVOKE_DEFAULT')


def check(ok, what):
    print(("PASS " if ok else "FAIL ") + what, flush=True)
    if not ok:
        raise AssertionError(what)


def step():
    try:
        return STEPS[state["step"]]()
    except Exception:
        traceback.print_exc()
        os._exit(1)


def start():
    bpy.data.batch_remove(list(bpy.data.objects))
    bpy.ops.wm.obj_import(filepath=os.path.join(ROOT, "assets", "meshes", "bunny.obj"))
    bpy.context.scene.exsynth.resolution = 160
    check(invoke_in_viewport() == {'RUNNING_MODAL'}, "invoke returns RUNNING_MODAL")
    check(names() == ["bunny"], "nothing is created while the job runs")
    state.update(step="wait_finish", t0=time.monotonic())
    return 0.02


def wait_finish():
    if "bunny_voxels" not in bpy.data.objects:
        if time.monotonic() - state["t0"] > 60:
            check(False, "the job finishes within a minute")
        return 0.02
    check(names() == ["bunny", "bunny_voxel_mesh", "bunny_voxels"], "finish adds the two objects")
    bpy.context.view_layer.objects.active = bpy.data.objects["bunny"]
    bpy.context.scene.exsynth.resolution = 400  # long enough to press Esc mid-way
    state.update(before=names())
    check(invoke_in_viewport() == {'RUNNING_MODAL'}, "second invoke returns RUNNING_MODAL")
    state.update(step="press_esc")
    return 0.01


def press_esc():
    if state["ctx"].progress == 0.0:
        return 0.01
    win = bpy.context.window_manager.windows[0]
    win.event_simulate('ESC', 'PRESS')
    win.event_simulate('ESC', 'RELEASE')
    state.update(step="after_esc", t0=time.monotonic())
    return 0.1


def after_esc():
    if time.monotonic() - state["t0"] < 3.0:
        return 0.1
    check(state["ctx"].cancelled, "Esc cancels the job")
    check(names() == state["before"], "a cancelled run leaves the objects unchanged")
    state.update(step="solid_start")
    return 0.1


# ---- Solid Texture: its panels draw, its modal run finishes -------------------
drawn = set()


def _record_draws(panel_class):
    draw = panel_class.draw

    def recording(self, context):
        draw(self, context)  # an exception propagates: Blender prints it, the flag stays unset
        drawn.add(panel_class.__name__)

    panel_class.draw = recording


def solid_start():
    bpy.data.batch_remove(list(bpy.data.objects))
    bpy.ops.wm.obj_import(filepath=os.path.join(ROOT, "assets", "meshes", "cow.obj"))
    settings = bpy.context.scene.exsynth
    texture = os.path.join(ROOT, "assets", "textures", "crackedground.png")
    settings.solid_exemplar = bpy.data.images.load(texture)
    settings.solid_size, settings.solid_levels, settings.solid_bake_resolution = 32, 2, 256
    for name in ("EXSYNTH_PT_solid", "EXSYNTH_PT_solid_rebake"):
        _record_draws(getattr(bpy.types, name))
    # Open the sidebar and step through its tabs (Ctrl+Wheel) to ExSynth.
    win = bpy.context.window_manager.windows[0]
    area = next(a for a in win.screen.areas if a.type == 'VIEW_3D')
    area.spaces.active.show_region_ui = True
    area.tag_redraw()
    # The start-up splash (still open) takes the mouse events: Esc closes it.
    win.event_simulate('ESC', 'PRESS')
    win.event_simulate('ESC', 'RELEASE')
    state.update(step="find_tab", tabs=0)
    return 0.3


def find_tab():
    if "EXSYNTH_PT_solid" in drawn:
        check("EXSYNTH_PT_solid_rebake" in drawn, "the Solid Texture panels draw without errors")
        check(invoke_in_viewport("solid_texture") == {'RUNNING_MODAL'}, "Solid Texture runs modal")
        state.update(step="solid_finish", t0=time.monotonic())
        return 0.05
    if state["tabs"] >= 8:
        check(False, "the ExSynth sidebar tab draws the Solid Texture panel")
    win = bpy.context.window_manager.windows[0]
    _next_sidebar_tab(win, next(a for a in win.screen.areas if a.type == 'VIEW_3D'))
    return 0.3


def _next_sidebar_tab(win, area):
    """Ctrl+wheel over the sidebar's tab column: the next tab (counted in state)."""
    region = next(r for r in area.regions if r.type == 'UI')
    x, y = region.x + region.width - 8, region.y + region.height - 60
    win.event_simulate('MOUSEMOVE', 'NOTHING', x=x, y=y)
    win.event_simulate('WHEELDOWNMOUSE', 'PRESS', x=x, y=y, ctrl=True)
    area.tag_redraw()
    state["tabs"] += 1


def solid_finish():
    if "cow_solid" not in bpy.data.images:
        if time.monotonic() - state["t0"] > 60:
            check(False, "Solid Texture finishes within a minute")
        return 0.05
    cow = bpy.data.objects["cow"]
    check(cow.material_slots[0].material.name == "cow_solid" and len(cow.data.uv_layers) == 1,
          "Solid Texture bakes an image onto the cow and gives it the material")
    state.update(step="geo_start")
    return 0.1


# ---- Geometric Texture: its panel draws, its modal run finishes, Ctrl+Z undoes it
def _in_viewport(fn):
    win = bpy.context.window_manager.windows[0]
    area = next(a for a in win.screen.areas if a.type == 'VIEW_3D')
    region = next(r for r in area.regions if r.type == 'WINDOW')
    with bpy.context.temp_override(window=win, screen=win.screen, area=area, region=region):
        return fn()


def _record_sphere_draws():
    """The pattern sphere's draw callback got as far as its line shader's
    uniforms (both looked up at call time, so wrapping them here counts)."""
    lines, style = pattern_preview.sphere_lines, compat.set_line_style

    def recording_lines(*args, **kw):
        drawn.add("sphere lines")
        return lines(*args, **kw)

    def recording_style(*args, **kw):
        style(*args, **kw)
        if "sphere lines" in drawn:
            drawn.add("pattern sphere")

    pattern_preview.sphere_lines, compat.set_line_style = recording_lines, recording_style


def geo_start():
    bpy.data.batch_remove(list(bpy.data.objects))
    bpy.ops.wm.obj_import(filepath=os.path.join(ROOT, "assets", "meshes", "bunny.obj"))
    bpy.context.scene.exsynth.geo_resolution = 48
    _record_draws(bpy.types.EXSYNTH_PT_geometric_texture)
    _record_sphere_draws()
    _in_viewport(lambda: bpy.ops.ed.undo_push(message="before Geometric Texture"))
    check(invoke_in_viewport("geometric_texture") == {'RUNNING_MODAL'}, "Geometric Texture runs modal")
    state.update(step="geo_finish", t0=time.monotonic())
    return 0.05


def geo_finish():
    if "bunny_spikes" not in bpy.data.objects:
        if time.monotonic() - state["t0"] > 60:
            check(False, "Geometric Texture finishes within a minute")
        return 0.05
    check(names() == ["bunny", "bunny_spikes"], "Geometric Texture adds 'bunny_spikes'")
    check("EXSYNTH_PT_geometric_texture" in drawn, "the Geometric Texture panel draws without errors")
    check("pattern sphere" in drawn, "the pattern sphere draws at the bunny while the ExSynth sidebar is open")
    _in_viewport(lambda: bpy.ops.ed.undo())
    state.update(step="geo_undone")
    return 0.3


def geo_undone():
    check(names() == ["bunny"], "one undo removes the Geometric Texture result")
    # The panel's other layout: a mesh pair (A set, A′ not yet), field preset along a curve.
    settings = bpy.context.scene.exsynth
    settings.geo_pair_source, settings.geo_field_preset = 'OBJECTS', 'ALONG_CURVE'
    settings.geo_a = bpy.data.objects["bunny"]
    drawn.discard("EXSYNTH_PT_geometric_texture")
    win = bpy.context.window_manager.windows[0]
    next(a for a in win.screen.areas if a.type == 'VIEW_3D').tag_redraw()
    state.update(step="geo_pair_drawn", t0=time.monotonic())
    return 0.3


def geo_pair_drawn():
    if "EXSYNTH_PT_geometric_texture" not in drawn:
        if time.monotonic() - state["t0"] > 10:
            check(False, "the Geometric Texture panel draws with a mesh pair")
        return 0.1
    check(True, "the Geometric Texture panel draws with a mesh pair")
    state.update(step="pts_start")
    return 0.1


# ---- Point Texture: its panel draws, its modal run finishes, Ctrl+Z undoes it
def pts_start():
    bpy.data.batch_remove(list(bpy.data.objects))
    s = bpy.context.scene.exsynth
    s.pts_preset, s.pts_density, s.pts_width, s.pts_depth, s.pts_patch_size = 'WEAVE', 2500.0, 1.5, 1.5, 0.5
    _record_draws(bpy.types.EXSYNTH_PT_point_texture)
    _in_viewport(lambda: bpy.ops.ed.undo_push(message="before Point Texture"))
    check(invoke_in_viewport("point_texture") == {'RUNNING_MODAL'}, "Point Texture runs modal")
    state.update(step="pts_finish", t0=time.monotonic())
    return 0.05


def pts_finish():
    if "weave_points" not in bpy.data.objects:
        if time.monotonic() - state["t0"] > 120:
            check(False, "Point Texture finishes within two minutes")
        return 0.05
    check(names() == ["weave_points"], "Point Texture adds 'weave_points'")
    check("EXSYNTH_PT_point_texture" in drawn, "the Point Texture panel draws without errors")
    _in_viewport(lambda: bpy.ops.ed.undo())
    state.update(step="pts_undone")
    return 0.3


def pts_undone():
    check(names() == [], "one undo removes the Point Texture result")
    state.update(step="surf_start")
    return 0.1


# ---- Surface Texture: its panel draws, its modal run finishes, Ctrl+Z undoes it
def surf_start():
    bpy.ops.mesh.primitive_cube_add(size=1.0)
    bpy.context.active_object.name = "cube"
    s = bpy.context.scene.exsynth
    s.surface_exemplar = bpy.data.images.load(os.path.join(ROOT, "assets", "textures", "crackedground.png"))
    s.surface_method, s.surface_size_mode, s.surface_face_resolution = 'COHERENT', 'FACE', 16
    _record_draws(bpy.types.EXSYNTH_PT_surface)
    _in_viewport(lambda: bpy.ops.ed.undo_push(message="before Surface Texture"))
    check(invoke_in_viewport("surface_texture") == {'RUNNING_MODAL'}, "Surface Texture runs modal")
    state.update(step="surf_finish", t0=time.monotonic())
    return 0.05


def surf_finish():
    if "cube_surface" not in bpy.data.objects:
        if time.monotonic() - state["t0"] > 60:
            check(False, "Surface Texture finishes within a minute")
        return 0.05
    check(names() == ["cube", "cube_surface"], "Surface Texture adds 'cube_surface'")
    check("EXSYNTH_PT_surface" in drawn, "the Surface Texture panel draws without errors")
    _in_viewport(lambda: bpy.ops.ed.undo())
    state.update(step="surf_undone")
    return 0.3


def surf_undone():
    check(names() == ["cube"], "one undo removes the Surface Texture result")
    state.update(step="paint_start")
    return 0.1


# ---- Paint Direction Field: the overlay draws, a simulated stroke turns the
# field its way, Esc ends the tool, one undo restores the field; a screenshot
SCREENSHOT = os.environ.get("EXSYNTH_SCREENSHOT", os.path.join(ROOT, "build", "gui_paint.png"))


def _viewport():
    win = bpy.context.window_manager.windows[0]
    area = next(a for a in win.screen.areas if a.type == 'VIEW_3D')
    return win, area, next(r for r in area.regions if r.type == 'WINDOW')


def _field():
    obj = bpy.data.objects["Sphere"]
    out = np.empty(3 * len(obj.data.vertices), np.float32)
    obj.data.attributes["exsynth_field"].data.foreach_get("vector", out)
    return out.reshape(-1, 3)


def _along_stroke():
    """Mean dot product, near the stroke, of the field with world +x laid
    into the tangent plane (the stroke runs left to right in a top view)."""
    from exsynth import field_brush

    obj = bpy.data.objects["Sphere"]
    co = np.empty(3 * len(obj.data.vertices), np.float32)
    obj.data.vertices.foreach_get("co", co)
    co = co.reshape(-1, 3)
    near = (co[:, 2] > 0.3) & (np.abs(co[:, 1]) < 0.15) & (np.abs(co[:, 0]) < 0.5)
    expect = field_brush.project_tangent([1.0, 0.0, 0.0], field_brush.normalized(co[near]))
    return float(np.mean(np.sum(_field()[near] * expect, axis=1))), int(near.sum())


def paint_start():
    from exsynth import overlay

    bpy.data.batch_remove(list(bpy.data.objects))
    _in_viewport(lambda: bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32, radius=1.0))
    settings = bpy.context.scene.exsynth
    settings.field_mode, settings.field_preset, settings.field_axis = 'PRESET', 'ALONG_AXIS', 'Y'
    settings.geo_show_pattern = False  # the picture shows the field, not Geometric Texture's pattern sphere
    check(bpy.ops.exsynth.direction_field() == {'FINISHED'}, "a preset field along Y to paint over")
    win, area, region = _viewport()
    area.spaces.active.show_region_ui = True
    if not FROM_START:  # the splash is still open and takes the mouse: Esc closes it
        win.event_simulate('ESC', 'PRESS')
        win.event_simulate('ESC', 'RELEASE')
    rv3d = area.spaces.active.region_3d
    rv3d.view_perspective = 'ORTHO'
    rv3d.view_rotation = (1.0, 0.0, 0.0, 0.0)  # top view: screen right = world +x, up = +y
    rv3d.view_location = (0.0, 0.0, 0.0)
    rv3d.view_distance = 3.0
    # For the picture: the Direction Field panel alone in the tab, open (the
    # other panels were drawn and checked above).
    from exsynth import panels

    others = [c for c in panels.CLASSES if c.__name__ != "EXSYNTH_PT_field"]
    for cls in sorted(others, key=lambda c: not getattr(c, "bl_parent_id", "")):  # sub-panels first
        bpy.utils.unregister_class(cls)
    _record_draws(bpy.types.EXSYNTH_PT_field)
    overlay.stats.update(draws=0, vertices=0)
    settings.field_overlay = True
    settings.field_overlay_max_strokes = 1500
    area.tag_redraw()
    state.update(step="paint_overlay", t0=time.monotonic())
    return 0.3


def paint_overlay():
    from exsynth import overlay

    if overlay.stats["draws"] == 0 or overlay.stats["vertices"] == 0:
        if time.monotonic() - state["t0"] > 10:
            check(False, "the field overlay draws strokes")
        _viewport()[1].tag_redraw()
        return 0.1
    check(overlay.stats["object"] == "Sphere" and overlay.stats["vertices"] > 1000,
          f"the field overlay draws strokes ({overlay.stats['vertices'] // 2} strokes)")
    check(overlay.stats["singular"] >= 2, f"the overlay marks the poles of the field along Y as singular "
          f"({overlay.stats['singular']} points)")
    before, n = _along_stroke()
    check(abs(before) < 0.2 and n > 10, f"before painting the field crosses the stroke (mean dot {before:.2f})")
    state["field_before"] = _field().copy()
    _in_viewport(lambda: bpy.ops.ed.undo_push(message="before painting"))
    from exsynth import keymap

    items = [k for k in bpy.context.window_manager.keyconfigs.addon.keymaps["3D View"].keymap_items
             if k.idname == "exsynth.paint_direction_field"]
    check(len(items) == 1 and (items[0].type, items[0].shift, items[0].alt) == ('P', True, True)
          and keymap.PAINT_SHORTCUT["type"] == 'P', "Shift+Alt+P in the 3D viewport starts Paint Direction Field")
    check(invoke_in_viewport("paint_direction_field") == {'RUNNING_MODAL'}, "Paint Direction Field runs modal")
    win, area, region = _viewport()
    cx, cy = region.x + region.width // 2, region.y + region.height // 2
    win.event_simulate('MOUSEMOVE', 'NOTHING', x=cx - 120, y=cy)
    win.event_simulate('LEFTMOUSE', 'PRESS', x=cx - 120, y=cy)
    for dx in range(-110, 121, 10):
        win.event_simulate('MOUSEMOVE', 'NOTHING', x=cx + dx, y=cy)
    state.update(step="paint_release", release=(cx + 120, cy))
    return 0.2


def paint_release():
    win = _viewport()[0]
    x, y = state["release"]
    win.event_simulate('LEFTMOUSE', 'RELEASE', x=x, y=y)
    state.update(step="paint_diffused", t0=time.monotonic())
    return 0.3


def paint_diffused():
    dot, _ = _along_stroke()
    if dot < 0.8:
        if time.monotonic() - state["t0"] > 30:
            check(False, f"the stroke turns the field its way while the tool runs (mean dot {dot:.2f})")
        return 0.2
    check(True, f"the stroke turns the field its way while the tool runs (mean dot {dot:.2f})")
    drawn.discard("EXSYNTH_PT_field")
    _viewport()[1].tag_redraw()
    state.update(step="paint_tab", tabs=0)
    return 0.3


def paint_tab():
    """The sidebar on the ExSynth tab (stepping through tabs with Ctrl+Wheel
    when this part runs alone), then a three-quarter view for the picture."""
    from mathutils import Euler

    win, area, region = _viewport()
    if "EXSYNTH_PT_field" not in drawn:
        if state["tabs"] >= 8:
            check(False, "the Direction Field panel draws while painting")
        _next_sidebar_tab(win, area)
        return 0.3
    check(True, "the Direction Field panel draws while painting")
    rv3d = area.spaces.active.region_3d
    rv3d.view_perspective = 'PERSP'
    rv3d.view_rotation = Euler((0.9, 0.0, 0.5)).to_quaternion()
    rv3d.view_distance = 4.5
    settings = bpy.context.scene.exsynth
    settings.field_overlay_max_strokes, settings.field_overlay_length = 500, 1.0  # fewer, longer: readable
    # The mouse over the sphere (not dragging): the brush circle shows there.
    win.event_simulate('MOUSEMOVE', 'NOTHING', x=region.x + region.width // 2 + 70, y=region.y + region.height // 2 + 40)
    area.tag_redraw()
    state.update(step="paint_screenshot")
    return 0.5


def paint_screenshot():
    win, area, region = _viewport()
    os.makedirs(os.path.dirname(SCREENSHOT), exist_ok=True)
    with bpy.context.temp_override(window=win, screen=win.screen, area=area):
        bpy.ops.screen.screenshot(filepath=SCREENSHOT)
    check(os.path.getsize(SCREENSHOT) > 10000, f"screenshot of the panel and the overlay: {SCREENSHOT}")
    from exsynth.operators import field_paint

    check(field_paint.cursor_draws > 0, "the brush circle draws under the mouse")
    win.event_simulate('ESC', 'PRESS')
    win.event_simulate('ESC', 'RELEASE')
    state.update(step="paint_ended", t0=time.monotonic())
    return 0.5


def paint_ended():
    dot, _ = _along_stroke()
    check(dot > 0.8, f"Esc ends the tool and keeps the stroke (mean dot with the stroke {dot:.2f})")
    check("exsynth_paint" in bpy.data.objects["Sphere"].data.attributes, "the stroke is in 'exsynth_paint'")
    _in_viewport(lambda: bpy.ops.ed.undo())
    state.update(step="paint_undone")
    return 0.3


def paint_undone():
    obj = bpy.data.objects["Sphere"]
    check(np.array_equal(_field(), state["field_before"]) and "exsynth_paint" not in obj.data.attributes,
          "one undo restores the field and removes the paint")
    print("gui_smoke: all passed", flush=True)
    os._exit(0)


STEPS = {"start": start, "wait_finish": wait_finish, "press_esc": press_esc, "after_esc": after_esc,
         "solid_start": solid_start, "find_tab": find_tab, "solid_finish": solid_finish,
         "geo_start": geo_start, "geo_finish": geo_finish, "geo_undone": geo_undone,
         "geo_pair_drawn": geo_pair_drawn, "pts_start": pts_start, "pts_finish": pts_finish,
         "pts_undone": pts_undone, "surf_start": surf_start, "surf_finish": surf_finish,
         "surf_undone": surf_undone, "paint_start": paint_start, "paint_overlay": paint_overlay,
         "paint_release": paint_release, "paint_diffused": paint_diffused, "paint_tab": paint_tab,
         "paint_screenshot": paint_screenshot,
         "paint_ended": paint_ended, "paint_undone": paint_undone}
bpy.app.timers.register(step, first_interval=1.0)
