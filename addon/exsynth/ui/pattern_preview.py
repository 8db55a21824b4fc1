# SPDX-License-Identifier: GPL-3.0-or-later
"""Geometric Texture's pattern size before running: the value the panel shows
(in scene units) and a wire sphere of that size drawn at the active mesh.

With Fit to Model on, the size comes from the mesh's thickness
(operators.analogy.fitted_pattern_scale, the same call the operator makes).
The measure takes 0.2–0.8 s on the bundled meshes, too long for a draw
callback: moving the object redraws the viewport at every mouse step and
each step is a new mesh state. So it runs on a worker thread (the engine
releases the GIL; the thread touches no bpy data), one at a time; until it
ends the panel says "measuring" and the sphere keeps the last size. A
timer on the main thread redraws the viewport when a measure ends, and the
redraw asks for the newest state, so a drag costs one measure at a time.

The sphere is drawn only in 3D views whose sidebar is open on the ExSynth
tab (Blender 3.4 cannot tell the tab: there, whenever the sidebar is open),
so artists who never open Geometric Texture do not see it.
"""

import math
import threading

import bpy
import numpy as np

from .. import compat
from ..io import mesh as mesh_io
from ..jobs import InputError
from ..operators import analogy as analogy_ops
from .redraw import tag_3d_views

COLOR = (1.0, 0.55, 0.1, 0.9)
SEGMENTS = 64
_cache = {}
_handle = None
_worker = {"thread": None, "last": None}  # the measure running; (object name, info) of the last done


