# SPDX-License-Identifier: GPL-3.0-or-later
"""The materials ExSynth results are shown with.

Each is shared by name: an existing one is reused as it is (the user may
have tuned it), a missing one is created and recorded in `created`.
"""

import bpy

VOLUME_MATERIAL = "ExSynth Volume"
SURFACE_MATERIAL = "ExSynth Surface"


def volume_material(created):
    mat = bpy.data.materials.get(VOLUME_MATERIAL)
    if mat is not None:
        return mat
    mat = created.add(bpy.data.materials.new(VOLUME_MATERIAL))
    # Nodes built by hand: what use_nodes creates depends on the active object
    # (a Principled BSDF, or with a Volume active a Principled Volume).
    shader = _output_with(mat, "ShaderNodeVolumePrincipled", "Volume")
    shader.inputs["Density Attribute"].default_value = "density"  # the grid written by the add-on
    shader.inputs["Density"].default_value = 1.0  # per world unit, as Blender's own volume default
    shader.inputs["Color"].default_value = (0.85, 0.85, 0.85, 1.0)
    return mat


def surface_material(created):
    mat = bpy.data.materials.get(SURFACE_MATERIAL)
    if mat is not None:
        return mat
    # Warm clay, easy to tell from a grey original.
    return created.add(new_surface_material(SURFACE_MATERIAL, (0.80, 0.45, 0.25)))


def new_surface_material(name, rgb, roughness=0.6):
    """A plain Principled BSDF material of colour `rgb`."""
    mat = bpy.data.materials.new(name)
    shader = _output_with(mat, "ShaderNodeBsdfPrincipled", "Surface")
    shader.inputs["Base Color"].default_value = (*rgb, 1.0)
    shader.inputs["Roughness"].default_value = roughness
    mat.diffuse_color = (*rgb, 1.0)  # what Solid view shows
    return mat


def _output_with(mat, shader_type, output_socket):
    mat.use_nodes = True
    nodes = mat.node_tree.nodes
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    out.location = (300, 0)
    shader = nodes.new(shader_type)
    mat.node_tree.links.new(shader.outputs[0], out.inputs[output_socket])
    return shader
