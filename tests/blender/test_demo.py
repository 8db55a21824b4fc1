# SPDX-License-Identifier: GPL-3.0-or-later
"""The demo's stage (addon/exsynth/demo_stage.py) in this Blender: the scene
it sets up renders. `./exsynth demo` itself renders for minutes; this runs
its staging and one tiny render, so a Blender release that renamed what the
stage uses (4.x's AgX looks did) fails here, not in an artist's first demo."""

import bpy
import numpy as np

from exsynth import demo_stage


def test_the_demo_stage_renders_a_cube_over_its_floor(tmp_path):
    scene = bpy.context.scene
    demo_stage.prepare_scene(scene, samples=1)
    assert scene.render.engine == 'CYCLES' and scene.camera is not None and scene.world.name == "Demo World"
    assert scene.view_settings.look != 'None'
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0.0, 0.0, 0.5))
    cube = bpy.context.active_object
    demo_stage.aim_camera(scene, cube.location.copy(), 6.0, 0.3)
    scene.render.resolution_x = scene.render.resolution_y = 24
    path = str(tmp_path / "stage.png")
    demo_stage.render(scene, path)
    image = bpy.data.images.load(path)
    px = np.array(image.pixels[:], np.float32).reshape(24, 24, 4)[..., :3]
    assert px.std() > 0.01  # cube, floor and sky: not one flat colour
