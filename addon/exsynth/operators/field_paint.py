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

This file is the operator (events -> samples); the data side is
field_paint_session.PaintSession, the math exsynth.field_brush.
"""

import bpy
import numpy as np

from .. import compat, field_brush, overlay
from ..jobs import REPORTED_ERRORS, InputError
from .field_paint_session import LIVE_DIFFUSION_LIMIT, PaintSession, check_target  # noqa: F401 (re-exported)

MODE_NAMES = {'PAINT': "Paint", 'ERASE': "Erase", 'COMB': "Comb"}
MODE_KEYS = {'P': 'PAINT', 'E': 'ERASE', 'C': 'COMB'}
MIRROR_KEYS = {'X': 0, 'Y': 1, 'Z': 2}
cursor_draws = 0  # brush circles drawn (the GUI smoke test reads it)


# ---- the modal tool -----------------------------------------------------------
def _view_region(context, event):
    """(region, rv3d, x, y) of the 3D viewport's main region under the mouse, or None."""
    area = context.area
    if area is None or area.type != 'VIEW_3D':
        return None
    def inside(region):
        x, y = event.mouse_x - region.x, event.mouse_y - region.y
        return region.width > 1 and 0 <= x < region.width and 0 <= y < region.height

    # With Region Overlap (the default) the sidebar, toolbar and headers lie
    # over the main region: the mouse there is for their buttons.
    if any(r.type != 'WINDOW' and inside(r) for r in area.regions):
        return None
    for region in area.regions:
        if region.type == 'WINDOW' and inside(region):
            return region, area.spaces.active.region_3d, event.mouse_x - region.x, event.mouse_y - region.y
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
