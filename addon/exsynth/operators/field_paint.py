# SPDX-License-Identifier: GPL-3.0-or-later
"""Paint Direction Field: a modal tool in the 3D viewport. The artist drags
strokes over the active mesh; each sample is ray-cast onto the evaluated
mesh, its screen motion turned into a tangent at the hit, and written with a
screen-space brush radius and a smooth falloff into the painted attribute
(`exsynth_paint` by default: the one Direction Field's Diffuse mode reads).
The engine diffuses the constraints into `exsynth_field` on a worker thread
(the newest constraints win; one diffusion at a time): while the artist
paints on meshes up to LIVE_DIFFUSION_LIMIT vertices, on release above.

Undo: the whole session is one undo step (Blender's memfile undo reloads the
mesh datablocks a running tool holds, so steps cannot be pushed mid-tool);
inside the tool Ctrl+Z takes back the last stroke. Cancelling (Backspace, or
Blender cancelling the tool) puts both attributes back as they were.

The bpy side is `PaintSession` (mesh <-> arrays, samples in world space) and
the operator (events -> samples); the math is exsynth.field_brush.
"""

import threading

import bpy
import numpy as np

from .. import _native, compat, field_brush, overlay
from ..io import mesh as mesh_io
from ..jobs import REPORTED_ERRORS, InputError
from .field import FIELD_ATTRIBUTE, check_field_slot, read_vectors

MODE_NAMES = {'PAINT': "Paint", 'ERASE': "Erase", 'COMB': "Comb"}
MODE_KEYS = {'P': 'PAINT', 'E': 'ERASE', 'C': 'COMB'}
MIRROR_KEYS = {'X': 0, 'Y': 1, 'Z': 2}
cursor_draws = 0  # brush circles drawn (the GUI smoke test reads it)
UNDO_DEPTH = 64  # strokes Ctrl+Z can take back inside one session
# Diffuse while the stroke is dragged on meshes up to this size, else on
# release. Measured (bench/bench_paint.py, 2 cores): one diffusion takes
# ~0.1 s CPU (85 ms wall at load 1.5, 0.27 s at load 6) on the 26 k-vertex
# Armadillo, live enough; once subdivided to 104 k, 0.43 s wall at load 1.5
# and 1.3-2.4 s at load 6, which would lag the brush and compete with it for
# the two cores.
LIVE_DIFFUSION_LIMIT = 50000


def check_target(obj, paint_name):
    """The mesh to paint on, or an InputError saying what to change."""
    if obj is None:
        raise InputError(
            "no active object. Select the mesh to paint a direction field on (click it in the viewport "
            "or the Outliner) and start Paint Direction Field again"
        )
    if obj.type != 'MESH':
        raise InputError(
            f"the active object '{obj.name}' is a {obj.type.lower()}, not a mesh. Select a mesh object "
            "and start Paint Direction Field again"
        )
    if obj.library is not None or obj.data.library is not None:
        raise InputError(
            f"the mesh '{obj.name}' is linked from another file, so it cannot get an attribute. "
            "Make it local (Object > Relations > Make Local)"
        )
    if len(obj.data.polygons) == 0:
        raise InputError(
            f"the mesh '{obj.name}' has no faces (only vertices or edges), so there is no surface to paint "
            "on. Give it faces (Edit Mode, select, F) or select another mesh"
        )
    if not paint_name:
        raise InputError(
            "no painted attribute named. Enter a name (default 'exsynth_paint') in the Direction Field panel"
        )
    attr = obj.data.attributes.get(paint_name)
    if attr is not None and (attr.domain, attr.data_type) != ('POINT', 'FLOAT_VECTOR'):
        raise InputError(
            f"the attribute '{paint_name}' of '{obj.name}' is {attr.data_type.lower()} on the "
            f"{attr.domain.lower()} domain; painted directions go into a Vector attribute on the Vertex "
            "domain. Rename or remove it, or enter another name in the Direction Field panel"
        )
    check_field_slot(obj)


