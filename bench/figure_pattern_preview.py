# SPDX-License-Identifier: GPL-3.0-or-later
"""The viewport screenshot of docs/analogy.md: the pattern-size wire sphere
(ui/pattern_preview.py) on the armadillo, Fit to Model at resolution 160, in
Blender 3.4's UI on a virtual display (a saved empty file keeps the splash away):

    blender -b --factory-startup --python-expr "import bpy; bpy.ops.wm.save_as_mainfile(filepath='/tmp/e.blend')"
    xvfb-run -a -s "-screen 0 1280x800x24" blender --factory-startup /tmp/e.blend \
        --python bench/figure_pattern_preview.py -- OUT.png
"""
import sys, os, bpy
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "build", "addon"))
import addon_utils

OUT = os.path.abspath(sys.argv[sys.argv.index("--") + 1])
addon_utils.enable("exsynth", default_set=True, handle_error=lambda e: (_ for _ in ()).throw(e))
for o in list(bpy.data.objects):
    bpy.data.objects.remove(o)
bpy.ops.wm.obj_import(filepath=os.path.join(ROOT, "assets", "meshes", "armadillo.obj"))
obj = bpy.context.view_layer.objects.active
bpy.context.view_layer.update()
obj.scale = [2.0 / obj.dimensions.y] * 3
bpy.context.view_layer.update()
s = bpy.context.scene.exsynth
s.geo_resolution = 160
from exsynth.ui import pattern_preview
info = pattern_preview.pattern_for(bpy.context, obj)
print("INFO", info, flush=True)
def setup():
    for area in bpy.context.screen.areas:
        if area.type == 'VIEW_3D':
            sp = area.spaces.active
            sp.show_region_ui = False
            r3d = sp.region_3d
            r3d.view_perspective = 'PERSP'
            from mathutils import Vector, Euler
            r3d.view_location = Vector(info["centre"])
            r3d.view_distance = 5.0
            r3d.view_rotation = Euler((1.35, 0, 0.35)).to_quaternion()
            sp.shading.type = 'SOLID'
            for region in area.regions:
                if region.type == 'UI' and hasattr(region, "active_panel_category"):
                    region.active_panel_category = "ExSynth"
    return None
def shoot():
    for area in bpy.context.screen.areas:
        if area.type == 'VIEW_3D':
            ov = bpy.context.copy(); ov["area"] = area
            ov["region"] = [r for r in area.regions if r.type == 'WINDOW'][0]
            bpy.ops.screen.screenshot_area(ov, filepath=OUT)
    print("SHOT", flush=True)
    os._exit(0)
bpy.app.timers.register(setup, first_interval=0.5)
bpy.app.timers.register(shoot, first_interval=3.0)
