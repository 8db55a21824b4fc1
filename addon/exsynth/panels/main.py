# SPDX-License-Identifier: GPL-3.0-or-later
"""The "ExSynth" tab in the 3D viewport's sidebar (N-panel)."""

import bpy

from .. import _native

CATEGORY = "ExSynth"


class SidebarPanel:
    """Base of the tool panels in the ExSynth tab (property-split layout)."""

    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = CATEGORY

    def _layout(self):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        return layout


def draw_field_preset(col, settings, prefix):
    """A field preset's settings (`<prefix>preset`, then its curve or its
    axis), as Direction Field and Geometric Texture both ask for them."""
    col.prop(settings, f"{prefix}preset")
    if getattr(settings, f"{prefix}preset") == 'ALONG_CURVE':
        col.prop(settings, f"{prefix}curve")
    else:
        col.row().prop(settings, f"{prefix}axis", expand=True)


def draw_shared_advanced(layout, settings, seed=True):
    """Seed and memory budget: scene-wide settings the tools' Advanced panels
    show (the seed only where something is random)."""
    if seed:
        layout.prop(settings, "seed")
    layout.prop(settings, "memory_budget_gib", text="Memory Budget (GiB)")
    layout.label(text="Shared with Voxelize", icon='LINKED')


class EXSYNTH_PT_voxelize(bpy.types.Panel):
    bl_label = "Voxelize"
    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = CATEGORY

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        settings = context.scene.exsynth

        col = layout.column()
        col.prop(settings, "resolution")
        col.prop(settings, "padding")
        col.prop(settings, "supersample")
        col.prop(settings, "make_mesh")

        obj = context.active_object
        box = layout.box()
        if obj is None or obj.type != 'MESH':
            box.label(text="Select a mesh object", icon='INFO')
        else:
            box.label(text=obj.name, icon='MESH_DATA')
            box.label(text=_grid_estimate(obj, settings))
        row = layout.row()
        row.scale_y = 1.4
        row.operator("exsynth.voxelize", icon='VOLUME_DATA')


class EXSYNTH_PT_voxelize_advanced(bpy.types.Panel):
    bl_label = "Advanced"
    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = CATEGORY
    bl_parent_id = "EXSYNTH_PT_voxelize"
    bl_options = {'DEFAULT_CLOSED'}

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        settings = context.scene.exsynth
        layout.prop(settings, "memory_budget_gib", text="Memory Budget (GiB)")


def _grid_estimate(obj, settings):
    # From the object's dimensions (scale included, rotation not), so the
    # artist sees the grid size before starting; the engine computes the real one.
    try:
        grid = _native.voxel_grid((0, 0, 0), tuple(obj.dimensions), resolution=settings.resolution,
                                  padding=settings.padding)
    except ValueError:
        return "Empty bounding box"
    z, y, x = grid["shape"]
    return f"about {x} × {y} × {z} voxels"


CLASSES = (EXSYNTH_PT_voxelize, EXSYNTH_PT_voxelize_advanced)