class Diffuser:
    """At most one diffusion on a worker thread (the engine releases the GIL;
    only numpy arrays cross, never bpy); `request` while one runs keeps the
    newest constraints for the next."""

    def __init__(self, vertices, triangles):
        self.vertices, self.triangles = vertices, triangles
        self._thread, self._pending, self._result = None, None, None
        self._lock = threading.Lock()
        self.runs, self.error = 0, None
        self.requested = None  # the constraints of the last request (main thread only)

    def request(self, constraints):
        """Diffuse these constraints next (not again if they are the last ones asked for)."""
        if self.requested is not None and np.array_equal(constraints, self.requested):
            return
        self.requested = constraints.copy()
        with self._lock:
            self._pending = self.requested
        self._start_if_idle()

    def _start_if_idle(self):
        with self._lock:
            if self._pending is None or (self._thread is not None and self._thread.is_alive()):
                return
            given, self._pending = self._pending, None
        self._thread = threading.Thread(target=self._work, args=(given,), name="exsynth paint diffusion", daemon=True)
        self._thread.start()

    def _work(self, given):
        try:
            field = _native.diffuse_direction_field(self.vertices, self.triangles, given)
            error = None
        except _native.Error as exc:  # e.g. everything erased: no constraint left
            field, error = None, exc
        with self._lock:
            self._result, self.error = field, error
            self.runs += 1

    def take(self):
        """The newest finished field (or None), and starts the next pending request."""
        with self._lock:
            result, self._result = self._result, None
        self._start_if_idle()
        return result

    @property
    def busy(self):
        with self._lock:
            return self._pending is not None or (self._thread is not None and self._thread.is_alive())

    def wait(self):
        """Blocks until every request is diffused; returns the last field (or None)."""
        result = None
        while True:
            if self._thread is not None:
                self._thread.join()
            latest = self.take()
            if latest is not None:
                result = latest
            if not self.busy:
                return result


def _attribute_state(mesh, name):
    attr = mesh.attributes.get(name)
    return None if attr is None else read_vectors(mesh, name).copy()


