# SPDX-License-Identifier: GPL-3.0-or-later
"""Geometric Texture in the "ExSynth" sidebar tab: pair, direction field, resolution."""

import bpy

from .. import _native
from ..operators.analogy import PAIR_MAX, PAIR_MIN, grid_resolution, pair_resolution
from ..operators.field import FIELD_ATTRIBUTE
from ..ui.pattern_preview import length_text, pattern_for
from .main import SidebarPanel, draw_field_preset, draw_shared_advanced

PAIR_DETAIL = _native.PAIR_DETAIL_RESOLUTION  # the pair's voxels from which its features keep their shape


def _is_mesh(obj):
    return obj is not None and obj.type == 'MESH'


def _has_field(obj):
    return _is_mesh(obj) and obj.data.attributes.get(FIELD_ATTRIBUTE) is not None


def _draw_pattern_size(context, layout, pattern):
    """The pattern's size in scene units (and the thickness it was fitted to)."""
    if pattern is None:
        return
    if "pending" in pattern:
        layout.label(text="Pattern: measuring the model…", icon='SPHERE')
        return
    if "error" in pattern:
        layout.label(text=f"Pattern: {pattern['error']}", icon='ERROR')
        return
    text = f"Pattern {length_text(context, pattern['size'])}"
    if pattern["thickness"] is not None:
        text += f" (thickness {length_text(context, pattern['thickness'])})"
    layout.label(text=text, icon='SPHERE')


class EXSYNTH_PT_geometric_texture(SidebarPanel, bpy.types.Panel):
    bl_label = "Geometric Texture"

    def draw(self, context):
        layout = self._layout()
        settings = context.scene.exsynth
        obj = context.active_object
        builtin = settings.geo_pair_source == 'BUILTIN'

        col = layout.column()
        col.prop(settings, "geo_pair_source", expand=True)
        pattern = pattern_for(context, obj) if builtin else None
        if builtin:
            col.prop(settings, "geo_preset")
            col.prop(settings, "geo_pattern_fit")
            if not settings.geo_pattern_fit:
                col.prop(settings, "geo_pattern_scale")
            _draw_pattern_size(context, col, pattern)
            col.prop(settings, "geo_show_pattern")
            if settings.geo_preset == 'DILATE':
                col.prop(settings, "geo_dilation")
            elif settings.geo_preset == 'SPIKES':
                col.prop(settings, "geo_spike_height")
        else:
            col.prop(settings, "geo_a")
            col.prop(settings, "geo_a_prime")
            col.prop(settings, "geo_a_selected_only")
        col.prop(settings, "geo_resolution")

        # The direction field: the mesh's own attribute wins over the preset.
        col = layout.column()
        needs_preset = not _has_field(obj) or (not builtin and not _has_field(settings.geo_a))
        if _has_field(obj):
            col.label(text=f"Field: '{FIELD_ATTRIBUTE}' of {obj.name}", icon='ORIENTATION_NORMAL')
        if needs_preset:
            draw_field_preset(col, settings, "geo_field_")
        col.prop(settings, "geo_make_volume")

        box = layout.box()
        if not _is_mesh(obj):
            box.label(text="Select a mesh object", icon='INFO')
        else:
            pair = settings.geo_preset.lower() if builtin else getattr(settings.geo_a_prime, "name", "A′")
            box.label(text=f"{obj.name} → {obj.name}_{pair}", icon='MESH_DATA')
        if builtin and pattern and "scale" in pattern:
            grid = grid_resolution(settings.geo_resolution, pattern["scale"], settings.geo_pattern_fit)
            r_pair = pair_resolution(grid, pattern["scale"])
            if not PAIR_MIN <= r_pair <= PAIR_MAX:
                box.label(text=f"Pair {r_pair}³: needs {PAIR_MIN} to {PAIR_MAX}", icon='ERROR')
            else:
                box.label(text=f"Exemplar pair {r_pair}³ voxels")
            if grid > settings.geo_resolution:  # the consequence, before the run
                box.label(text=f"Runs at {grid} voxels: the pattern's detail needs them", icon='INFO')
            if r_pair < PAIR_DETAIL:
                box.label(text=f"Soft features under {PAIR_DETAIL}: raise Resolution or Pattern Size", icon='ERROR')
        elif settings.geo_a is None or settings.geo_a_prime is None:
            box.label(text="Pick A and A′ (meshes)", icon='ERROR')
        row = layout.row()
        row.scale_y = 1.4
        row.operator("exsynth.geometric_texture", icon='MOD_DISPLACE')


class EXSYNTH_PT_geometric_texture_advanced(SidebarPanel, bpy.types.Panel):
    bl_label = "Advanced"
    bl_parent_id = "EXSYNTH_PT_geometric_texture"
    bl_options = {'DEFAULT_CLOSED'}

    def draw(self, context):
        draw_shared_advanced(self._layout(), context.scene.exsynth, seed=False)


CLASSES = (EXSYNTH_PT_geometric_texture, EXSYNTH_PT_geometric_texture_advanced)
