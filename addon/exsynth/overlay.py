# SPDX-License-Identifier: GPL-3.0-or-later
"""The field overlay: the active mesh's `exsynth_field` drawn in the 3D
viewport as short strokes coloured from tail (dark blue) to head (yellow),
with its singular points (red) and clashes (orange, where neighbouring
directions point more than 90 degrees apart) marked. Drawn from the
attribute whatever made it (preset, painting, script).

The draw handler exists only while the overlay is on (Direction Field panel
› Show Field), so it costs nothing when off. The geometry is rebuilt only
when the mesh, its field or the overlay settings change. What to draw is
computed by exsynth.field_glyphs (no bpy); this file reads the mesh and
talks to the gpu module (shader names through compat).
"""

import bpy
import numpy as np

from . import compat, field_glyphs
from .ui.redraw import tag_3d_views

FIELD_ATTRIBUTE = "exsynth_field"
TAIL_COLOUR = (0.05, 0.25, 0.9, 1.0)
HEAD_COLOUR = (1.0, 0.9, 0.1, 1.0)
SINGULAR_COLOUR = (1.0, 0.1, 0.1, 1.0)
CLASH_COLOUR = (1.0, 0.5, 0.0, 1.0)

_handle = None
# Set by the paint tool while a stroke is dragged: on meshes above
# LIVE_SINGULARITY_LIMIT vertices the singularity pass (~0.5 s at 100 k under
# load) would stall the brush at every diffusion, so it waits for the release.
stroking = False
LIVE_SINGULARITY_LIMIT = 50000
# What the last draw did (the GUI smoke test reads it): draws counted, stroke
# vertices, singular points and clashes in the last one's geometry, and the
# stroke vertices on the side facing the view (the ones drawn).
stats = {"draws": 0, "vertices": 0, "singular": 0, "clashes": 0, "shown_vertices": 0, "object": None}
_cache = {"key": None, "geometry": None, "topology_key": None, "topology": None, "batches": None,
          "facing": None, "visible": None}


def enabled():
    return _handle is not None


def enable():
    global _handle
    if _handle is None:
        _handle = bpy.types.SpaceView3D.draw_handler_add(_draw, (), 'WINDOW', 'POST_VIEW')
    tag_3d_views()


def disable():
    global _handle
    if _handle is not None:
        bpy.types.SpaceView3D.draw_handler_remove(_handle, 'WINDOW')
        _handle = None
    _cache.update(key=None, geometry=None, topology_key=None, topology=None, batches=None, facing=None, visible=None)
    tag_3d_views()


def sync(settings, _context=None):
    """The property update of `field_overlay`: handler on or off."""
    if settings.field_overlay:
        enable()
    else:
        disable()


def field_object(context):
    """The active object if it is a mesh in Object Mode with a usable
    `exsynth_field`, else None (deleted, not a mesh, no field...)."""
    try:
        obj = context.active_object
        if obj is None or obj.type != 'MESH' or obj.mode == 'EDIT' or not obj.visible_get():
            return None
        attr = obj.data.attributes.get(FIELD_ATTRIBUTE)
        if attr is None or (attr.domain, attr.data_type) != ('POINT', 'FLOAT_VECTOR'):
            return None
        return obj
    except (ReferenceError, AttributeError):
        return None


def _mesh_arrays(mesh):
    n = len(mesh.vertices)
    co = np.empty(3 * n, np.float32)
    mesh.vertices.foreach_get("co", co)
    field = np.empty(3 * n, np.float32)
    mesh.attributes[FIELD_ATTRIBUTE].data.foreach_get("vector", field)
    mesh.calc_loop_triangles()
    tris = np.empty(3 * len(mesh.loop_triangles), np.int32)
    mesh.loop_triangles.foreach_get("vertices", tris)
    return co.reshape(-1, 3), field.reshape(-1, 3), tris.reshape(-1, 3)


def geometry(obj, settings):
    """What the overlay draws for `obj` (mesh space): a dict with segments
    (2 k, 3), singular (S, 3), clashes (C, 3); cached on the mesh, its field
    and the settings."""
    mesh = obj.data
    co, field, tris = _mesh_arrays(mesh)
    key = (mesh.as_pointer(), len(co), len(tris), hash(co.tobytes()), hash(field.tobytes()),
           settings.field_overlay_max_strokes, round(settings.field_overlay_length, 6),
           settings.field_overlay_singularities, stroking and len(co) > LIVE_SINGULARITY_LIMIT)
    if key == _cache["key"]:
        return _cache["geometry"]
    topology_key = (mesh.as_pointer(), len(co), hash(tris.tobytes()), hash(co.tobytes()),
                    settings.field_overlay_max_strokes)
    if topology_key != _cache["topology_key"]:
        from .field_brush import vertex_normals

        _cache["topology"] = {
            "normals": vertex_normals(co, tris),
            "edge": field_glyphs.mean_edge_length(co, tris),
            "edges": field_glyphs.mesh_edges(tris),
            "strokes": field_glyphs.stroke_indices(co, tris, settings.field_overlay_max_strokes),
        }
        _cache["topology_key"] = topology_key
    topo = _cache["topology"]
    idx, spacing = topo["strokes"]
    lift = 0.05 * topo["edge"]
    drawn = field_glyphs.drawable(field, idx)
    out = {"segments": field_glyphs.drawable_strokes(co, topo["normals"], field, drawn,
                                                     settings.field_overlay_length * spacing, lift),
           "segment_normals": topo["normals"][drawn]}
    deferred = stroking and len(co) > LIVE_SINGULARITY_LIMIT
    if settings.field_overlay_singularities and len(tris) and not deferred:
        out.update(field_glyphs.singular_points(co, tris, field, topo["normals"], lift, edges=topo["edges"]))
    else:
        none = np.zeros((0, 3), np.float32)
        out.update(singular=none, singular_normals=none, clashes=none, clash_normals=none)
    _cache.update(key=key, geometry=out, batches=None, facing=None)
    return out


