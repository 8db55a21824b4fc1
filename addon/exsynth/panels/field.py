# SPDX-License-Identifier: GPL-3.0-or-later
"""Direction Field in the "ExSynth" sidebar tab."""

import bpy

from .main import CATEGORY, draw_field_preset


class EXSYNTH_PT_field(bpy.types.Panel):
    bl_label = "Direction Field"
    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = CATEGORY

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        settings = context.scene.exsynth
        obj = context.active_object
        mesh = obj.data if obj is not None and obj.type == 'MESH' else None

        col = layout.column()
        col.prop(settings, "field_mode")
        if settings.field_mode == 'PRESET':
            draw_field_preset(col, settings, "field_")
        elif mesh is not None:
            col.prop_search(settings, "field_paint_attribute", mesh, "attributes")
        else:
            col.prop(settings, "field_paint_attribute")

        box = layout.box()
        if mesh is None:
            box.label(text="Select a mesh object", icon='INFO')
        else:
            box.label(text=f"{obj.name}: {len(mesh.vertices)} vertices", icon='MESH_DATA')
            if settings.field_mode == 'DIFFUSE' and mesh.attributes.get(settings.field_paint_attribute) is None:
                box.label(text="Add a Vector (Vertex) attribute to paint", icon='ERROR')
            if mesh.attributes.get("exsynth_field") is not None:
                box.label(text="Replaces its 'exsynth_field'", icon='INFO')
        row = layout.row()
        row.scale_y = 1.4
        row.operator("exsynth.direction_field", icon='ORIENTATION_NORMAL')

        # Painting: strokes into the painted attribute, diffused as you go.
        box = layout.box()
        col = box.column()
        col.prop(settings, "field_brush_mode")
        col.prop(settings, "field_brush_radius")
        col.prop(settings, "field_brush_strength")
        row = col.row(heading="Mirror", align=True)
        for k, axis in enumerate("XYZ"):
            row.prop(settings, "field_mirror", index=k, text=axis, toggle=True)
        row = box.row()
        row.scale_y = 1.3
        row.operator("exsynth.paint_direction_field", icon='BRUSH_DATA')
        box.label(text="Drag on the mesh", icon='INFO')

        # The overlay: drawn from 'exsynth_field' whatever made it.
        box = layout.box()
        box.prop(settings, "field_overlay", icon='HIDE_OFF' if settings.field_overlay else 'HIDE_ON')
        if settings.field_overlay:
            col = box.column()
            col.prop(settings, "field_overlay_max_strokes")
            col.prop(settings, "field_overlay_length")
            col.prop(settings, "field_overlay_singularities")
            if mesh is not None and mesh.attributes.get("exsynth_field") is None:
                box.label(text="No 'exsynth_field' on this mesh yet", icon='INFO')


CLASSES = (EXSYNTH_PT_field,)
