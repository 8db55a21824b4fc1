# SPDX-License-Identifier: GPL-3.0-or-later
"""addon/exsynth/compat.py: the one place for differences between Blender
releases; run in 3.4 and each bpy release (it is in the launcher's subset)."""

import warnings

import bpy

from exsynth import compat, jobs
from exsynth.io import materials


def test_materials_are_made_without_deprecation_warnings():
    """5.0 deprecates Material.use_nodes: the add-on's materials are built
    without touching it there, and with it up to 4.5."""
    created = jobs.Created()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        surface = materials.surface_material(created)
        volume = materials.volume_material(created)
    assert [m.name for m in created.ids] == ["ExSynth Surface", "ExSynth Volume"]
    kinds = {n.bl_idname for n in surface.node_tree.nodes}
    assert kinds == {"ShaderNodeOutputMaterial", "ShaderNodeBsdfPrincipled"}
    assert "ShaderNodeVolumePrincipled" in {n.bl_idname for n in volume.node_tree.nodes}
    assert surface.node_tree.nodes["Material Output"].inputs["Surface"].is_linked


def test_world_node_tree():
    world = bpy.data.worlds.new("W")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        tree = compat.ensure_node_tree(world)
    assert tree is world.node_tree and "Background" in tree.nodes
