# SPDX-License-Identifier: GPL-3.0-or-later
"""exsynth: example-based texture and geometry synthesis for Blender.

This file only registers the add-on. It must stay importable without bpy:
plain-Python tests run `import exsynth._native` with the staged add-on on
PYTHONPATH, which executes this file first. Everything that needs bpy is
imported inside register()/unregister().
"""

bl_info = {
    "name": "ExSynth",
    "author": "exsynth contributors",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "View3D > Sidebar > ExSynth",
    "description": "Example-based texture and geometry synthesis (voxelize meshes into volumes, "
    "solid textures from 2D exemplars baked onto meshes)",
    "category": "ExSynth",
}

# Registration order matters: the PropertyGroup before anything that reads it.
_MODULES = ("properties", "operators", "panels", "overlay", "ui", "keymap")


def _modules():
    import importlib

    return [importlib.import_module(f"{__name__}.{name}") for name in _MODULES]


def register():
    import bpy

    try:
        from . import _native  # noqa: F401  (fail here, with advice, rather than on first use)
    except ImportError as exc:
        from . import platforms

        # One line, no chained traceback: which zip this Blender needs.
        raise ImportError(platforms.module_failure(__path__[0], bl_info["version"], bpy.app.version, exc)) from None

    done, attached = [], []
    try:
        for mod in _modules():
            for cls in mod.CLASSES:
                bpy.utils.register_class(cls)
                done.append(cls)
            if hasattr(mod, "attach"):
                mod.attach()
                attached.append(mod)
    except BaseException:
        # Leave Blender as it was, then let the caller see the real error.
        for mod in reversed(attached):
            mod.detach()
        _unregister_classes(done)
        raise


def unregister():
    mods = _modules()
    for mod in reversed(mods):
        if hasattr(mod, "detach"):
            mod.detach()
    _unregister_classes([cls for mod in mods for cls in mod.CLASSES])


def _unregister_classes(classes):
    import bpy

    for cls in reversed(classes):
        if getattr(cls, "is_registered", False):
            bpy.utils.unregister_class(cls)
