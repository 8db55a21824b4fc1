# SPDX-License-Identifier: GPL-3.0-or-later
"""Shared fixtures of the add-on tests (run inside Blender by run_tests.py)."""

import os
import shutil

import bpy
import pytest

from exsynth import jobs
from exsynth.io import volume as volume_io
from helpers import BUNNY_OBJ, COW_OBJ, TEXTURES


@pytest.fixture(autouse=True)
def clean_scene():
    """An empty, unsaved file for every test, add-on still enabled.

    read_homefile(use_empty=True) keeps registered add-ons (unlike
    read_factory_settings) and resets the scene's ExSynth settings. The
    unsaved file's cache folder (in Blender's session temp dir) is emptied;
    cache file names still count up over the session, as for a user (Blender
    4.5 keeps a deleted file's grids in memory by path).
    """
    bpy.ops.wm.read_homefile(use_empty=True)
    shutil.rmtree(volume_io.cache_dir(), ignore_errors=True)
    assert hasattr(bpy.types, "EXSYNTH_OT_voxelize"), "the add-on lost its registration"
    assert bpy.data.filepath == "" and len(bpy.data.objects) == 0
    jobs.job_started_hooks.clear()
    yield
    jobs.job_started_hooks.clear()


@pytest.fixture
def bunny():
    """The bundled bunny, imported Z-up and moved/scaled so that world space
    differs from its mesh space."""
    bpy.ops.wm.obj_import(filepath=BUNNY_OBJ)
    obj = bpy.context.view_layer.objects.active
    assert obj is not None and obj.name == "bunny"
    obj.location = (3.0, -2.0, 1.0)
    obj.scale = (0.5, 0.5, 0.5)
    bpy.context.view_layer.update()
    return obj



@pytest.fixture
def cow():
    """The bundled cow (no UV map), moved and scaled, the only selected object."""
    bpy.ops.wm.obj_import(filepath=COW_OBJ)
    obj = bpy.context.view_layer.objects.active
    assert obj is not None and obj.name == "cow" and len(obj.data.uv_layers) == 0
    obj.location = (1.5, -0.7, 0.4)
    obj.scale = (0.8, 0.8, 0.8)
    bpy.context.view_layer.update()
    assert [o.name for o in bpy.context.selected_objects] == ["cow"]
    return obj


@pytest.fixture
def exemplar():
    """A bundled 128² 8-bit texture, loaded by Blender and set as the Solid
    Texture exemplar, with settings small enough for fast tests."""
    image = bpy.data.images.load(os.path.join(TEXTURES, "crackedground.png"))
    settings = bpy.context.scene.exsynth
    settings.solid_exemplar = image
    settings.solid_method = 'OPTIMIZATION'  # the optimiser's tests; the method's own tests set it
    settings.solid_size = 16
    settings.solid_levels = 2
    settings.solid_iterations = 2
    settings.solid_bake_resolution = 128
    return image
