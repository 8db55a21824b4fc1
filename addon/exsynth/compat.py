# SPDX-License-Identifier: GPL-3.0-or-later
"""Differences between the Blender releases the add-on runs in (Debian's
3.4, official 4.2 LTS, 4.5 LTS, 5.x), in one place. Each helper says what
changed and where it was checked.

- The gpu module's built-in shader names. Blender 3.x names them per
  dimension ('3D_UNIFORM_COLOR', '2D_UNIFORM_COLOR', '3D_POLYLINE_SMOOTH_COLOR');
  4.0 removed those names for dimension-free ones ('UNIFORM_COLOR',
  'POLYLINE_SMOOTH_COLOR') that serve 2D and 3D alike.
- Node trees of new materials and worlds (`use_nodes`, deprecated in 5.0).
"""

import bpy

NEW_SHADER_NAMES = bpy.app.version >= (4, 0, 0)


def builtin_shader_name(name, dimensions=3):
    """The built-in shader called `name` in Blender 4+ ('UNIFORM_COLOR',
    'SMOOTH_COLOR', 'POLYLINE_UNIFORM_COLOR', 'POLYLINE_SMOOTH_COLOR'), as this
    Blender names it for drawing in `dimensions` (2 or 3)."""
    if NEW_SHADER_NAMES:
        return name
    return f"{dimensions}D_{name}"


def builtin_shader(name, dimensions=3):
    import gpu  # not importable in every context (no GPU in `blender -b`): import on use

    return gpu.shader.from_builtin(builtin_shader_name(name, dimensions))


def ensure_node_tree(data):
    """The node tree of a material or world, made if missing.

    Up to 4.5 a new material or world has no node tree until `use_nodes` is
    set. 5.0 gives each one and deprecates `use_nodes` (setting it prints a
    DeprecationWarning). Checked on 3.4.1, 4.5.15 (node_tree None after
    materials.new) and 5.0.1 (node_tree present for materials and worlds)."""
    if data.node_tree is None:
        data.use_nodes = True
    return data.node_tree
