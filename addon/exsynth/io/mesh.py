# SPDX-License-Identifier: GPL-3.0-or-later
"""Blender meshes <-> numpy (vertices V by 3, triangles F by 3).

Bulk access only (foreach_get/foreach_set on flat numpy buffers): a Python
loop over vertices would take seconds on meshes the engine handles in
milliseconds.
"""

import bpy
import numpy as np

from . import materials


def world_triangles(objects, depsgraph):
    """Triangles of the evaluated meshes (modifiers applied) in world space.

    Returns (vertices float64 V by 3, triangles int32 F by 3) for all objects
    together. World space because the engine's grids are placed in world
    space: the Volume made from them keeps an identity object transform.
    """
    all_verts, all_tris, offset = [], [], 0
    for obj in objects:
        verts, tris = _evaluated_triangles(obj, depsgraph)
        all_verts.append(verts)
        all_tris.append(tris + offset)
        offset += len(verts)
    if not all_verts:
        return np.zeros((0, 3), np.float64), np.zeros((0, 3), np.int32)
    return np.concatenate(all_verts), np.concatenate(all_tris)


def _evaluated_triangles(obj, depsgraph):
    obj_eval = obj.evaluated_get(depsgraph)
    mesh = obj_eval.to_mesh()
    try:
        co, tris = mesh_arrays(mesh)
        matrix = np.array(obj_eval.matrix_world, dtype=np.float64)
    finally:
        obj_eval.to_mesh_clear()
    # Transform in float64: large world offsets would lose precision in float32.
    return co.astype(np.float64) @ matrix[:3, :3].T + matrix[:3, 3], tris


def new_mesh(name, vertices, triangles, smooth=False):
    """A new mesh datablock from (V by 3 positions, F by 3 vertex indices)."""
    verts = np.ascontiguousarray(vertices, np.float32).reshape(-1)
    tris = np.ascontiguousarray(triangles, np.int32).reshape(-1)
    n_faces = len(tris) // 3
    mesh = bpy.data.meshes.new(name)
    mesh.vertices.add(len(verts) // 3)
    mesh.vertices.foreach_set("co", verts)
    mesh.loops.add(len(tris))
    mesh.loops.foreach_set("vertex_index", tris)
    mesh.polygons.add(n_faces)
    mesh.polygons.foreach_set("loop_start", np.arange(0, len(tris), 3, dtype=np.int32))
    # Blender >= 3.6 derives loop_total from loop_start and makes it read-only.
    if not bpy.types.MeshPolygon.bl_rna.properties["loop_total"].is_readonly:
        mesh.polygons.foreach_set("loop_total", np.full(n_faces, 3, np.int32))
    if smooth:
        mesh.polygons.foreach_set("use_smooth", np.ones(n_faces, bool))
    mesh.update(calc_edges=True)
    return mesh


def new_surface_object(name, vertices, triangles, collection, created):
    """A smooth-shaded mesh object with the shared "ExSynth Surface"
    material, linked into `collection`; everything recorded in `created`."""
    mesh = created.add(new_mesh(name, vertices, triangles, smooth=True))
    mesh.materials.append(materials.surface_material(created))
    obj = created.add(bpy.data.objects.new(mesh.name, mesh))
    collection.objects.link(obj)
    return obj


def mesh_arrays(mesh):
    """(vertices float32 V by 3, triangles int32 F by 3) of a mesh's own data."""
    mesh.calc_loop_triangles()
    co = np.empty(3 * len(mesh.vertices), np.float32)
    mesh.vertices.foreach_get("co", co)
    tris = np.empty(3 * len(mesh.loop_triangles), np.int32)
    mesh.loop_triangles.foreach_get("vertices", tris)
    return co.reshape(-1, 3), tris.reshape(-1, 3)



def selected_world_triangles(obj):
    """World-space (vertices V by 3 float64, triangles F by 3) of the faces
    selected on a mesh object's own mesh (as last left in Edit Mode), or
    None when no face is selected."""
    mesh = obj.data
    selected = np.zeros(len(mesh.polygons), bool)
    mesh.polygons.foreach_get("select", selected)
    if not selected.any():
        return None
    mesh.calc_loop_triangles()
    tris = np.zeros(3 * len(mesh.loop_triangles), np.int32)
    mesh.loop_triangles.foreach_get("vertices", tris)
    owner = np.zeros(len(mesh.loop_triangles), np.int32)
    mesh.loop_triangles.foreach_get("polygon_index", owner)
    co = np.zeros(3 * len(mesh.vertices), np.float32)
    mesh.vertices.foreach_get("co", co)
    matrix = np.array(obj.matrix_world, np.float64)
    verts = co.reshape(-1, 3).astype(np.float64) @ matrix[:3, :3].T + matrix[:3, 3]
    return verts, tris.reshape(-1, 3)[selected[owner]]
