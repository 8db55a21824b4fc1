# SPDX-License-Identifier: GPL-3.0-or-later
"""Bad inputs are refused with a message that says what to change, and the
scene stays as it was. In background mode bpy.ops raises RuntimeError
carrying the operator's error report."""

import bpy
import pytest

from helpers import add_camera, add_faceless_mesh, scene_state


def run_expecting_error(match):
    before = scene_state()
    with pytest.raises(RuntimeError, match=match):
        bpy.ops.exsynth.voxelize()
    assert scene_state() == before


def test_no_active_object(bunny):
    bpy.context.view_layer.objects.active = None
    run_expecting_error(r"no active object\. Select the mesh")


def test_active_object_is_not_a_mesh(bunny):
    cam = add_camera()
    bpy.context.view_layer.objects.active = cam
    run_expecting_error(r"'Cam' is a camera, not a mesh\. Select a mesh object")


def test_mesh_without_faces():
    obj = add_faceless_mesh()
    run_expecting_error(r"'Dots' has no faces")


def test_resolution_over_the_memory_budget(bunny):
    settings = bpy.context.scene.exsynth
    settings.resolution = 512
    settings.memory_budget_gib = 0.001
    run_expecting_error(r"over the memory budget of 1\.02 MiB.*lower the resolution")


def test_edit_mode(bunny):
    bpy.ops.object.mode_set(mode='EDIT')
    try:
        run_expecting_error(r"Object Mode only")
    finally:
        bpy.ops.object.mode_set(mode='OBJECT')
