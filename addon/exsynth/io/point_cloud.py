# SPDX-License-Identifier: GPL-3.0-or-later
"""A point texture as Blender data: a vertex-only mesh with a FLOAT_VECTOR
point attribute `exsynth_normal`, shown as oriented discs by a geometry-nodes
modifier (Mesh to Points -> Instance on Points of a small disc turned to the
normal). Works in Blender 3.4 and 4.x (Cycles renders the instances)."""

import bpy
import numpy as np

from .. import compat
from . import materials

NORMAL_ATTRIBUTE = "exsynth_normal"
NODE_GROUP = "ExSynth Point Discs"
POINT_MATERIAL = "ExSynth Points"


def new_point_mesh(name, positions, normals):
    mesh = bpy.data.meshes.new(name)
    mesh.vertices.add(len(positions))
    mesh.vertices.foreach_set("co", np.ascontiguousarray(positions, np.float32).reshape(-1))
    attr = mesh.attributes.new(NORMAL_ATTRIBUTE, 'FLOAT_VECTOR', 'POINT')
    attr.data.foreach_set("vector", np.ascontiguousarray(normals, np.float32).reshape(-1))
    mesh.update()
    return mesh


def _socket(group, in_out, socket_type, name):
    if hasattr(group, "interface"):  # Blender >= 4.0
        return group.interface.new_socket(name, in_out=in_out, socket_type=socket_type)
    return (group.inputs if in_out == 'INPUT' else group.outputs).new(socket_type, name)


def disc_node_group(material, created):
    """The shared node group (reused by name; the disc radius is its input)."""
    group = bpy.data.node_groups.get(NODE_GROUP)
    if group is not None:
        return group
    group = created.add(bpy.data.node_groups.new(NODE_GROUP, 'GeometryNodeTree'))
    _socket(group, 'INPUT', 'NodeSocketGeometry', "Geometry")
    radius = _socket(group, 'INPUT', 'NodeSocketFloat', "Radius")
    radius.default_value = 0.01
    _socket(group, 'OUTPUT', 'NodeSocketGeometry', "Geometry")
    nodes, links = group.nodes, group.links
    gin = nodes.new("NodeGroupInput")
    gout = nodes.new("NodeGroupOutput")
    to_points = nodes.new("GeometryNodeMeshToPoints")
    disc = nodes.new("GeometryNodeMeshCircle")
    disc.fill_type = 'NGON'
    disc.inputs["Vertices"].default_value = 8
    set_mat = nodes.new("GeometryNodeSetMaterial")
    set_mat.inputs["Material"].default_value = material
    normal = nodes.new("GeometryNodeInputNamedAttribute")
    normal.data_type = 'FLOAT_VECTOR'
    normal.inputs["Name"].default_value = NORMAL_ATTRIBUTE
    align = nodes.new("FunctionNodeAlignEulerToVector")
    align.axis = 'Z'
    inst = nodes.new("GeometryNodeInstanceOnPoints")
    links.new(gin.outputs["Geometry"], to_points.inputs["Mesh"])
    links.new(gin.outputs["Radius"], disc.inputs["Radius"])
    links.new(disc.outputs["Mesh"], set_mat.inputs["Geometry"])
    links.new(normal.outputs["Attribute"], align.inputs["Vector"])
    links.new(to_points.outputs["Points"], inst.inputs["Points"])
    links.new(set_mat.outputs["Geometry"], inst.inputs["Instance"])
    links.new(align.outputs["Rotation"], inst.inputs["Rotation"])
    links.new(inst.outputs["Instances"], gout.inputs["Geometry"])
    return group


def point_material(created):
    mat = bpy.data.materials.get(POINT_MATERIAL)
    if mat is not None:
        return mat
    return created.add(materials.new_surface_material(POINT_MATERIAL, (0.75, 0.72, 0.65), roughness=0.35))


def new_point_cloud_object(name, positions, normals, disc_radius, collection, created):
    """The point cloud object `name`, its discs `disc_radius` wide; all recorded in `created`."""
    mesh = created.add(new_point_mesh(name, positions, normals))
    obj = created.add(bpy.data.objects.new(mesh.name, mesh))
    collection.objects.link(obj)
    mat = point_material(created)
    mesh.materials.append(mat)
    mod = obj.modifiers.new("ExSynth Discs", 'NODES')
    mod.node_group = disc_node_group(mat, created)
    compat.set_modifier_input(mod, "Radius", float(disc_radius))
    return obj


def read_point_cloud(obj):
    """(positions N by 3 world, normals N by 3 world) of a point cloud object made here."""
    mesh = obj.data
    co = np.empty(3 * len(mesh.vertices), np.float32)
    mesh.vertices.foreach_get("co", co)
    nrm = np.empty(3 * len(mesh.vertices), np.float32)
    mesh.attributes[NORMAL_ATTRIBUTE].data.foreach_get("vector", nrm)
    m = np.array(obj.matrix_world, np.float64)
    pos = co.reshape(-1, 3) @ m[:3, :3].T + m[:3, 3]
    n = nrm.reshape(-1, 3) @ np.linalg.inv(m[:3, :3])
    return pos, n / np.linalg.norm(n, axis=1, keepdims=True)
