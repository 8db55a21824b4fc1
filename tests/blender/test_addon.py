# SPDX-License-Identifier: GPL-3.0-or-later
"""The add-on registers cleanly, shows its sidebar tab and can be toggled."""

import os
import subprocess
import types

import addon_utils
import bpy
import pytest

import exsynth


def test_operator_panel_and_settings_are_registered():
    op = bpy.types.EXSYNTH_OT_voxelize
    assert op.bl_idname == "exsynth.voxelize"
    assert {'REGISTER', 'UNDO'} <= set(op.bl_options)
    assert bpy.ops.exsynth.voxelize.get_rna_type().identifier == "EXSYNTH_OT_voxelize"

    panel = bpy.types.EXSYNTH_PT_voxelize
    assert (panel.bl_space_type, panel.bl_region_type, panel.bl_category) == ('VIEW_3D', 'UI', "ExSynth")
    assert bpy.types.EXSYNTH_PT_voxelize_advanced.bl_parent_id == "EXSYNTH_PT_voxelize"
    # Surface Texture's job takes a seed and a memory budget: its Advanced panel shows them.
    assert bpy.types.EXSYNTH_PT_surface_advanced.bl_parent_id == "EXSYNTH_PT_surface"

    settings = bpy.context.scene.exsynth
    assert settings.resolution == 128 and settings.make_mesh is True
    rna = settings.bl_rna.properties["resolution"]
    assert (rna.hard_min, rna.hard_max) == (8, 1024)


def test_bl_info_targets_blender_3_4():
    assert exsynth.bl_info["blender"] == (3, 4, 0)
    assert exsynth.bl_info["category"] == "ExSynth"


def test_disable_removes_everything_and_enable_restores_it():
    addon_utils.disable("exsynth", default_set=True)
    try:
        assert not hasattr(bpy.types, "EXSYNTH_OT_voxelize")
        assert not hasattr(bpy.types, "EXSYNTH_PT_voxelize")
        assert not hasattr(bpy.types.Scene, "exsynth")
    finally:
        def raise_error(exc):
            raise exc

        addon_utils.enable("exsynth", default_set=True, handle_error=raise_error)
    assert hasattr(bpy.types, "EXSYNTH_OT_voxelize")
    assert bpy.context.scene.exsynth.resolution == 128


def test_package_imports_without_bpy():
    # The plain-Python tier imports exsynth._native with /usr/bin/python3,
    # which runs exsynth/__init__.py: it must not need bpy.
    addon_dir = os.path.dirname(os.path.dirname(exsynth.__file__))
    probe = subprocess.run(
        ["/usr/bin/python3", "-c", "import exsynth, exsynth._native, sys; "
         "assert 'bpy' not in sys.modules; print(exsynth.bl_info['name'])"],
        env={**os.environ, "PYTHONPATH": addon_dir}, capture_output=True, text=True, timeout=60,
    )
    assert probe.returncode == 0, probe.stderr
    assert probe.stdout.strip() == "ExSynth"


def test_a_module_for_another_python_fails_to_enable_with_one_line_naming_the_zip(tmp_path):
    """A zip whose compiled module is for another Python than this Blender's
    (a legacy zip in the wrong Blender): register() raises one line naming
    the zip to get, with no chained traceback, and registers nothing."""
    import importlib
    import shutil
    import sys

    from exsynth import platforms

    src = os.path.dirname(exsynth.__file__)
    pkg = tmp_path / "exsynth_wrong_python"
    shutil.copytree(src, pkg, ignore=shutil.ignore_patterns("__pycache__", "_native*.so"))
    here = sys.version_info[:2]
    other = next(p for p in sorted(platforms.PYTHONS) if p != here)
    (pkg / f"_native.cpython-{other[0]}{other[1]}-x86_64-linux-gnu.so").write_bytes(b"\x7fELF not for this Python")
    sys.path.insert(0, str(tmp_path))
    classes_before = set(dir(bpy.types))
    try:
        wrong = importlib.import_module("exsynth_wrong_python")
        with pytest.raises(ImportError) as raised:
            wrong.register()
    finally:
        sys.path.remove(str(tmp_path))
        for name in [n for n in sys.modules if n.startswith("exsynth_wrong_python")]:
            del sys.modules[name]
    message = str(raised.value)
    assert message == platforms.wrong_module_message(exsynth.bl_info["version"], here, bpy.app.version)
    assert "\n" not in message and platforms.extension_zip("0.1.0", here) in message
    assert raised.value.__cause__ is None and raised.value.__suppress_context__
    assert set(dir(bpy.types)) == classes_before


def test_defaults_and_limits_that_come_from_the_engine():
    from exsynth import _native, cli

    rna = bpy.context.scene.exsynth.bl_rna.properties
    assert rna["geo_spike_height"].default == pytest.approx(_native.PAIR_DEFAULTS["feature_height"])
    assert rna["geo_dilation"].default == pytest.approx(_native.PAIR_DEFAULTS["dilation"])
    assert (rna["solid_bake_resolution"].default, rna["solid_bake_resolution"].hard_max) == (
        _native.BAKE_DEFAULT_SIZE, _native.BAKE_MAX_SIZE)
    for name, default, hard in (("surface_segments", _native.SURFACE_DEFAULT_SEGMENTS, _native.SURFACE_MAX_SEGMENTS),
                                ("surface_face_resolution", _native.SURFACE_DEFAULT_FACE_RESOLUTION,
                                 _native.SURFACE_MAX_FACE_RESOLUTION)):
        assert (rna[name].default, rna[name].hard_max) == (default, hard), name
    surface = cli._parser().parse_args(["surface", "--mesh", "m.obj", "--exemplar", "e.png", "--out", "o.obj",
                                        "--texture-out", "t.png"])
    assert surface.segments == _native.SURFACE_DEFAULT_SEGMENTS
    assert rna["pts_density"].default == _native.POINTS_DEFAULT_DENSITY == cli.POINTS_DENSITY
    # The panels offer the engine's names, no more, no fewer.
    assert tuple(i.identifier.lower() for i in rna["geo_preset"].enum_items) == _native.PAIR_PRESETS
    assert tuple(i.identifier.lower() for i in rna["pts_preset"].enum_items) == _native.POINT_BUILTINS
    # The CLI bakes at the same default size as the panel.
    help_text = cli._parser()._subparsers._group_actions[0].choices["solid"].format_help()
    assert f"(default {_native.BAKE_DEFAULT_SIZE})" in " ".join(help_text.split())
    assert f"the engine's {_native.DEFAULT_MEMORY_BUDGET / 2 ** 30:g} GiB" in " ".join(help_text.split())


def test_the_surface_advanced_panel_draws_the_seed_and_the_memory_budget():
    drawn = []

    class Layout:
        def prop(self, _data, name, **_):
            drawn.append(name)

        def __getattr__(self, name):
            return lambda *a, **k: self

    layout = Layout()
    bpy.types.EXSYNTH_PT_surface_advanced.draw(types.SimpleNamespace(layout=layout, _layout=lambda: layout),
                                               bpy.context)
    assert drawn == ["seed", "memory_budget_gib"]
