# SPDX-License-Identifier: GPL-3.0-or-later
"""The materials ExSynth results are shown with.

Each is shared by name: an existing one is reused as it is (the user may
have tuned it), a missing one is created and recorded in `created`.
"""

import bpy

from .. import compat

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
    nodes = compat.ensure_node_tree(mat).nodes
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    out.location = (300, 0)
    shader = nodes.new(shader_type)
    mat.node_tree.links.new(shader.outputs[0], out.inputs[output_socket])
    return shader


def solid_volume_material(name, srgb, density, created):
    """A new material showing a solid's `color` grid in a Volume object.

    `srgb`: the grid holds display-encoded colours (from an 8-bit exemplar),
    turned back to linear for rendering with a gamma of 2.2. `density` is per
    unit length, so that a tile of the solid renders as a dense block. The
    colour both scatters and glows (emission = density: in a dense block the
    glow shows the colour as it is), so dark exemplars stay readable."""
    mat = created.add(bpy.data.materials.new(name))
    shader = _output_with(mat, "ShaderNodeVolumePrincipled", "Volume")
    shader.inputs["Density"].default_value = density
    shader.inputs["Density Attribute"].default_value = "density"  # 1 inside the tile
    tree = mat.node_tree
    attr = tree.nodes.new("ShaderNodeAttribute")
    attr.attribute_name = "color"
    attr.location = (-500, 100)
    colour = attr.outputs["Color"]
    if srgb:
        gamma = tree.nodes.new("ShaderNodeGamma")
        gamma.inputs["Gamma"].default_value = 2.2
        gamma.location = (-250, 100)
        tree.links.new(colour, gamma.inputs["Color"])
        colour = gamma.outputs["Color"]
    tree.links.new(colour, shader.inputs["Color"])
    tree.links.new(colour, shader.inputs["Emission Color"])
    shader.inputs["Emission Strength"].default_value = density
    return mat


def image_material(name, image, uv_map, created, alpha=False):
    """A new material: the image over UV map `uv_map` as the base colour
    (and its alpha as alpha with `alpha`)."""
    mat = created.add(bpy.data.materials.new(name))
    shader = _output_with(mat, "ShaderNodeBsdfPrincipled", "Surface")
    shader.inputs["Roughness"].default_value = 0.5
    tree = mat.node_tree
    tex = tree.nodes.new("ShaderNodeTexImage")
    tex.image = image
    tex.interpolation = 'Linear'
    tex.location = (-400, 0)
    uv = tree.nodes.new("ShaderNodeUVMap")
    uv.uv_map = uv_map
    uv.location = (-650, -100)
    tree.links.new(uv.outputs["UV"], tex.inputs["Vector"])
    tree.links.new(tex.outputs["Color"], shader.inputs["Base Color"])
    if alpha:
        tree.links.new(tex.outputs["Alpha"], shader.inputs["Alpha"])
    return mat


def attribute_material(name, attribute, created):
    """A new material: colour attribute `attribute` as the base colour."""
    mat = created.add(bpy.data.materials.new(name))
    shader = _output_with(mat, "ShaderNodeBsdfPrincipled", "Surface")
    shader.inputs["Roughness"].default_value = 0.5
    tree = mat.node_tree
    attr = tree.nodes.new("ShaderNodeVertexColor")
    attr.layer_name = attribute
    attr.location = (-400, 0)
    tree.links.new(attr.outputs["Color"], shader.inputs["Base Color"])
    return mat