class PaintSession:
    """One painting session on one mesh: the constraints as a numpy array,
    written to the painted attribute as strokes go; the field diffused from
    them. Samples are given in world space (what the viewport ray-cast
    yields); distances are measured there, so the brush is round on a scaled
    object; directions are stored in the mesh's own space."""

    def __init__(self, obj, paint_name):
        check_target(obj, paint_name)
        self.object_name, self.mesh_name, self.paint_name = obj.name, obj.data.name, paint_name
        mesh = obj.data
        verts, tris = mesh_io.mesh_arrays(mesh)
        self.vertices = verts.astype(np.float64)
        self.triangles = tris
        self.normals = field_brush.vertex_normals(self.vertices, tris)
        self.matrix = np.array(obj.matrix_world, np.float64)
        self.to_local = np.linalg.inv(self.matrix)
        self.world = self.vertices @ self.matrix[:3, :3].T + self.matrix[:3, 3]
        # The scene as it was, for cancel.
        self.original = {name: _attribute_state(mesh, name) for name in (paint_name, FIELD_ATTRIBUTE)}
        paint = self.original[paint_name]
        self.constraints = np.zeros((len(verts), 3), np.float32) if paint is None else paint.astype(np.float32)
        field = self.original[FIELD_ATTRIBUTE]
        self.field = None if field is None else field.astype(np.float32)
        self.history = []  # constraints before each finished stroke (Ctrl+Z)
        self.before_stroke = None
        self.samples = 0
        self.diffuser = Diffuser(self.vertices, self.triangles)
        self.live = len(self.vertices) <= LIVE_DIFFUSION_LIMIT

    @property
    def mesh(self):
        mesh = bpy.data.meshes.get(self.mesh_name)
        if mesh is None or len(mesh.vertices) != len(self.vertices):
            raise InputError(f"the mesh '{self.mesh_name}' was removed or changed while painting; start again")
        return mesh

    # ---- strokes ---------------------------------------------------------
    def begin_stroke(self):
        self.before_stroke = self.constraints.copy()

    def apply(self, centre, direction, radius, mode='PAINT', mirror_axes=(), strength=1.0):
        """One sample: brush at world point `centre`, stroke tangent
        `direction` (world), brush `radius` (world units). Mirrors across the
        mesh's local axes in `mirror_axes` (0, 1, 2). Returns the number of
        vertices changed. Raises ValueError on a bad radius, mode or strength
        (nothing changed)."""
        centre = np.asarray(centre, np.float64)
        direction = np.asarray(direction, np.float64)
        if centre.shape != (3,) or direction.shape != (3,) or not (np.all(np.isfinite(centre))
                                                                   and np.all(np.isfinite(direction))):
            raise ValueError("a brush sample needs a finite world point and direction (3 numbers each)")
        field_brush.falloff(0.0, radius)  # validates the radius before anything changes
        local_centre = self.to_local[:3, :3] @ centre + self.to_local[:3, 3]
        local_dir = self.to_local[:3, :3] @ direction
        changed = 0
        for p, d in field_brush.mirrored_samples(local_centre, local_dir, mirror_axes):
            world_p = self.matrix[:3, :3] @ p + self.matrix[:3, 3]
            changed += len(field_brush.apply_brush(self.constraints, self.field, self.world, self.normals,
                                                   world_p, radius, d, mode=mode, strength=strength))
        self.samples += 1
        return changed

    def end_stroke(self):
        """Keeps the stroke: writes the constraints, asks for a diffusion."""
        if self.before_stroke is not None:
            self.history = (self.history + [self.before_stroke])[-UNDO_DEPTH:]
        self.before_stroke = None
        self.write_paint()
        self.request_diffusion()

    def cancel_stroke(self):
        if self.before_stroke is not None:
            self.constraints = self.before_stroke
            self.before_stroke = None
            self.write_paint()
            self.request_diffusion()

    def undo_stroke(self):
        """Takes back the last finished stroke; False when there is none."""
        if not self.history:
            return False
        self.constraints = self.history.pop()
        self.write_paint()
        self.request_diffusion()
        return True

    # ---- diffusion ---------------------------------------------------------
    def request_diffusion(self):
        if field_brush.has_constraints(self.constraints):
            self.diffuser.request(self.constraints)

    def poll_field(self):
        """Writes a finished diffusion into `exsynth_field`; True if it did."""
        field = self.diffuser.take()
        if field is None:
            return False
        self.write_field(field)
        return True

    def finish(self):
        """Waits for the last diffusion and writes everything (end of the tool)."""
        self.write_paint()
        if field_brush.has_constraints(self.constraints):
            self.diffuser.request(self.constraints)
        field = self.diffuser.wait()
        if field is not None:
            self.write_field(field)

    def changed(self):
        return any(not _same(self.original[name], _attribute_state(self.mesh, name))
                   for name in (self.paint_name, FIELD_ATTRIBUTE))

    # ---- the mesh ----------------------------------------------------------
    def write_paint(self):
        _write(self.mesh, self.paint_name, self.constraints)

    def write_field(self, field):
        self.field = np.asarray(field, np.float32)
        _write(self.mesh, FIELD_ATTRIBUTE, self.field)

    def restore(self):
        """Both attributes back as they were when the session began."""
        self.diffuser.wait()
        mesh = bpy.data.meshes.get(self.mesh_name)
        if mesh is None:
            return
        for name, values in self.original.items():
            attr = mesh.attributes.get(name)
            if values is None:
                if attr is not None:
                    mesh.attributes.remove(attr)
            else:
                _write(mesh, name, values)
        mesh.update()


def _same(a, b):
    if a is None or b is None:
        return a is None and b is None
    return a.shape == b.shape and np.array_equal(a, b)


