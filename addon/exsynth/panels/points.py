# SPDX-License-Identifier: GPL-3.0-or-later
"""Point Texture in the "ExSynth" sidebar tab: exemplar, output, patch size; weights under Advanced."""

import bpy

from ..jobs import REPORTED_ERRORS
from .main import SidebarPanel, draw_field_preset, draw_shared_advanced


_last_estimate = [None, None]  # (the inputs, the line): draw() runs on every redraw


def _estimate_line(context, s):
    """'Scale 0.82: about 860 patches, …' for a built-in or object exemplar over the target."""
    from ..operators import points as points_ops

    target = s.pts_target
    if target is None or target.type != 'MESH' or s.pts_exemplar_source == 'FILE':
        return None
    source = s.pts_object if s.pts_exemplar_source != 'BUILTIN' else None
    if s.pts_exemplar_source != 'BUILTIN' and (source is None or source.type != 'MESH'):
        return None
    key = (target.name, len(target.data.vertices), tuple(map(tuple, target.matrix_world)), s.pts_scale,
           s.pts_exemplar_source, s.pts_preset, source and source.name, s.pts_density, s.pts_patch_size,
           s.pts_custom_weights)
    if _last_estimate[0] != key:
        _last_estimate[:] = [key, None]
        try:
            job = points_ops.make_point_job(context, s)
            if not job.scale:
                return None
            _last_estimate[1] = f"Scale {job.scale:.3g}: {job.preview()}"
        except REPORTED_ERRORS:  # an input the operator names when it runs
            pass
    return _last_estimate[1]


class EXSYNTH_PT_point_texture(SidebarPanel, bpy.types.Panel):
    bl_label = "Point Texture"

    def draw(self, context):
        layout = self._layout()
        s = context.scene.exsynth
        col = layout.column()
        col.prop(s, "pts_exemplar_source")
        if s.pts_exemplar_source == 'BUILTIN':
            col.prop(s, "pts_preset")
        elif s.pts_exemplar_source in ('OBJECT', 'SELECTED'):
            col.prop(s, "pts_object")
        else:
            col.prop(s, "pts_file")
        if s.pts_exemplar_source != 'FILE':
            col.prop(s, "pts_density")
        col = layout.column()
        col.prop(s, "pts_output", expand=True)
        if s.pts_output == 'PLANE':
            col.prop(s, "pts_width")
            col.prop(s, "pts_depth")
        else:
            col.prop(s, "pts_target")
            col.prop(s, "pts_scale")
            line = _estimate_line(context, s)
            if line:
                col.label(text=line, icon='INFO')
            draw_field_preset(col, s, "pts_field_")
        col.prop(s, "pts_patch_size")
        col.prop(s, "pts_make_mesh")
        row = layout.row()
        row.scale_y = 1.4
        row.operator("exsynth.point_texture", icon='POINTCLOUD_DATA')


class EXSYNTH_PT_point_texture_advanced(SidebarPanel, bpy.types.Panel):
    bl_label = "Advanced"
    bl_parent_id = "EXSYNTH_PT_point_texture"
    bl_options = {'DEFAULT_CLOSED'}

    def draw(self, context):
        layout = self._layout()
        s = context.scene.exsynth
        layout.prop(s, "pts_custom_weights")
        col = layout.column()
        col.enabled = s.pts_custom_weights
        for key in ("extra", "epsilon", "w_p", "w_n", "w_v", "w_l", "w_d"):
            col.prop(s, f"pts_{key}")
        draw_shared_advanced(layout, s)


CLASSES = (EXSYNTH_PT_point_texture, EXSYNTH_PT_point_texture_advanced)
