# SPDX-License-Identifier: GPL-3.0-or-later
"""The pattern-size figure of docs/analogy.md: Geometric Texture (spikes) on
the armadillo at resolution 160, with the old default pattern size (half of
its longest side) and with Fit to Model, rendered side by side (Cycles):

    blender -b --factory-startup --python bench/figure_pattern_fit.py -- OUT.png [RESOLUTION]
"""

import os
import sys
import time

import bpy
from mathutils import Vector

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.environ.get("EXSYNTH_ADDON_DIR", os.path.join(ROOT, "build", "addon")))

from exsynth import demo_stage  # noqa: E402
from exsynth.io import materials  # noqa: E402
from exsynth.ui import pattern_preview  # noqa: E402

HEIGHT = 2.0


def main(out, resolution):
    bpy.ops.wm.read_homefile(use_empty=True)
    demo_stage.ensure_addon()
    scene, view_layer = bpy.context.scene, bpy.context.view_layer
    bpy.ops.wm.obj_import(filepath=os.path.join(ROOT, "assets", "meshes", "armadillo.obj"))
    model = view_layer.objects.active
    model.name = "Armadillo"
    view_layer.update()
    model.scale = [HEIGHT / model.dimensions.y] * 3  # Y-up file: local Y is world Z
    view_layer.update()
    demo_stage.smooth(model.data)
    s = scene.exsynth
    s.geo_preset, s.geo_resolution = 'SPIKES', resolution
    s.geo_field_preset, s.geo_field_axis = 'AROUND_AXIS', 'Z'
    made, report = [], []
    for fit, label, rgb in ((False, "old", (0.72, 0.42, 0.22)), (True, "fit", (0.25, 0.45, 0.70))):
        s.geo_pattern_fit, s.geo_pattern_scale = fit, 0.5
        info = pattern_preview.pattern_for(bpy.context, model)
        demo_stage.select([model])
        cpu, wall = time.process_time(), time.perf_counter()
        assert bpy.ops.exsynth.geometric_texture() == {'FINISHED'}
        cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
        obj = bpy.context.view_layer.objects.active  # the result
        assert obj is not model, [o.name for o in bpy.data.objects]
        obj.name = f"Armadillo_{label}"
        obj.data.materials[0] = materials.new_surface_material(f"Fig {label}", rgb, roughness=0.45)
        made.append(obj)
        report.append(f"{label}: pattern scale {info['scale']:.3f} (size {info['size']:.3f} of height {HEIGHT}), "
                      f"{wall:.1f} s wall, {cpu:.1f} s CPU")
    model.hide_render = True
    demo_stage.prepare_scene(scene, 16)
    lo, hi = demo_stage.world_bounds(model)
    width = 1.15 * float(hi[0] - lo[0])
    centre = Vector((0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), lo[2]))
    for i, obj in enumerate(made):
        obj.location += Vector(((i - 0.5) * width, 0.0, 0.0)) - centre
    scene.render.resolution_x, scene.render.resolution_y = 640, 360
    demo_stage.aim_camera(scene, Vector((0.0, 0.0, 0.5 * HEIGHT)), distance=6.0, side=0.0)
    demo_stage.render(scene, out)
    print("figure_pattern_fit: " + "; ".join(report) + f" -> {out}", flush=True)


if __name__ == "__main__":
    args = sys.argv[sys.argv.index("--") + 1:]
    main(os.path.abspath(args[0]), int(args[1]) if len(args) > 1 else 160)
