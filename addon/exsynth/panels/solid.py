# SPDX-License-Identifier: GPL-3.0-or-later
"""Solid Texture in the "ExSynth" sidebar tab: exemplars, synthesis, bake, Re-bake."""

import bpy

from .main import SidebarPanel, draw_shared_advanced


class EXSYNTH_PT_solid(SidebarPanel, bpy.types.Panel):
    bl_label = "Solid Texture"

    def draw(self, context):
        layout = self._layout()
        settings = context.scene.exsynth

        layout.template_ID(settings, "solid_exemplar", open="image.open")
        image = settings.solid_exemplar
        if image is not None and image.has_data:  # has_data: drawing must not load files
            kind = "float" if image.is_float else "8-bit"
            layout.label(text=f"{image.size[0]} × {image.size[1]} px, {kind}", icon='IMAGE_DATA')

        col = layout.column()
        col.prop(settings, "solid_size")
        col.prop(settings, "solid_scale")
        col.prop(settings, "solid_levels")
        col.prop(settings, "solid_iterations")
        col.prop(settings, "solid_use_alpha")

        col = layout.column()
        col.prop(settings, "solid_bake_target")
        if settings.solid_bake_target == 'IMAGE':
            col.prop(settings, "solid_bake_resolution")
            col.prop(settings, "solid_new_uvs")
        col.prop(settings, "solid_bake_interpolation")

        meshes = [o for o in context.selected_objects if o.type == 'MESH']
        box = layout.box()
        if not meshes:
            box.label(text="Select the mesh(es) to bake onto", icon='INFO')
        else:
            extra = f" and {len(meshes) - 1} more" if len(meshes) > 1 else ""
            box.label(text=f"{meshes[0].name}{extra}", icon='MESH_DATA')
            n = settings.solid_size
            box.label(text=f"{n}³ voxels, {settings.solid_scale / n:.3g} each")
        row = layout.row()
        row.scale_y = 1.4
        row.operator("exsynth.solid_texture", icon='TEXTURE')


class EXSYNTH_PT_solid_axes(SidebarPanel, bpy.types.Panel):
    bl_label = "Per-Axis Exemplars"
    bl_parent_id = "EXSYNTH_PT_solid"
    bl_options = {'DEFAULT_CLOSED'}

    def draw(self, context):
        layout = self._layout()
        settings = context.scene.exsynth
        layout.label(text="Empty: the main exemplar", icon='INFO')
        layout.prop(settings, "solid_exemplar_y", text="Y (XZ slices)")
        layout.prop(settings, "solid_exemplar_z", text="Z (XY slices)")


class EXSYNTH_PT_solid_rebake(SidebarPanel, bpy.types.Panel):
    bl_label = "Re-bake"
    bl_parent_id = "EXSYNTH_PT_solid"

    def draw(self, context):
        layout = self._layout()
        settings = context.scene.exsynth
        layout.prop(settings, "solid_volume")
        layout.operator("exsynth.solid_rebake", icon='FILE_REFRESH')


class EXSYNTH_PT_solid_advanced(SidebarPanel, bpy.types.Panel):
    bl_label = "Advanced"
    bl_parent_id = "EXSYNTH_PT_solid"
    bl_options = {'DEFAULT_CLOSED'}

    def draw(self, context):
        layout = self._layout()
        settings = context.scene.exsynth
        layout.prop(settings, "solid_method")
        col = layout.column()
        col.active = settings.solid_method == 'OPTIMIZATION'  # the other method ignores them
        col.prop(settings, "solid_feature_weight")
        row = col.row()
        row.active = settings.solid_feature_weight > 0  # the threshold picks the features the weight weighs
        row.prop(settings, "solid_feature_threshold")
        row = col.row()
        row.active = settings.solid_feature_weight > 0  # the scale shapes the channel the weight weighs
        row.prop(settings, "solid_feature_scale")
        col.prop(settings, "solid_rotate_exemplar")
        col.prop(settings, "solid_histogram_values")
        col.prop(settings, "solid_structure_sigma")
        draw_shared_advanced(layout, context.scene.exsynth)


CLASSES = (EXSYNTH_PT_solid, EXSYNTH_PT_solid_axes, EXSYNTH_PT_solid_rebake, EXSYNTH_PT_solid_advanced)
