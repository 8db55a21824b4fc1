# SPDX-License-Identifier: GPL-3.0-or-later
"""The scene the demo and the docs' figures render in (demo.py,
demo_points.py, bench/figure_pattern_fit.py): Cycles on the CPU at a small
size, a sun, a floor and a camera, and the few steps every figure repeats."""

import math

import bpy
import numpy as np
from mathutils import Vector

from . import compat
from .io import materials
from .io import mesh as mesh_io
from .io.selection import select_only

RESOLUTION_PX = (480, 360)


def world_bounds(obj):
    corners = (np.array(obj.matrix_world) @ np.c_[np.array(obj.bound_box), np.ones(8)].T)[:3]
    return corners.min(axis=1), corners.max(axis=1)


def select(objects):
    select_only(bpy.context.view_layer, objects)


def ensure_addon():
    if hasattr(bpy.types, "EXSYNTH_OT_voxelize"):
        return
    import addon_utils

    def raise_error(exc):
        raise exc

    # The add-on's own module name: "exsynth", or "bl_ext.REPO.exsynth" when
    # installed as an extension.
    addon_utils.enable(__package__, default_set=True, handle_error=raise_error)


def prepare_scene(scene, samples):
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
    compat.set_medium_contrast_look(scene.view_settings)

    world = bpy.data.worlds.new("Demo World")
    background = compat.ensure_node_tree(world).nodes["Background"]
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


def aim_camera(scene, target, distance, side):
    # From the front (-Y), slightly above; `side` turns it towards +X.
    direction = Vector((side, -1.0, 0.35)).normalized()
    camera = scene.camera
    camera.location = target + distance * direction
    camera.rotation_euler = (-direction).to_track_quat('-Z', 'Y').to_euler()


def render(scene, path):
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)


def smooth(mesh):
    mesh.polygons.foreach_set("use_smooth", np.ones(len(mesh.polygons), bool))
    mesh.update()
