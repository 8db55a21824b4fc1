# SPDX-License-Identifier: GPL-3.0-or-later
"""`./exsynth demo`: voxelize the bundled bunny with the real operator and
render the Volume and the rebuilt mesh; solid-texture the bundled cow, cut
open, with Solid Texture and Re-bake; give the bunny spikes and grooves with
Geometric Texture; texture the cow's subdivision surface with Surface Texture
(coherent, multiscale, and with height). Cycles (CPU, small, fast)."""

import math
import os
import time

import bpy
import numpy as np
from mathutils import Vector

from . import demo_stage
from .io import materials
from .io import mesh as mesh_io

BUNNY_HEIGHT = 2.0  # the OBJ is ~10 units tall; scaled to a Blender-sized prop


def run(bunny_path, out_dir, resolution=96, samples=16):
    t0 = time.perf_counter()
    bpy.ops.wm.read_homefile(use_empty=True)  # keeps registered add-ons
    demo_stage.ensure_addon()

    # The OBJ importer turns the file's Y-up into Blender's Z-up.
    bpy.ops.wm.obj_import(filepath=bunny_path)
    bunny = bpy.context.view_layer.objects.active
    bunny.name = "Bunny"
    bunny.scale = [BUNNY_HEIGHT / bunny.dimensions.z] * 3
    demo_stage.smooth(bunny.data)
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

    demo_stage.prepare_scene(scene, samples)
    centre = Vector((0.0, 0.0, 0.5 * BUNNY_HEIGHT))

    # 1. The Volume alone, where the bunny stood.
    bunny.hide_render = remesh.hide_render = True
    _thicken(volume)
    demo_stage.aim_camera(scene, centre, distance=7.0, side=0.35)
    demo_stage.render(scene, os.path.join(out_dir, "voxelize_volume.png"))
    t3 = time.perf_counter()

    # 2. Original (left) beside the mesh rebuilt from the voxels (right).
    volume.hide_render = True
    bunny.hide_render = remesh.hide_render = False
    gap = 0.62 * bunny.dimensions.x
    bunny.location.x -= gap
    remesh.location.x += gap
    demo_stage.aim_camera(scene, centre, distance=10.0, side=0.1)
    demo_stage.render(scene, os.path.join(out_dir, "voxelize_mesh.png"))
    t4 = time.perf_counter()

    print(f"demo: voxelized the bunny at {resolution} voxels in {t2 - t1:.2f} s; renders "
          f"{t3 - t2:.1f} s + {t4 - t3:.1f} s; total {t4 - t0:.1f} s -> {out_dir}")
    return 0


COW_LENGTH = 2.0  # the OBJ is 1 unit long
SOLID_SCALE = 1.0  # one tile of the solid, in world units
# 128^3: at 64^3 the voxels are ~1/64 of the cow and its stones come out as
# soft blotches; at 128^3 the feature channel's dark cracks show (docs/solid.md,
# ninth pass); the solid takes ~9 s of the demo on 2 cores.
DEMO_SOLID_SIZE = 128


