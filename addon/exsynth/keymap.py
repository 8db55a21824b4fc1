# SPDX-License-Identifier: GPL-3.0-or-later
"""The add-on's shortcut: Shift+Alt+P over the 3D viewport starts Paint
Direction Field on the active mesh (no default Blender binding uses it in
3.4, 4.2, 4.5 or 5.0's Object Mode). Registered in the add-on key
configuration, so Preferences › Keymap can change or disable it; absent
where Blender has no window manager key configuration (`blender -b`, bpy)."""

import bpy

CLASSES = ()
PAINT_SHORTCUT = dict(type='P', value='PRESS', shift=True, alt=True)

_items = []


def attach():
    keyconfig = bpy.context.window_manager.keyconfigs.addon if bpy.context.window_manager else None
    if keyconfig is None:
        return
    keymap = keyconfig.keymaps.new(name="3D View", space_type='VIEW_3D')
    _items.append((keymap, keymap.keymap_items.new("exsynth.paint_direction_field", **PAINT_SHORTCUT)))


def detach():
    for keymap, item in _items:
        try:
            keymap.keymap_items.remove(item)
        except (ReferenceError, RuntimeError):  # the key configuration went first (Blender quitting)
            pass
    _items.clear()