def visible(geo, obj, region_data):
    """The part of `geo` on the side of the model facing the view (see
    field_glyphs.facing), cached on which marks face it."""
    to_object = obj.matrix_world.inverted()
    view_to_world = region_data.view_matrix.inverted()
    if region_data.is_perspective:
        view = {"eye": np.array(to_object @ view_to_world.translation)}
    else:  # the view's +Z, toward the viewer, as a direction in object space
        view = {"toward_viewer": np.array(to_object.to_3x3() @ view_to_world.col[2].xyz)}
    masks = (field_glyphs.facing(geo["segments"][0::2], geo["segment_normals"], **view),
             field_glyphs.facing(geo["singular"], geo["singular_normals"], **view),
             field_glyphs.facing(geo["clashes"], geo["clash_normals"], **view))
    key = tuple(hash(m.tobytes()) for m in masks)
    if key != _cache.get("facing"):
        seg = geo["segments"].reshape(-1, 2, 3)[masks[0]].reshape(-1, 3)
        _cache.update(facing=key, batches=None,
                      visible={"segments": seg, "singular": geo["singular"][masks[1]], "clashes": geo["clashes"][masks[2]]})
    return _cache["visible"]


def _batches(geo):
    from gpu_extras.batch import batch_for_shader

    if _cache["batches"] is None:
        lines = compat.builtin_shader('POLYLINE_SMOOTH_COLOR')
        points = compat.point_shader()
        seg = geo["segments"]
        colours = np.empty((len(seg), 4), np.float32)
        colours[0::2], colours[1::2] = TAIL_COLOUR, HEAD_COLOUR
        # An empty vertex buffer is refused by some releases: no batch instead.
        _cache["batches"] = {
            "lines": (lines, batch_for_shader(lines, 'LINES', {"pos": seg, "color": colours}) if len(seg) else None),
            "singular": (points, batch_for_shader(points, 'POINTS', {"pos": geo["singular"]})
                         if len(geo["singular"]) else None),
            "clashes": (points, batch_for_shader(points, 'POINTS', {"pos": geo["clashes"]})
                        if len(geo["clashes"]) else None),
        }
    return _cache["batches"]


def _draw():
    import gpu

    context = bpy.context
    settings = getattr(context.scene, "exsynth", None)
    if settings is None or not settings.field_overlay:
        return
    obj = field_object(context)
    if obj is None:
        stats.update(object=None, vertices=0, singular=0, clashes=0, shown_vertices=0)
        return
    geo = geometry(obj, settings)
    shown = visible(geo, obj, context.region_data)
    batches = _batches(shown)
    gpu.state.depth_test_set('LESS_EQUAL')
    gpu.state.blend_set('ALPHA')
    gpu.matrix.push()
    try:
        gpu.matrix.multiply_matrix(obj.matrix_world)
        shader, batch = batches["lines"]
        if batch is not None:
            shader.bind()
            shader.uniform_float("viewportSize", gpu.state.viewport_get()[2:])
            shader.uniform_float("lineWidth", 2.0)
            batch.draw(shader)
        for name, colour in (("clashes", CLASH_COLOUR), ("singular", SINGULAR_COLOUR)):
            shader, batch = batches[name]
            if batch is None:
                continue
            shader.bind()
            shader.uniform_float("color", colour)
            compat.set_point_size(shader, 7.0)
            batch.draw(shader)
    finally:
        gpu.matrix.pop()
        gpu.state.point_size_set(1.0)
        gpu.state.depth_test_set('NONE')
        gpu.state.blend_set('NONE')
    stats.update(draws=stats["draws"] + 1, vertices=len(geo["segments"]), singular=len(geo["singular"]),
                 clashes=len(geo["clashes"]), shown_vertices=len(shown["segments"]), object=obj.name)


@bpy.app.handlers.persistent
def _on_load(_dummy=None):
    """A file opened (or File › New): the handler follows its scene's toggle."""
    scene = getattr(bpy.context, "scene", None)
    settings = getattr(scene, "exsynth", None)
    if settings is not None:
        sync(settings)


CLASSES = ()


def attach():
    bpy.app.handlers.load_post.append(_on_load)


def detach():
    if _on_load in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.remove(_on_load)
    disable()