def run_solid(cow_path, exemplar_path, out_dir, size=DEMO_SOLID_SIZE, samples=16, method=None, name="solid_texture.png"):
    """Solid-texture the bundled cow, cut open: the Solid Texture operator on
    the cow minus a box, Re-bake on the piece the box took out (then set
    beside it, cut face to the camera), so the cut faces of both show the
    inside of the same block of stone. `method` (a SOLID_METHODS name; None:
    the add-on's default) and `name` are for figures (bench/figure_solid_cow.py)."""
    t0 = time.perf_counter()
    bpy.ops.wm.read_homefile(use_empty=True)
    demo_stage.ensure_addon()
    scene = bpy.context.scene
    view_layer = bpy.context.view_layer

    cow, dims = _cow_on_the_floor(cow_path)
    demo_stage.smooth(cow.data)

    # A box over the middle of the back, on the camera's side: the cut shows
    # the inside of the body.
    box = bpy.data.objects.new("Cut", mesh_io.new_mesh("Cut", *_box()))
    scene.collection.objects.link(box)
    box.location = (-0.03 * dims.x, -0.45 * dims.y, 0.72 * dims.z)
    box.scale = (0.2 * dims.x, 0.45 * dims.y, 0.35 * dims.z)
    box.rotation_euler = (math.radians(-8), 0.0, math.radians(10))
    piece = cow.copy()
    piece.data = cow.data.copy()
    piece.name = piece.data.name = "Cow piece"
    scene.collection.objects.link(piece)
    _boolean(cow, box, 'DIFFERENCE')
    _boolean(piece, box, 'INTERSECT')
    bpy.data.batch_remove([box, box.data])

    exemplar = bpy.data.images.load(exemplar_path)
    settings = scene.exsynth
    settings.solid_exemplar = exemplar
    settings.solid_size = size
    settings.solid_scale = SOLID_SCALE
    settings.solid_bake_resolution = 1024
    if method is not None:
        settings.solid_method = method.upper()
    t1 = time.perf_counter()
    demo_stage.select([cow])
    result = bpy.ops.exsynth.solid_texture()
    if result != {'FINISHED'}:
        raise RuntimeError(f"exsynth.solid_texture returned {result}")
    t2 = time.perf_counter()
    demo_stage.select([piece])
    result = bpy.ops.exsynth.solid_rebake()  # the solid Solid Texture just made
    if result != {'FINISHED'}:
        raise RuntimeError(f"exsynth.solid_rebake returned {result}")
    t3 = time.perf_counter()
    # Take the piece out and turn its cut face to the camera, as a block
    # split open (the texture is baked: it moves with the piece).
    piece.rotation_euler.z += math.pi
    view_layer.update()
    p_lo, p_hi = demo_stage.world_bounds(piece)
    target = Vector((0.42 * dims.x, -1.5 * dims.y, 0.0))
    piece.location += target - Vector((0.5 * (p_lo[0] + p_hi[0]), 0.5 * (p_lo[1] + p_hi[1]), p_lo[2]))

    demo_stage.prepare_scene(scene, samples)
    centre = Vector((0.18 * dims.x, -0.6 * dims.y, 0.4 * dims.z))
    demo_stage.aim_camera(scene, centre, distance=4.6, side=0.3)
    demo_stage.render(scene, os.path.join(out_dir, name))
    t4 = time.perf_counter()
    print(f"demo: solid {size}³ from {os.path.basename(exemplar_path)} and bake in {t2 - t1:.2f} s, "
          f"re-bake {t3 - t2:.2f} s; render {t4 - t3:.1f} s; total {t4 - t0:.1f} s -> {out_dir}")
    return 0


