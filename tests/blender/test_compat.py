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


def test_geometry_nodes_modifier_input_is_set_and_read_on_either_api():
    """Up to 5.0 a modifier input is an ID property of the modifier; 5.2
    refuses ID properties there and has `properties.inputs`. The helper takes
    whichever this Blender has, and the evaluated geometry sees the value."""
    bpy.ops.mesh.primitive_plane_add()
    obj = bpy.context.active_object
    group = bpy.data.node_groups.new("Offset", "GeometryNodeTree")
    if hasattr(group, "interface"):
        group.interface.new_socket("Geometry", in_out='INPUT', socket_type='NodeSocketGeometry')
        group.interface.new_socket("Lift", in_out='INPUT', socket_type='NodeSocketFloat')
        group.interface.new_socket("Geometry", in_out='OUTPUT', socket_type='NodeSocketGeometry')
    else:
        group.inputs.new('NodeSocketGeometry', "Geometry")
        group.inputs.new('NodeSocketFloat', "Lift")
        group.outputs.new('NodeSocketGeometry', "Geometry")
    nodes, links = group.nodes, group.links
    gin, gout = nodes.new("NodeGroupInput"), nodes.new("NodeGroupOutput")
    move = nodes.new("GeometryNodeTransform")
    combine = nodes.new("ShaderNodeCombineXYZ")
    links.new(gin.outputs["Lift"], combine.inputs["Z"])
    links.new(combine.outputs["Vector"], move.inputs["Translation"])
    links.new(gin.outputs["Geometry"], move.inputs["Geometry"])
    links.new(move.outputs["Geometry"], gout.inputs["Geometry"])
    mod = obj.modifiers.new("Lift", 'NODES')
    mod.node_group = group
    compat.set_modifier_input(mod, "Lift", 0.75)
    assert abs(compat.modifier_input(mod, "Lift") - 0.75) < 1e-6
    depsgraph = bpy.context.evaluated_depsgraph_get()
    mesh = obj.evaluated_get(depsgraph).to_mesh()
    zs = {round(v.co.z, 5) for v in mesh.vertices}
    obj.evaluated_get(depsgraph).to_mesh_clear()
    assert zs == {0.75}


def test_medium_contrast_look_exists_in_this_blender():
    """The demo's look: 'Medium Contrast' under 3.x's Filmic, the AgX look of
    the same contrast from 4.0 (names prefixed by the view transform)."""
    view = bpy.context.scene.view_settings
    look = compat.set_medium_contrast_look(view)
    assert look == view.look and look != 'None'
    assert look == 'Medium Contrast' if bpy.app.version < (4, 0, 0) else look.startswith(view.view_transform + " - ")
