# SPDX-License-Identifier: GPL-3.0-or-later
"""Point Texture in the "ExSynth" sidebar tab: exemplar, output, patch size; weights under Advanced."""

import bpy

from .main import SidebarPanel, draw_field_preset, draw_shared_advanced


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