def run_analogy(bunny_path, out_dir, resolution=128, pattern_size=0.4, samples=16):
    """Geometric Texture with the real operators: a direction field diffused
    from two painted strokes (Direction Field), then the built-in pairs
    following it. analogy_bunny.png: the bunny, with spikes and with
    grooves; analogy_pairs.png: spikes, pits, holes and grooves."""
    t0 = time.perf_counter()
    bpy.ops.wm.read_homefile(use_empty=True)
    demo_stage.ensure_addon()
    scene = bpy.context.scene
    view_layer = bpy.context.view_layer

    bpy.ops.wm.obj_import(filepath=bunny_path)  # Y-up file -> Z-up (the object's rotation)
    bunny = view_layer.objects.active
    bunny.name = "Bunny"
    view_layer.update()
    bunny.scale = [BUNNY_HEIGHT / bunny.dimensions.y] * 3  # local Y is world Z
    view_layer.update()
    demo_stage.smooth(bunny.data)
    bunny.data.materials.append(materials.new_surface_material("Demo Original", (0.55, 0.58, 0.62)))

    settings = scene.exsynth
    _paint_strokes(bunny)
    settings.field_mode = 'DIFFUSE'
    demo_stage.select([bunny])
    if bpy.ops.exsynth.direction_field() != {'FINISHED'}:
        raise RuntimeError("exsynth.direction_field did not finish")
    settings.geo_resolution = resolution
    settings.geo_pattern_fit = False  # the demo's figures are made at a set size
    settings.geo_pattern_scale = pattern_size
    made, seconds = {}, {}
    colours = {'SPIKES': (0.72, 0.42, 0.22), 'PITS': (0.45, 0.62, 0.38), 'HOLES': (0.62, 0.52, 0.70),
               'GROOVES': (0.25, 0.45, 0.70)}
    for preset, rgb in colours.items():
        settings.geo_preset = preset
        demo_stage.select([bunny])
        t = time.perf_counter()
        result = bpy.ops.exsynth.geometric_texture()
        if result != {'FINISHED'}:
            raise RuntimeError(f"exsynth.geometric_texture ({preset.lower()}) returned {result}")
        seconds[preset] = time.perf_counter() - t
        obj = bpy.data.objects[f"Bunny_{preset.lower()}"]
        obj.data.materials[0] = materials.new_surface_material(f"Demo {preset.title()}", rgb, roughness=0.45)
        made[preset] = obj
    t1 = time.perf_counter()

    # The results are in world space where the bunny is: rows of them move
    # by the same steps. 1: original, spikes, grooves.
    view_layer.update()
    lo, hi = demo_stage.world_bounds(bunny)
    gap = 1.25 * float(hi[0] - lo[0])
    centre = Vector((0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), lo[2]))
    home = {obj.name: obj.location.copy() for obj in [bunny, *made.values()]}

    def row(objects):
        for obj in [bunny, *made.values()]:
            obj.hide_render = obj not in objects
            obj.location = home[obj.name]
        for i, obj in enumerate(objects):
            obj.location += Vector(((i - 0.5 * (len(objects) - 1)) * gap, 0.0, 0.0)) - centre

    demo_stage.prepare_scene(scene, samples)
    row([bunny, made['SPIKES'], made['GROOVES']])
    scene.render.resolution_x = 2 * demo_stage.RESOLUTION_PX[1]  # three bunnies side by side: wider
    demo_stage.aim_camera(scene, Vector((0.0, 0.0, 0.45 * BUNNY_HEIGHT)), distance=11.5, side=0.0)
    demo_stage.render(scene, os.path.join(out_dir, "analogy_bunny.png"))
    # 2: the four built-in pattern pairs.
    row([made[p] for p in ('SPIKES', 'PITS', 'HOLES', 'GROOVES')])
    scene.render.resolution_x = int(2.6 * demo_stage.RESOLUTION_PX[1])
    demo_stage.aim_camera(scene, Vector((0.0, 0.0, 0.45 * BUNNY_HEIGHT)), distance=14.5, side=0.0)
    demo_stage.render(scene, os.path.join(out_dir, "analogy_pairs.png"))
    t2 = time.perf_counter()
    times = ", ".join(f"{p.lower()} {s:.2f} s" for p, s in seconds.items())
    print(f"demo: geometric texture at {resolution} voxels, pattern size {pattern_size}: {times}; "
          f"renders {t2 - t1:.1f} s; total {t2 - t0:.1f} s -> {out_dir}")
    return 0


# Surface Texture: texels per world unit of the 2-unit cow (135 k texels
# coherent; multiscale gets the minimum 2x2 texels a face, 73 k).
SURFACE_DENSITY = {"coherent": 150.0, "multiscale": 72.0}


