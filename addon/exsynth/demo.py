# SPDX-License-Identifier: GPL-3.0-or-later
"""`./exsynth demo`: voxelize the bundled bunny with the real operator and
render the Volume and the rebuilt mesh with Cycles (CPU, small, fast)."""

import math
import os
import time

import bpy
import numpy as np
from mathutils import Vector

from .io import materials
from .io import mesh as mesh_io

RESOLUTION_PX = (480, 360)
BUNNY_HEIGHT = 2.0  # the OBJ is ~10 units tall; scaled to a Blender-sized prop


def run(bunny_path, out_dir, resolution=96, samples=16):
    t0 = time.perf_counter()
    bpy.ops.wm.read_homefile(use_empty=True)  # keeps registered add-ons
    _ensure_addon()

    # The OBJ importer turns the file's Y-up into Blender's Z-up.
    bpy.ops.wm.obj_import(filepath=bunny_path)
    bunny = bpy.context.view_layer.objects.active
    bunny.name = "Bunny"
    bunny.scale = [BUNNY_HEIGHT / bunny.dimensions.z] * 3
    _smooth(bunny.data)
    bunny.data.materials.append(materials.new_surface_material("Demo Original", (0.55, 0.58, 0.62)))

    scene = bpy.context.scene
    scene.exsynth.resolution = resolution
    scene.exsynth.make_mesh = True
    t1 = time.perf_counter()
    result = bpy.ops.exsynth.voxelize()
    if result != {'FINISHED'}:
        raise RuntimeError(f"exsynth.voxelize returned {result}")
    t2 = time.perf_counter()
    volume = bpy.data.objects["Bunny_voxels"]
    remesh = bpy.data.objects["Bunny_voxel_mesh"]

    _stage(scene, samples)
    centre = Vector((0.0, 0.0, 0.5 * BUNNY_HEIGHT))

    # 1. The Volume alone, where the bunny stood.
    bunny.hide_render = remesh.hide_render = True
    _thicken(volume)
    _aim_camera(scene, centre, distance=7.0, side=0.35)
    _render(scene, os.path.join(out_dir, "voxelize_volume.png"))
    t3 = time.perf_counter()

    # 2. Original (left) beside the mesh rebuilt from the voxels (right).
    volume.hide_render = True
    bunny.hide_render = remesh.hide_render = False
    gap = 0.62 * bunny.dimensions.x
    bunny.location.x -= gap
    remesh.location.x += gap
    _aim_camera(scene, centre, distance=10.0, side=0.1)
    _render(scene, os.path.join(out_dir, "voxelize_mesh.png"))
    t4 = time.perf_counter()

    print(f"demo: voxelized the bunny at {resolution} voxels in {t2 - t1:.2f} s; renders "
          f"{t3 - t2:.1f} s + {t4 - t3:.1f} s; total {t4 - t0:.1f} s -> {out_dir}")
    return 0


def _ensure_addon():
    if hasattr(bpy.types, "EXSYNTH_OT_voxelize"):
        return
    import addon_utils

    def raise_error(exc):
        raise exc

    addon_utils.enable("exsynth", default_set=True, handle_error=raise_error)


def _stage(scene, samples):
    scene.render.engine = 'CYCLES'
    scene.cycles.device = 'CPU'
    scene.cycles.samples = samples
    scene.cycles.use_adaptive_sampling = False
    # Debian's Blender has no OpenImageDenoise; denoising would fail the render.
    scene.cycles.use_denoising = False
    scene.cycles.max_bounces = 4
    scene.render.resolution_x, scene.render.resolution_y = RESOLUTION_PX
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = 'PNG'
    scene.view_settings.look = 'Medium Contrast'

    world = bpy.data.worlds.new("Demo World")
    world.use_nodes = True
    background = world.node_tree.nodes["Background"]
    background.inputs["Color"].default_value = (0.30, 0.36, 0.46, 1.0)
    background.inputs["Strength"].default_value = 0.5
    scene.world = world

    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", 'SUN'))
    sun.data.energy = 3.0
    sun.data.angle = math.radians(8)
    sun.rotation_euler = (math.radians(50), math.radians(10), math.radians(-35))
    scene.collection.objects.link(sun)

    size = 30.0
    corners = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], np.float32) * size
    floor_mesh = mesh_io.new_mesh("Floor", corners, np.array([[0, 1, 2], [0, 2, 3]]))
    floor_mesh.materials.append(materials.new_surface_material("Demo Floor", (0.12, 0.12, 0.13)))
    scene.collection.objects.link(bpy.data.objects.new("Floor", floor_mesh))

    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    camera.data.lens = 50
    scene.collection.objects.link(camera)
    scene.camera = camera


def _aim_camera(scene, target, distance, side):
    # From the front (-Y), slightly above; `side` turns it towards +X.
    direction = Vector((side, -1.0, 0.35)).normalized()
    camera = scene.camera
    camera.location = target + distance * direction
    camera.rotation_euler = (-direction).to_track_quat('-Z', 'Y').to_euler()


def _thicken(volume):
    # The add-on's material uses Blender's default density (1 per unit), in
    # which a 2-unit bunny is a faint haze; the demo wants a visible cloud.
    shader = volume.active_material.node_tree.nodes["Principled Volume"]
    shader.inputs["Density"].default_value = 4.0
    shader.inputs["Color"].default_value = (0.75, 0.85, 1.0, 1.0)


def _render(scene, path):
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)


def _smooth(mesh):
    mesh.polygons.foreach_set("use_smooth", np.ones(len(mesh.polygons), bool))
    mesh.update()

