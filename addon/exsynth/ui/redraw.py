# SPDX-License-Identifier: GPL-3.0-or-later
"""Redrawing the 3D viewports (and their sidebars) from outside a draw:
after a draw handler is added or removed, or a background measure ends."""

import bpy


def tag_3d_views():
    wm = getattr(bpy.context, "window_manager", None)
    for win in getattr(wm, "windows", ()):
        for area in win.screen.areas:
            if area.type == 'VIEW_3D':
                area.tag_redraw()
