# SPDX-License-Identifier: GPL-3.0-or-later
"""The differences between the Blender releases the add-on supports (Debian's
3.4, 4.2 LTS, 4.5 LTS, 5.x), in one place. Each helper says what changed and
where it was checked."""

import bpy


def ensure_node_tree(data):
    """The node tree of a material or world, made if missing.

    Up to 4.5 a new material or world has no node tree until `use_nodes` is
    set. 5.0 gives each one and deprecates `use_nodes` (setting it prints a
    DeprecationWarning). Checked on 3.4.1, 4.5.15 (node_tree None after
    materials.new) and 5.0.1 (node_tree present for materials and worlds)."""
    if data.node_tree is None:
        data.use_nodes = True
    return data.node_tree


def builtin_shader(name):
    """A gpu built-in shader by its 3.4+ name ('UNIFORM_COLOR',
    'POLYLINE_UNIFORM_COLOR'). 3.4 accepts these names beside the older
    '3D_'-prefixed ones, which 4.0 removed; anything else that moves goes
    here."""
    import gpu

    return gpu.shader.from_builtin(name)
