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
    # Built by hand: use_nodes alone gives a Principled BSDF wired to Surface,
    # which a Volume object cannot show.
    shader = _output_with(mat, "ShaderNodeVolumePrincipled", "Volume")
    shader.inputs["Density Attribute"].default_value = "density"  # the grid written by the add-on
    shader.inputs["Density"].default_value = 1.0  # per world unit, as Blender's own volume default
    shader.inputs["Color"].default_value = (0.85, 0.85, 0.85, 1.0)
    return mat


def surface_material(created):
    mat = bpy.data.materials.get(SURFACE_MATERIAL)
    if mat is not None:
        return mat
    mat = created.add(bpy.data.materials.new(SURFACE_MATERIAL))
    shader = _output_with(mat, "ShaderNodeBsdfPrincipled", "Surface")
    colour = (0.80, 0.45, 0.25, 1.0)  # warm clay, easy to tell from a grey original
    shader.inputs["Base Color"].default_value = colour
    shader.inputs["Roughness"].default_value = 0.6
    mat.diffuse_color = colour  # what Solid view shows
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