def _write(mesh, name, values):
    attr = mesh.attributes.get(name)
    if attr is None:
        attr = mesh.attributes.new(name, 'FLOAT_VECTOR', 'POINT')
    attr.data.foreach_set("vector", np.ascontiguousarray(values, np.float32).ravel())
    mesh.update()


# ---- the modal tool -----------------------------------------------------------
def _view_region(context, event):
    """(region, rv3d, x, y) of the 3D viewport's main region under the mouse, or None."""
    area = context.area
    if area is None or area.type != 'VIEW_3D':
        return None
    for region in area.regions:
        if region.type != 'WINDOW':
            continue
        x, y = event.mouse_x - region.x, event.mouse_y - region.y
        if 0 <= x < region.width and 0 <= y < region.height:
            return region, area.spaces.active.region_3d, x, y
    return None


class EXSYNTH_OT_paint_direction_field(bpy.types.Operator):
    """Paint a direction field on the active mesh: drag strokes over it (P paint, E erase, C comb, X/Y/Z mirror, [ ] radius, Ctrl+Z undo stroke, Esc/right-click done, Backspace discard). The field is diffused as you paint"""

    bl_idname = "exsynth.paint_direction_field"
    bl_label = "Paint Direction Field"
    bl_options = {'UNDO'}

    def _start(self, context):
        """The session for the active mesh, or None after reporting what to change."""
        if context.mode != 'OBJECT':
            self.report({'ERROR'}, "Paint Direction Field: works in Object Mode only. Press Tab to leave Edit "
                        "Mode and start it again")
            return None
        try:
            session = PaintSession(context.active_object, context.scene.exsynth.field_paint_attribute)
        except InputError as exc:
            self.report({'ERROR'}, f"Paint Direction Field: {exc}")
            return None
        if context.area is None or context.area.type != 'VIEW_3D':
            self.report({'ERROR'}, "Paint Direction Field is interactive: start it from a 3D viewport (the "
                        "ExSynth tab of its sidebar, or F3 over the viewport)")
            return None
        return session

    def execute(self, context):
        # Scripts and `blender -b` have no mouse to paint with: the same checks, then the same advice.
        if self._start(context) is not None:
            self.report({'ERROR'}, "Paint Direction Field is interactive: invoke it (INVOKE_DEFAULT) in a 3D "
                        "viewport, or use PaintSession from a script")
        return {'CANCELLED'}

    def invoke(self, context, event):
        settings = context.scene.exsynth
        self.session = self._start(context)
        if self.session is None:
            return {'CANCELLED'}
        from mathutils.bvhtree import BVHTree

        obj = context.active_object
        self.bvh = BVHTree.FromObject(obj, context.evaluated_depsgraph_get())
        self.stroking, self.last = False, None
        self.mouse = None  # (region, x, y) for the brush circle
        self.cursor = bpy.types.SpaceView3D.draw_handler_add(self._draw_cursor, (), 'WINDOW', 'POST_PIXEL')
        self.overlay_was_on = settings.field_overlay
        settings.field_overlay = True
        self.timer = context.window_manager.event_timer_add(0.05, window=context.window)
        context.window_manager.modal_handler_add(self)
        self._header(context)
        return {'RUNNING_MODAL'}

    # ---- events --------------------------------------------------------------
    def modal(self, context, event):
        try:
            return self._modal(context, event)
        except (InputError, *REPORTED_ERRORS) as exc:
            self.report({'ERROR'}, f"Paint Direction Field: {exc}")
            self._end(context, keep=False)
            return {'CANCELLED'}

    def _modal(self, context, event):
        settings = context.scene.exsynth
        kind, value = event.type, event.value
        if kind in {'MOUSEMOVE', 'INBETWEEN_MOUSEMOVE'}:
            found = _view_region(context, event)
            self.mouse = None if found is None else (found[0].as_pointer(), found[2], found[3])
            if context.area is not None:
                context.area.tag_redraw()
        if kind == 'TIMER':
            if self.session.poll_field():
                context.area.tag_redraw()
            error = self.session.diffuser.error
            if error is not None:  # shown, not fatal: the next stroke may fix it
                self.session.diffuser.error = None
                self._header(context, f"field not updated: {error}")
            return {'PASS_THROUGH'}
        if self.stroking:
            if kind in {'MOUSEMOVE', 'INBETWEEN_MOUSEMOVE'}:
                self._sample(context, event)
                return {'RUNNING_MODAL'}
            if kind == 'LEFTMOUSE' and value == 'RELEASE':
                self.stroking = overlay.stroking = False
                self.session.end_stroke()
                return {'RUNNING_MODAL'}
            if kind in {'ESC', 'RIGHTMOUSE'} and value == 'PRESS':
                self.stroking = overlay.stroking = False
                self.session.cancel_stroke()
                self._header(context, "stroke cancelled")
                return {'RUNNING_MODAL'}
            return {'RUNNING_MODAL'}
        if kind == 'LEFTMOUSE' and value == 'PRESS':
            if _view_region(context, event) is None:
                return {'PASS_THROUGH'}  # the sidebar, header...: their buttons work
            self.stroking, self.last = True, None
            overlay.stroking = True
            self.session.begin_stroke()
            self._sample(context, event)
            return {'RUNNING_MODAL'}
        if value != 'PRESS':
            return {'PASS_THROUGH'}
        if kind in {'ESC', 'RIGHTMOUSE', 'RET', 'NUMPAD_ENTER', 'SPACE'}:
            return self._end(context, keep=True)
        if kind == 'BACK_SPACE':
            return self._end(context, keep=False)
        if kind == 'Z' and event.ctrl:
            self._header(context, "stroke undone" if self.session.undo_stroke() else "no stroke to undo")
            return {'RUNNING_MODAL'}
        if kind in MODE_KEYS and not (event.ctrl or event.alt or event.shift):
            settings.field_brush_mode = MODE_KEYS[kind]
        elif kind in MIRROR_KEYS and not (event.ctrl or event.alt or event.shift):
            axis = MIRROR_KEYS[kind]
            settings.field_mirror[axis] = not settings.field_mirror[axis]
        elif kind == 'LEFT_BRACKET':
            settings.field_brush_radius = max(1, int(settings.field_brush_radius / 1.25))
        elif kind == 'RIGHT_BRACKET':
            settings.field_brush_radius = int(settings.field_brush_radius * 1.25) + 1
        else:
            return {'PASS_THROUGH'}  # view navigation and the rest
        self._header(context)
        return {'RUNNING_MODAL'}

    def _sample(self, context, event):
        """Ray-cast the mouse onto the evaluated mesh; apply the brush along
        the screen motion since the last sample (every few pixels)."""
        from bpy_extras import view3d_utils
        from mathutils import Vector

        found = _view_region(context, event)
        if found is None:
            return
        region, rv3d, x, y = found
        settings = context.scene.exsynth
        radius_px = settings.field_brush_radius
        if self.last is not None and np.hypot(x - self.last[0], y - self.last[1]) < max(2.0, radius_px / 5):
            return
        mouse = Vector((x, y))
        origin = view3d_utils.region_2d_to_origin_3d(region, rv3d, mouse)
        ray = view3d_utils.region_2d_to_vector_3d(region, rv3d, mouse)
        matrix = np.array(self.session.matrix)
        inv = self.session.to_local
        o_local = inv[:3, :3] @ np.array(origin) + inv[:3, 3]
        d_local = inv[:3, :3] @ np.array(ray)
        hit, normal, _, _ = self.bvh.ray_cast(Vector(o_local), Vector(d_local / np.linalg.norm(d_local)))
        if hit is None:
            self.last = None  # off the mesh: the next hit starts afresh
            return
        centre = matrix[:3, :3] @ np.array(hit) + matrix[:3, 3]
        normal_w = field_brush.normalized(inv[:3, :3].T @ np.array(normal))
        at = Vector(centre)
        edge = view3d_utils.region_2d_to_location_3d(region, rv3d, Vector((x + radius_px, y)), at)
        radius = float(np.linalg.norm(np.array(edge) - centre))
        if self.last is not None and radius > 0:
            prev = view3d_utils.region_2d_to_location_3d(region, rv3d, Vector(self.last), at)
            here = view3d_utils.region_2d_to_location_3d(region, rv3d, mouse, at)
            tangent = field_brush.tangent_from_view(np.array(here) - np.array(prev), normal_w, np.array(ray))
            if np.any(tangent != 0):
                mirror = [k for k in range(3) if settings.field_mirror[k]]
                self.session.apply(centre, tangent, radius, settings.field_brush_mode, mirror,
                                   settings.field_brush_strength)
                if self.session.live:  # the paint attribute is written when the stroke ends
                    self.session.request_diffusion()
        self.last = (x, y)

    # ---- ending ----------------------------------------------------------------
    def _end(self, context, keep):
        settings = context.scene.exsynth
        overlay.stroking = False
        if self.timer is not None:  # _end may run twice: an error while keeping, then the roll-back
            context.window_manager.event_timer_remove(self.timer)
            self.timer = None
        if self.cursor is not None:
            bpy.types.SpaceView3D.draw_handler_remove(self.cursor, 'WINDOW')
            self.cursor = None
        if context.area is not None:
            context.area.header_text_set(None)
            context.area.tag_redraw()
        if keep:
            self.session.finish()
        else:
            self.session.restore()
        settings.field_overlay = self.overlay_was_on or keep
        if keep and self.session.changed():
            self.report({'INFO'}, f"ExSynth: painted direction field on '{self.session.object_name}'")
            return {'FINISHED'}
        return {'CANCELLED'}

    def cancel(self, context):
        # Blender ends the tool itself (a file is loaded, the window closes).
        self._end(context, keep=False)

    def _draw_cursor(self):
        """The brush: a circle of the radius (screen pixels) around the mouse,
        white for Paint, red for Erase, yellow for Comb."""
        import gpu
        from gpu_extras.batch import batch_for_shader

        context = bpy.context
        if self.mouse is None or context.region is None or context.region.as_pointer() != self.mouse[0]:
            return
        settings = context.scene.exsynth
        r = settings.field_brush_radius
        angles = np.linspace(0.0, 2.0 * np.pi, 49)
        points = np.stack([self.mouse[1] + r * np.cos(angles), self.mouse[2] + r * np.sin(angles)], axis=1)
        colour = {'PAINT': (1.0, 1.0, 1.0, 0.9), 'ERASE': (1.0, 0.3, 0.3, 0.9),
                  'COMB': (1.0, 0.85, 0.2, 0.9)}[settings.field_brush_mode]
        shader = compat.builtin_shader('UNIFORM_COLOR', dimensions=2)
        batch = batch_for_shader(shader, 'LINE_STRIP', {"pos": points.astype(np.float32)})
        gpu.state.blend_set('ALPHA')
        shader.bind()
        shader.uniform_float("color", colour)
        batch.draw(shader)
        gpu.state.blend_set('NONE')
        global cursor_draws
        cursor_draws += 1

    def _header(self, context, note=""):
        s = context.scene.exsynth
        mirror = "".join("XYZ"[k] for k in range(3) if s.field_mirror[k]) or "off"
        text = (f"Paint Direction Field — {MODE_NAMES[s.field_brush_mode]} (P/E/C) · radius "
                f"{s.field_brush_radius} px ([ ]) · mirror {mirror} (X/Y/Z) · drag: stroke · "
                "Ctrl+Z: undo stroke · Esc/right-click/Enter: done · Backspace: discard")
        context.area.header_text_set(text + (f" — {note}" if note else ""))


CLASSES = (EXSYNTH_OT_paint_direction_field,)
