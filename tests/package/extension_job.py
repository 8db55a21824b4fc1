# SPDX-License-Identifier: GPL-3.0-or-later
"""Runs inside a PyPI bpy venv (started by test_extension.py, never on its own):

    BLENDER_USER_RESOURCES=EMPTY_DIR VENV/bin/python extension_job.py ZIP MODE OUT.json

Installs the extension zip into the (empty) user folder, enables it, runs
each tool once (Voxelize, Direction Field, Geometric Texture, Solid Texture,
Surface Texture, Point Texture) and a small Cycles render (Blender's own
Embree 4 in the same process), and writes what it saw as JSON. MODE "global"
loads Blender's libraries into the global symbol scope first, as the blender
executable has them (its own dependencies), where same-named symbols of
Blender's Embree 4 would otherwise capture the module's Embree calls. MODE
"refused": only the install, expected to be refused; its reports are kept.
"""

import json
import os
import sys

zip_path, mode, out_path = sys.argv[1:4]
if mode == "global":
    flags = sys.getdlopenflags()
    sys.setdlopenflags(os.RTLD_NOW | os.RTLD_GLOBAL)
    import bpy  # noqa: E402
    sys.setdlopenflags(flags)
else:
    import bpy  # noqa: E402
import importlib.util  # noqa: E402

import numpy as np  # noqa: E402

seen = {"mode": mode, "blender": ".".join(map(str, bpy.app.version))}
# The build tree and a system-wide exsynth are out of reach.
seen["exsynth_importable_before"] = importlib.util.find_spec("exsynth") is not None
seen["build_tree_on_path"] = [p for p in sys.path if os.path.join("build", "addon") in p]

bpy.ops.wm.read_factory_settings(use_empty=True)
if mode == "refused":
    # Blender's refusal is an ERROR report (printed to stdout), not a result.
    seen["install"] = sorted(bpy.ops.extensions.package_install_files(
        filepath=zip_path, repo="user_default", enable_on_install=True))
    seen["addons"] = sorted(k for k in bpy.context.preferences.addons.keys() if "exsynth" in k)
    with open(out_path, "w", encoding="utf-8") as fh:
        json.dump(seen, fh, indent=1)
    sys.stdout.flush()
    os._exit(0)
seen["install"] = sorted(bpy.ops.extensions.package_install_files(
    filepath=zip_path, repo="user_default", enable_on_install=True))
seen["addons"] = sorted(k for k in bpy.context.preferences.addons.keys() if "exsynth" in k)
module = sys.modules["bl_ext.user_default.exsynth"]
native = sys.modules["bl_ext.user_default.exsynth._native"]
seen["package_dir"] = os.path.dirname(module.__file__)
seen["native_file"] = native.__file__

# A small mesh, off the origin and scaled, so world space matters.
bpy.ops.mesh.primitive_torus_add(major_radius=1.0, minor_radius=0.35, location=(0.5, -0.2, 0.3))
torus = bpy.context.view_layer.objects.active
torus.name = "Torus"
settings = bpy.context.scene.exsynth
settings.resolution = 40
settings.make_mesh = True
seen["voxelize"] = sorted(bpy.ops.exsynth.voxelize())
volumes = [o for o in bpy.data.objects if o.type == 'VOLUME']
seen["volumes"] = [o.name for o in volumes]
if volumes:
    grids = native.read_vdb(bpy.path.abspath(volumes[0].data.filepath))["grids"]
    seen["sdf_inside_voxels"] = int((np.asarray(grids["sdf"]) < 0).sum())
    seen["density_sum"] = float(np.asarray(grids["density"]).sum())
seen["voxel_mesh_vertices"] = [len(o.data.vertices) for o in bpy.data.objects
                               if o.type == 'MESH' and o is not torus]

for obj in list(bpy.data.objects):
    if obj is not torus:
        bpy.data.objects.remove(obj)
bpy.context.view_layer.objects.active = torus
torus.select_set(True)
settings.geo_preset = 'SPIKES'
settings.geo_resolution = 40
seen["geometric_texture"] = sorted(bpy.ops.exsynth.geometric_texture())
results = [o for o in bpy.data.objects if o.type == 'MESH' and o is not torus]
seen["texture_results"] = [(o.name, len(o.data.vertices)) for o in results]


def run_tool(name, op):
    """One tool on the torus (active and selected); its new objects' names."""
    before = set(bpy.data.objects)
    bpy.context.view_layer.objects.active = torus
    for obj in bpy.data.objects:
        obj.select_set(obj is torus)
    seen["tools"][name] = sorted(op())
    seen["tool_results"][name] = sorted(o.name for o in set(bpy.data.objects) - before)


ASSETS = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "assets")
seen["tools"], seen["tool_results"] = {}, {}
settings.field_preset, settings.field_axis = 'AROUND_AXIS', 'Z'
run_tool("direction_field", bpy.ops.exsynth.direction_field)
exemplar = bpy.data.images.load(os.path.join(ASSETS, "textures", "crackedground.png"))
settings.solid_exemplar = exemplar
settings.solid_size, settings.solid_levels, settings.solid_iterations = 16, 2, 2
settings.solid_bake_resolution = 64
run_tool("solid_texture", bpy.ops.exsynth.solid_texture)
settings.surface_exemplar = exemplar
settings.surface_size_mode, settings.surface_face_resolution = 'FACE', 4
run_tool("surface_texture", bpy.ops.exsynth.surface_texture)
settings.pts_density, settings.pts_width, settings.pts_depth, settings.pts_patch_size = 2500.0, 1.0, 1.0, 0.45
run_tool("point_texture", bpy.ops.exsynth.point_texture)

# Cycles (Blender's Embree 4) in the same process, after the module ran.
scene = bpy.context.scene
cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
scene.collection.objects.link(cam)
cam.location = (0.5, -6.0, 2.5)
cam.rotation_euler = (1.18, 0.0, 0.0)
scene.camera = cam
scene.render.engine = 'CYCLES'
scene.cycles.device = 'CPU'
scene.cycles.samples = 1
scene.cycles.use_denoising = False
scene.render.film_transparent = True
scene.render.resolution_x = scene.render.resolution_y = 32
scene.render.filepath = os.path.join(os.path.dirname(out_path), "render.png")
bpy.ops.render.render(write_still=True)
image = bpy.data.images.load(scene.render.filepath)
alpha = np.array(image.pixels[:], np.float32).reshape(-1, 4)[:, 3]
seen["render_coverage"] = float((alpha > 0.5).mean())

# Which copy of each library the process runs.
maps = {line.split()[-1] for line in open("/proc/self/maps") if ".so" in line}
seen["mapped"] = sorted(maps)
with open(out_path, "w", encoding="utf-8") as fh:
    json.dump(seen, fh, indent=1)
sys.stdout.flush()
os._exit(0)  # the 4.2 module can crash in interpreter teardown (see tests/blender/run_bpy.py)
