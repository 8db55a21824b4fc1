# SPDX-License-Identifier: GPL-3.0-or-later
"""addon/exsynth/compat.py: the one place for differences between Blender
releases; run in 3.4 and each bpy release (it is in the launcher's subset)."""

import warnings

import bpy

from exsynth import compat, jobs
from exsynth.io import materials


def no_deprecation(capfd, record):
    """Blender reports deprecated properties as a DeprecationWarning, raised
    or (after read_homefile, seen in 5.0.1) printed to stderr: neither."""
    out, err = capfd.readouterr()
    assert not [w for w in record if issubclass(w.category, DeprecationWarning)]
    assert "DeprecationWarning" not in out + err and "expected to be removed" not in out + err


def test_materials_are_made_without_deprecation_warnings(capfd):
    """5.0 deprecates Material.use_nodes: the add-on's materials are built
    without touching it there, and with it up to 4.5."""
    created = jobs.Created()
    capfd.readouterr()
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        surface = materials.surface_material(created)
        volume = materials.volume_material(created)
    no_deprecation(capfd, record)
    assert [m.name for m in created.ids] == ["ExSynth Surface", "ExSynth Volume"]
    kinds = {n.bl_idname for n in surface.node_tree.nodes}
    assert kinds == {"ShaderNodeOutputMaterial", "ShaderNodeBsdfPrincipled"}
    assert "ShaderNodeVolumePrincipled" in {n.bl_idname for n in volume.node_tree.nodes}
    assert surface.node_tree.nodes["Material Output"].inputs["Surface"].is_linked


def test_world_node_tree(capfd):
    world = bpy.data.worlds.new("W")
    capfd.readouterr()
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        tree = compat.ensure_node_tree(world)
    no_deprecation(capfd, record)
    assert tree is world.node_tree and "Background" in tree.nodes