def run_surface(cow_path, wood_path, ground_path, out_dir, samples=16):
    """Texture synthesis on the cow's subdivision surface (Surface Texture):
    dark wood with the grain along the body, coherent and multiscale, and
    cracked ground with the same image as height (real displaced geometry),
    side by side."""
    t0 = time.perf_counter()
    bpy.ops.wm.read_homefile(use_empty=True)
    demo_stage.ensure_addon()
    scene = bpy.context.scene
    view_layer = bpy.context.view_layer
    cow, dims = _cow_on_the_floor(cow_path)

    settings = scene.exsynth
    settings.surface_size_mode = 'DENSITY'
    settings.surface_field = 'ALONG_AXIS'
    settings.surface_axis = 'X'
    wood = bpy.data.images.load(wood_path)
    ground = bpy.data.images.load(ground_path)
    # Multiscale from the wood at half size (the pattern twice as large): 3
    # pyramid levels instead of 4, whose coarsest neighbourhoods walk across
    # many of the cow's small faces (55 s -> a few seconds under load).
    small = wood.copy()
    small.name = "drkwood2 (64 px)"
    small.scale(wood.size[0] // 2, wood.size[1] // 2)
    runs = (("coherent", wood, None, 1.0), ("multiscale", small, None, 1.0), ("coherent", ground, ground, 1.0))
    results, times = [], []
    for method, exemplar, height, scale in runs:
        settings.surface_method = method.upper()
        settings.surface_density = SURFACE_DENSITY[method]
        settings.surface_exemplar_scale = scale
        settings.surface_exemplar = exemplar
        settings.surface_height = height
        settings.surface_height_scale = 0.01
        t = time.perf_counter()
        demo_stage.select([cow])
        result = bpy.ops.exsynth.surface_texture()
        if result != {'FINISHED'}:
            raise RuntimeError(f"exsynth.surface_texture returned {result}")
        times.append(time.perf_counter() - t)
        results.append(view_layer.objects.active)
    cow.hide_render = True
    # Left to right: coherent wood, multiscale wood, coherent cracked ground + height.
    for i, obj in enumerate(results):
        obj.location.x += (i - 1) * 1.15 * dims.x
        demo_stage.smooth(obj.data)
    t1 = time.perf_counter()
    demo_stage.prepare_scene(scene, samples)
    scene.render.resolution_x = int(2.6 * demo_stage.RESOLUTION_PX[1])
    demo_stage.aim_camera(scene, Vector((0.0, 0.0, 0.4 * dims.z)), distance=10.0, side=0.0)
    demo_stage.render(scene, os.path.join(out_dir, "surface_cow.png"))
    t2 = time.perf_counter()
    made = ", ".join(f"{m} {e.name}{' + height' if h else ''} {dt:.1f} s" for (m, e, h, _), dt in zip(runs, times))
    print(f"demo: surface texture on the cow: {made}; render {t2 - t1:.1f} s; total {t2 - t0:.1f} s -> {out_dir}")
    return 0


def _paint_strokes(bunny):
    """Two painted strokes on the flank the camera sees, as an artist would
    paint them in the `exsynth_paint` attribute: upright over the front
    half, lengthwise over the rear; the rest is left free (zero) for the
    Direction Field operator to fill in by diffusion."""
    mesh = bunny.data
    co = np.zeros(3 * len(mesh.vertices), np.float32)
    mesh.vertices.foreach_get("co", co)
    co = co.reshape(-1, 3)  # local: the OBJ's axes (y up; +z towards the camera; head at -x)
    u = (co - co.min(axis=0)) / np.ptp(co, axis=0)
    paint = np.zeros_like(co)
    flank = u[:, 2] > 0.6
    paint[flank & (u[:, 0] < 0.45)] = (0.0, 1.0, 0.0)
    paint[flank & (u[:, 0] > 0.6)] = (1.0, 0.0, 0.0)
    attribute = mesh.attributes.new("exsynth_paint", 'FLOAT_VECTOR', 'POINT')
    attribute.data.foreach_set("vector", paint.ravel())


def _cow_on_the_floor(cow_path):
    """The bundled cow imported as "Cow", COW_LENGTH long, centred on the
    floor at the origin; returns it and its world extents (obj.dimensions
    ignores the importer's rotation). The OBJ importer turns the file's Y-up
    into Blender's Z-up as the object's rotation: dimensions are right after
    a view-layer update."""
    view_layer = bpy.context.view_layer
    bpy.ops.wm.obj_import(filepath=cow_path)
    cow = view_layer.objects.active
    cow.name = "Cow"
    view_layer.update()
    cow.scale = [COW_LENGTH / cow.dimensions.x] * 3
    view_layer.update()
    lo, hi = demo_stage.world_bounds(cow)
    cow.location -= Vector((0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), lo[2]))  # on the floor
    view_layer.update()
    return cow, Vector(hi - lo)




def _box():
    corners = np.array([[x, y, z] for z in (-1, 1) for y in (-1, 1) for x in (-1, 1)], np.float32)
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    tris = [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))]
    return corners, np.array(tris, np.int32)


def _boolean(obj, cutter, operation):
    mod = obj.modifiers.new("Cut", 'BOOLEAN')
    mod.object = cutter
    mod.operation = operation
    mod.solver = 'EXACT'
    with bpy.context.temp_override(object=obj, active_object=obj):
        bpy.ops.object.modifier_apply(modifier=mod.name)










def _thicken(volume):
    # The add-on's material uses Blender's default density (1 per unit), in
    # which a 2-unit bunny is a faint haze; the demo wants a visible cloud.
    shader = volume.active_material.node_tree.nodes["Principled Volume"]
    shader.inputs["Density"].default_value = 4.0
    shader.inputs["Color"].default_value = (0.75, 0.85, 1.0, 1.0)
