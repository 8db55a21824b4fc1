# SPDX-License-Identifier: GPL-3.0-or-later
"""The geometry benchmark's pictures: per mesh, the outputs of
bench/bench_geometry.py side by side (each preset at each resolution, in
the order of their names), rendered with Cycles:

    blender -b --factory-startup --python bench/figure_geometry.py -- OUTPUTS_DIR RENDER_DIR MESH...
"""

import glob
import os
import re
import sys

import bpy
from mathutils import Vector

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.environ.get("EXSYNTH_ADDON_DIR", os.path.join(ROOT, "build", "addon")))

from exsynth import demo_stage  # noqa: E402
from exsynth.io import materials  # noqa: E402

HEIGHT = 1.0
COLOURS = {"spikes": (0.72, 0.42, 0.22), "grooves": (0.25, 0.45, 0.70)}


def render_mesh(outputs, render_dir, mesh):
    bpy.ops.wm.read_homefile(use_empty=True)
    demo_stage.ensure_addon()
    scene, view_layer = bpy.context.scene, bpy.context.view_layer
    paths = sorted(glob.glob(os.path.join(outputs, f"{mesh}_*_*.obj")),
                   key=lambda p: (re.sub(r"_\d+\.obj$", "", p), int(re.search(r"_(\d+)\.obj$", p).group(1))))
    paths = [p for p in paths if "_plain_" not in p]
    made = []
    for path in paths:
        bpy.ops.wm.obj_import(filepath=path)
        obj = view_layer.objects.active
        view_layer.update()
        obj.scale = [HEIGHT / max(obj.dimensions)] * 3
        view_layer.update()
        preset = os.path.basename(path).split("_")[-2]
        obj.data.materials.clear()
        obj.data.materials.append(materials.new_surface_material(f"Fig {preset}", COLOURS.get(preset, (0.6,) * 3),
                                                                 roughness=0.45))
        made.append(obj)
    demo_stage.prepare_scene(scene, 16)
    width = 1.1 * HEIGHT
    for i, obj in enumerate(made):
        lo, hi = demo_stage.world_bounds(obj)
        centre = Vector((0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), lo[2]))
        obj.location += Vector(((i - 0.5 * (len(made) - 1)) * width, 0.0, 0.0)) - centre
    scene.render.resolution_x, scene.render.resolution_y = 320 * len(made), 360
    demo_stage.aim_camera(scene, Vector((0.0, 0.0, 0.35 * HEIGHT)), distance=1.6 * len(made), side=0.0)
    out = os.path.join(render_dir, f"geometry_{mesh}.png")
    demo_stage.render(scene, out)
    print(f"figure_geometry: {', '.join(os.path.basename(p) for p in paths)} -> {out}", flush=True)


if __name__ == "__main__":
    args = sys.argv[sys.argv.index("--") + 1:]
    os.makedirs(args[1], exist_ok=True)
    for name in args[2:]:
        render_mesh(os.path.abspath(args[0]), os.path.abspath(args[1]), name)
