# SPDX-License-Identifier: GPL-3.0-or-later
"""Shared fixtures of the add-on tests (run inside Blender by run_tests.py)."""

import shutil

import bpy
import pytest

from exsynth import jobs
from exsynth.io import volume as volume_io
from helpers import BUNNY_OBJ


@pytest.fixture(autouse=True)
def clean_scene():
    """An empty, unsaved file for every test, add-on still enabled.

    read_homefile(use_empty=True) keeps registered add-ons (unlike
    read_factory_settings) and resets the scene's ExSynth settings. The
    unsaved file's cache folder (in Blender's session temp dir) is emptied
    so file names do not depend on the tests run before.
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

