# SPDX-License-Identifier: GPL-3.0-or-later
"""Helpers shared by the add-on tests (plain functions; fixtures are in conftest.py)."""

import os
import sys
import threading
import time

import bpy
import numpy as np

from exsynth.io import volume as volume_io

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BUNNY_OBJ = os.path.join(ROOT, "assets", "meshes", "bunny.obj")
COW_OBJ = os.path.join(ROOT, "assets", "meshes", "cow.obj")
TEXTURES = os.path.join(ROOT, "assets", "textures")
sys.path.append(os.path.join(ROOT, "tests", "python"))  # fsmarks, shared with the Python-module tier
from fsmarks import immutable  # noqa: E402,F401  (re-exported for the tests)


def scene_state():
    """Everything a failed or cancelled run must leave untouched."""
    cache = volume_io.cache_dir()
    return {
        "objects": sorted(o.name for o in bpy.data.objects),
        "meshes": sorted(m.name for m in bpy.data.meshes),
        "volumes": sorted(v.name for v in bpy.data.volumes),
        "materials": sorted(m.name for m in bpy.data.materials),
        "images": sorted(i.name for i in bpy.data.images),
        "collection": sorted(o.name for o in bpy.context.collection.objects),
        "selected": sorted(o.name for o in bpy.context.view_layer.objects.selected),
        "active": getattr(bpy.context.view_layer.objects.active, "name", None),
        "cache_files": sorted(os.listdir(cache)) if os.path.isdir(cache) else None,
    }


def mesh_state(obj):
    """What a failed or cancelled bake must leave untouched on a mesh object."""
    mesh = obj.data
    return {
        "uv_maps": [uv.name for uv in mesh.uv_layers],
        "attributes": sorted(a.name for a in mesh.attributes),
        "slots": [(s.link, getattr(s.material, "name", None)) for s in obj.material_slots],
        "loops": len(mesh.loops),
    }


def world_mesh(obj):
    """(vertices V by 3 in world space, triangles F by 3) of an object's mesh."""
    obj.data.calc_loop_triangles()
    co = np.empty(3 * len(obj.data.vertices), np.float32)
    obj.data.vertices.foreach_get("co", co)
    tris = np.empty(3 * len(obj.data.loop_triangles), np.int32)
    obj.data.loop_triangles.foreach_get("vertices", tris)
    # float64 like the add-on's mesh_io.world_triangles: np.array of a
    # mathutils Matrix is float32 from Blender 5.0 on, and the thickness
    # measure moves by 0.1 % when the vertices move by 1e-7.
    m = np.array(obj.matrix_world, dtype=np.float64)
    return co.reshape(-1, 3).astype(np.float64) @ m[:3, :3].T + m[:3, 3], tris.reshape(-1, 3)


def enclosed_volume(vertices, triangles):
    """Divergence theorem; positive when the normals point outwards."""
    v = np.asarray(vertices, np.float64)[triangles]
    return float(np.einsum("ij,ij->i", v[:, 0], np.cross(v[:, 1], v[:, 2])).sum() / 6.0)


def volume_surface_points(volume_obj, grid_name, threshold):
    """World-space vertices of Blender's own Volume to Mesh of one grid: how
    Blender itself places the voxels (render and modifiers agree on this)."""
    probe = bpy.data.objects.new("probe", bpy.data.meshes.new("probe"))
    bpy.context.collection.objects.link(probe)
    try:
        mod = probe.modifiers.new("to_mesh", 'VOLUME_TO_MESH')
        mod.object = volume_obj
        mod.grid_name = grid_name
        mod.threshold = threshold
        depsgraph = bpy.context.evaluated_depsgraph_get()
        probe_eval = probe.evaluated_get(depsgraph)
        mesh = probe_eval.to_mesh()
        co = np.empty(3 * len(mesh.vertices), np.float32)
        mesh.vertices.foreach_get("co", co)
        m = np.array(probe_eval.matrix_world)
        probe_eval.to_mesh_clear()
    finally:
        bpy.data.batch_remove([probe, probe.data])
    return co.reshape(-1, 3) @ m[:3, :3].T + m[:3, 3]


def bbox(points):
    points = np.asarray(points)
    return points.min(axis=0), points.max(axis=0)


def cancel_once_running(seen):
    """A jobs.job_started_hooks entry that cancels the job from another
    thread as soon as it reports progress, as Esc does mid-run; it records
    the progress and stage it saw in `seen`."""

    def hook(ctx):
        def watch():
            deadline = time.monotonic() + 30
            while ctx.progress == 0.0 and time.monotonic() < deadline:
                time.sleep(0.001)
            seen["progress"], seen["stage"] = ctx.progress, ctx.stage
            ctx.cancel()

        threading.Thread(target=watch, daemon=True).start()

    return hook


def add_camera(name="Cam"):
    """A camera object, linked: the not-a-mesh (or not-a-curve) input."""
    cam = bpy.data.objects.new(name, bpy.data.cameras.new(name))
    bpy.context.collection.objects.link(cam)
    return cam


def read_obj(path):
    """Vertices and triangles of an OBJ file the CLI wrote."""
    lines = open(path).read().splitlines()
    verts = np.array([l.split()[1:4] for l in lines if l.startswith("v ")], np.float64)
    faces = np.array([[int(t.split("/")[0]) - 1 for t in l.split()[1:4]]
                      for l in lines if l.startswith("f ")], np.int64)
    return verts, faces


def add_faceless_mesh(name="Dots"):
    """A mesh object with three vertices and no faces, linked and active:
    the 'mesh has no faces' bad input every mesh operator must refuse."""
    mesh = bpy.data.meshes.new(name)
    mesh.vertices.add(3)
    mesh.vertices.foreach_set("co", np.eye(3, dtype=np.float32).ravel())
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    return obj


def write_grid_obj(path, n=3):
    """An n x n grid of unit quads in z = 0 as OBJ; returns the path."""
    with open(path, "w") as f:
        for j in range(n + 1):
            for i in range(n + 1):
                f.write(f"v {i} {j} 0\n")
        for j in range(n):
            for i in range(n):
                a = j * (n + 1) + i + 1
                f.write(f"f {a} {a + 1} {a + n + 2} {a + n + 1}\n")
    return path