def _state_key(obj, resolution, fit, manual_scale):
    """What the measure depends on, cheap enough for every redraw: the mesh
    (its pointer, size and a checksum of its coordinates), the transform,
    the modifiers and the settings."""
    mesh = obj.data
    co = np.empty(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("co", co)
    modifiers = tuple((m.type, m.show_viewport) for m in obj.modifiers)
    matrix = tuple(round(x, 6) for row in obj.matrix_world for x in row)
    return (obj.name, mesh.as_pointer(), len(co), float(co.sum(dtype=np.float64)), matrix, modifiers,
            resolution, fit, None if fit else manual_scale)


def pattern_for(context, obj, wait=False):
    """{'scale', 'size', 'thickness', 'centre'} for `obj` with the scene's
    settings (size and thickness in world units; thickness None when set by
    hand), {'error': message}, or {'pending': True, 'last': the previous
    info or None} while the thickness is measured on a worker thread (wait:
    block until it is). None when obj is not a mesh."""
    if obj is None or obj.type != 'MESH':
        return None
    settings = context.scene.exsynth
    key = _state_key(obj, settings.geo_resolution, settings.geo_pattern_fit, settings.geo_pattern_scale)
    found = _cache.get(obj.name)
    if found is not None and found[0] == key:
        return found[1]
    running = _worker["thread"]
    if running is not None and running.is_alive():
        if not wait:
            return _pending(obj.name)
        running.join()
        return pattern_for(context, obj, wait)
    # The view layer's graph as it stands: drawing must not re-evaluate it.
    verts, tris = mesh_io.world_triangles([obj], context.view_layer.depsgraph)
    if len(tris) == 0 or not settings.geo_pattern_fit:
        _store(key, obj.name, _measure(verts, tris, settings.geo_resolution, None, settings.geo_pattern_scale))
        return _cache[obj.name][1]
    name, resolution = obj.name, settings.geo_resolution  # read here: the thread must not touch bpy

    def work():
        try:
            info = _measure(verts, tris, resolution, True)
        except Exception as exc:  # e.g. over the memory budget: said in the panel, not retried at every redraw
            info = {"error": f"cannot measure the model ({exc})"}
        _store(key, name, info)

    thread = threading.Thread(target=work, name="exsynth pattern size", daemon=True)
    _worker["thread"] = thread
    thread.start()
    if wait:
        thread.join()
        return _cache[obj.name][1]
    bpy.app.timers.register(_redraw_when_measured, first_interval=0.05)
    return _pending(obj.name)


def _pending(name):
    last = _worker["last"]
    return {"pending": True, "last": last[1] if last is not None and last[0] == name else None}


def _measure(verts, tris, resolution, fit, manual_scale=None):
    """The pattern info of a world-space mesh (no bpy: runs on the worker)."""
    if len(tris) == 0:
        return {"error": "no faces"}
    lo, hi = verts.min(axis=0), verts.max(axis=0)
    longest = float((hi - lo).max())
    info = {"centre": tuple(0.5 * (lo + hi)), "thickness": None}
    try:
        if fit:
            info["scale"], measure = analogy_ops.fitted_pattern_scale(verts, tris, resolution)
            info["thickness"] = measure["thickness"]
        else:
            info["scale"] = manual_scale
        info["size"] = info["scale"] * longest
    except InputError as exc:
        info = {"error": str(exc)}
    return info


def _store(key, name, info):
    _cache.clear()  # one mesh at a time: the active one
    _cache[name] = (key, info)
    _worker["last"] = (name, info)


def _redraw_when_measured():
    """Timer (main thread): poll the worker; when it is done, redraw the 3D
    views and the sidebar so they show the size (and ask for a newer state)."""
    thread = _worker["thread"]
    if thread is not None and thread.is_alive():
        return 0.05
    tag_3d_views()
    return None


def length_text(context, value):
    """`value` (world units) as the scene's units show lengths."""
    units = context.scene.unit_settings
    if units.system == 'NONE':
        return f"{value:.3g}"
    return bpy.utils.units.to_string(units.system, 'LENGTH', value * units.scale_length, precision=3)


def sphere_lines(centre, radius, segments=SEGMENTS):
    """Three great circles (XY, YZ, ZX) as line-segment end points."""
    a = np.linspace(0.0, 2.0 * math.pi, segments + 1)
    ring = np.stack([np.cos(a), np.sin(a)], axis=1) * radius
    lines = []
    for u, v in ((0, 1), (1, 2), (2, 0)):
        pts = np.zeros((segments + 1, 3))
        pts[:, u], pts[:, v] = ring[:, 0], ring[:, 1]
        pts += np.asarray(centre)
        lines.append(np.repeat(pts, 2, axis=0)[1:-1])
    return np.concatenate(lines).astype(np.float32)


def sidebar_shows_exsynth(space, area):
    """True when a 3D view's sidebar is open on the ExSynth tab (where
    Geometric Texture is), or open on an unknown tab (Blender 3.4)."""
    from ..panels.main import CATEGORY  # here: the panels import this module
    if space is None or area is None or not getattr(space, "show_region_ui", False):
        return False
    for region in area.regions:
        if region.type == 'UI':
            tab = compat.sidebar_tab(region)
            return tab is None or tab == CATEGORY
    return False


def _draw():
    context = bpy.context
    settings = getattr(context.scene, "exsynth", None)
    obj = context.active_object
    if settings is None or not settings.geo_show_pattern or settings.geo_pair_source != 'BUILTIN':
        return
    if not sidebar_shows_exsynth(context.space_data, context.area):
        return
    if obj is None or obj.type != 'MESH' or context.mode != 'OBJECT':
        return
    info = pattern_for(context, obj)
    if info and "pending" in info:
        info = info["last"]
    if not info or "error" in info:
        return
    import gpu
    from gpu_extras.batch import batch_for_shader

    shader = compat.line_shader()
    batch = batch_for_shader(shader, 'LINES', {"pos": sphere_lines(info["centre"], 0.5 * info["size"])})
    gpu.state.blend_set('ALPHA')
    shader.bind()
    compat.set_line_style(shader, COLOR, 2.0)
    batch.draw(shader)
    gpu.state.blend_set('NONE')


def attach():
    global _handle
    if _handle is None:
        _handle = bpy.types.SpaceView3D.draw_handler_add(_draw, (), 'WINDOW', 'POST_VIEW')


def detach():
    global _handle
    if _handle is not None:
        bpy.types.SpaceView3D.draw_handler_remove(_handle, 'WINDOW')
        _handle = None
    _cache.clear()
    thread = _worker["thread"]
    if thread is not None:
        thread.join()  # the add-on's module may go away with it
    _worker.update(thread=None, last=None)
