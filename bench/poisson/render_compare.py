"""blender -b --factory-startup --python render_compare.py -- MESH.obj OUT.png: Cycles, 8 samples, 360 x 300."""
import bpy, sys, math
argv = sys.argv[sys.argv.index("--") + 1:]
bpy.ops.wm.read_factory_settings(use_empty=True)
sc = bpy.context.scene
bpy.ops.import_scene.obj(filepath=argv[0], axis_forward='Y', axis_up='Z')
for o in bpy.context.selected_objects:
    o.data.materials.append(bpy.data.materials.new("m"))
    for p in o.data.polygons: p.use_smooth = True
cam = bpy.data.objects.new("cam", bpy.data.cameras.new("cam")); sc.collection.objects.link(cam)
cam.location = (1.0, -0.6, 1.1); cam.rotation_euler = (math.radians(50), 0, 0); cam.data.lens = 40
sc.camera = cam
sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", 'SUN')); sc.collection.objects.link(sun)
sun.rotation_euler = (math.radians(40), math.radians(20), math.radians(30)); sun.data.energy = 4
sc.world = bpy.data.worlds.new("w"); sc.world.color = (0.3, 0.3, 0.35)
sc.render.engine = 'CYCLES'; sc.cycles.samples = 8; sc.cycles.use_denoising = False; sc.render.resolution_x = 360; sc.render.resolution_y = 300
sc.render.filepath = argv[1]; bpy.ops.render.render(write_still=True)
