# SPDX-License-Identifier: GPL-3.0-or-later
"""Point Texture renders for the docs (Cycles): chainmail and weave grown
from their 1 x 1 built-in exemplars over a plane (point cloud discs beside
the surface made from the points), and the bundled bunny covered in
chainmail. Run:

    blender -b --factory-startup --python-expr 'import sys; sys.path.insert(0, "build/addon");
    from exsynth import demo_points; demo_points.run("assets/meshes/bunny.obj", "out")'
"""

import os
import time

import bpy
from mathutils import Vector

from . import demo, demo_stage
from .io import materials
from .operators import points as points_ops


def _grow(job, name_colour):
    from .jobs import Created, Runner

    runner = Runner(job)
    runner.run_here()
    result = runner.outcome()
    created = Created()
    objs = points_ops.add_result_objects(bpy.context, result, created)
    for obj in objs[1:]:
        obj.data.materials[0] = materials.new_surface_material(*name_colour, roughness=0.3)
    return result, objs, runner.seconds


def run(bunny_path, out_dir, samples=16, density=6000.0):
    t0 = time.perf_counter()
    bpy.ops.wm.read_homefile(use_empty=True)
    demo_stage.ensure_addon()
    scene = bpy.context.scene
    demo_stage.prepare_scene(scene, samples)
    lines = []
    for preset, rgb in (("chainmail", (0.75, 0.75, 0.78)), ("weave", (0.70, 0.50, 0.30))):
        opts = points_ops._native.point_texture_preset(preset)
        job = points_ops.PointTextureJob(exemplar=points_ops.Exemplar(name=preset, preset=preset, density=density),
                                         size=(2.0, 2.0), options=opts, make_mesh=True, seed=1)
        scene.cursor.location = (0.0, 0.0, 0.0)
        result, (cloud, surf), secs = _grow(job, (f"Demo {preset}", rgb))
        cloud.location = (-2.2, -1.0, 0.0)
        surf.location = (0.2, -1.0, 0.0)
        demo_stage.aim_camera(scene, Vector((0.0, 0.0, 0.0)), distance=5.5, side=0.0)
        scene.render.resolution_x, scene.render.resolution_y = 640, 320
        for o in bpy.data.objects:
            if o.type == 'MESH' and o.name not in (cloud.name, surf.name, "Floor"):
                o.hide_render = True
        demo_stage.render(scene, os.path.join(out_dir, f"points_{preset}.png"))
        lines.append(f"{preset} {len(result.positions)} points in {secs:.1f} s")
        cloud.hide_render = surf.hide_render = True

    bpy.ops.wm.obj_import(filepath=bunny_path)
    bunny = bpy.context.view_layer.objects.active
    bpy.context.view_layer.update()
    bunny.scale = [demo.BUNNY_HEIGHT / bunny.dimensions.y] * 3
    bpy.context.view_layer.update()
    demo_stage.smooth(bunny.data)
    bunny.data.materials.append(materials.new_surface_material("Demo Bunny", (0.55, 0.30, 0.20)))
    s = scene.exsynth
    s.pts_output, s.pts_target, s.pts_scale = 'TARGET', bunny, 0.35
    s.pts_field_preset, s.pts_field_axis = 'AROUND_AXIS', 'Z'
    target = points_ops.target_input(bpy.context, s)
    opts = points_ops._native.point_texture_preset("chainmail")
    job = points_ops.PointTextureJob(exemplar=points_ops.Exemplar(name="chainmail", preset="chainmail",
                                                                  density=density / 2),
                                     target=target, scale=0.35, options=opts, make_mesh=True, seed=1)
    result, (cloud, surf), secs = _grow(job, ("Demo bunny chainmail", (0.78, 0.78, 0.82)))
    cloud.hide_render = True
    lo = Vector(bunny.bound_box[0])
    demo_stage.aim_camera(scene, bunny.matrix_world @ Vector((0, 0, 0)) + Vector((0, 0, 0.45 * demo.BUNNY_HEIGHT)),
                     distance=6.0, side=0.3)
    scene.render.resolution_x, scene.render.resolution_y = 480, 400
    demo_stage.render(scene, os.path.join(out_dir, "points_bunny_chainmail.png"))
    lines.append(f"bunny chainmail {len(result.positions)} points in {secs:.1f} s (lo {tuple(lo)})")
    print(f"demo_points: {'; '.join(lines)}; total {time.perf_counter() - t0:.1f} s -> {out_dir}")
    return 0
