# SPDX-License-Identifier: GPL-3.0-or-later
"""Surface Texture in the "ExSynth" sidebar tab."""

import bpy

from .main import SidebarPanel, draw_shared_advanced


class EXSYNTH_PT_surface(SidebarPanel, bpy.types.Panel):
    bl_label = "Surface Texture"

    def draw(self, context):
        layout = self._layout()
        s = context.scene.exsynth
        layout.template_ID(s, "surface_exemplar", open="image.open")
        col = layout.column()
        col.prop(s, "surface_height")
        col.prop(s, "surface_use_alpha")
        col.prop(s, "surface_method")
        col.prop(s, "surface_size_mode")
        col.prop(s, "surface_density" if s.surface_size_mode == 'DENSITY' else "surface_face_resolution")
        col.prop(s, "surface_exemplar_scale")
        obj = context.active_object
        has_field = obj is not None and obj.type == 'MESH' and obj.data.attributes.get("exsynth_field") is not None
        if has_field:
            layout.label(text="Field: the mesh's 'exsynth_field'", icon='FORCE_FORCE')
        else:
            col = layout.column()
            col.prop(s, "surface_field")
            col.prop(s, "surface_axis")
        col = layout.column()
        if s.surface_height is not None:
            col.prop(s, "surface_height_scale")
        col.prop(s, "surface_segments")
        row = layout.row()
        row.scale_y = 1.4
        row.operator("exsynth.surface_texture", icon='TEXTURE')


class EXSYNTH_PT_surface_advanced(SidebarPanel, bpy.types.Panel):
    """The seed and memory budget the Surface Texture job uses."""

    bl_label = "Advanced"
    bl_parent_id = "EXSYNTH_PT_surface"
    bl_options = {'DEFAULT_CLOSED'}

    def draw(self, context):
        draw_shared_advanced(self._layout(), context.scene.exsynth)


CLASSES = (EXSYNTH_PT_surface, EXSYNTH_PT_surface_advanced)
