# SPDX-License-Identifier: GPL-3.0-or-later
"""Differences between the Blender releases the add-on runs in (Debian's
3.4, official 4.2 LTS, 4.5 LTS, 5.x), in one place. Each helper says what
changed and where it was checked.

- The gpu module's built-in shader names. Blender 3.x names them per
  dimension ('3D_UNIFORM_COLOR', '2D_UNIFORM_COLOR', '3D_POLYLINE_SMOOTH_COLOR');
  4.0 removed those names for dimension-free ones ('UNIFORM_COLOR',
  'POLYLINE_SMOOTH_COLOR') that serve 2D and 3D alike.
- Sized points: 4.5 has a POINT_UNIFORM_COLOR shader with a `size`
  uniform (its name is in 4.5.15's and 5.0.1's bpy binaries, not in
  4.2.23's; the wheels cannot make shaders, so it was not drawn there);
  before, the point size is GL state (`gpu.state.point_size_set`).
- Wide lines: `gpu.state.line_width_set` above 1 is not honoured by every
  backend; the POLYLINE shaders (3.x and later) draw width themselves.
- Node trees of new materials and worlds (`use_nodes`, deprecated in 5.0).
- The sidebar's tab: `Region.active_panel_category` (in the 4.2.23 and
  5.0.1 wheels' RNA, not in Debian's 3.4) names the tab a region shows.
- A geometry-nodes modifier's input values: ID properties of the modifier
  keyed by the socket's identifier (`mod["Socket_0"]`) up to 5.0; in 5.2 the
  modifier takes no ID properties and each input is
  `mod.properties.inputs.<identifier>.value`.
- Group interface sockets: `group.interface` from 4.0, `group.inputs` before.
- Colour looks: 3.x's Filmic names them plainly ('Medium Contrast'); 4.0
  made AgX the default view transform and prefixes each look with its view
  transform ('AgX - Base Contrast'; seen in Debian 13's 4.3.2).
"""

import bpy

NEW_SHADER_NAMES = bpy.app.version >= (4, 0, 0)
POINT_SIZE_UNIFORM = bpy.app.version >= (4, 5, 0)


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


def point_shader():
    """The built-in shader for points of one colour and a set size (see
    set_point_size)."""
    return builtin_shader('POINT_UNIFORM_COLOR' if POINT_SIZE_UNIFORM else 'UNIFORM_COLOR')


def set_point_size(shader, size):
    """Point size in pixels for point_shader(), after shader.bind(): a uniform
    from 4.5 on, GL state before (reset it with gpu.state.point_size_set(1))."""
    if POINT_SIZE_UNIFORM:
        shader.uniform_float("size", size)
    else:
        import gpu

        gpu.state.point_size_set(size)


def line_shader():
    """The built-in shader for lines of one colour and a width in pixels
    (set_line_style), in 2D or 3D alike."""
    return builtin_shader('POLYLINE_UNIFORM_COLOR')


def set_line_style(shader, colour, width):
    """Colour and width for line_shader(), after shader.bind()."""
    import gpu

    shader.uniform_float("viewportSize", gpu.state.viewport_get()[2:])
    shader.uniform_float("lineWidth", width)
    shader.uniform_float("color", colour)


def sidebar_tab(region):
    """The tab (panel category) a sidebar region shows, or None where
    Blender cannot tell: before 4.1, or before the region first drew."""
    tab = getattr(region, "active_panel_category", None)
    return tab if tab and tab != 'UNSUPPORTED' else None


def ensure_node_tree(data):
    """The node tree of a material or world, made if missing.

    Up to 4.5 a new material or world has no node tree until `use_nodes` is
    set. 5.0 gives each one and deprecates `use_nodes` (setting it prints a
    DeprecationWarning). Checked on 3.4.1, 4.5.15 (node_tree None after
    materials.new) and 5.0.1 (node_tree present for materials and worlds)."""
    if data.node_tree is None:
        data.use_nodes = True
    return data.node_tree


def group_input_identifier(group, name):
    """The identifier of node group input `name` (its key on a modifier)."""
    if hasattr(group, "interface"):
        for item in group.interface.items_tree:
            if getattr(item, "in_out", None) == 'INPUT' and item.name == name:
                return item.identifier
        raise KeyError(f"node group {group.name!r} has no input {name!r}")
    return group.inputs[name].identifier


def _modifier_inputs(mod):
    properties = getattr(mod, "properties", None)
    return getattr(properties, "inputs", None)


def set_modifier_input(mod, name, value):
    """Sets the geometry-nodes modifier's input `name` (of its node group)
    to `value`: an ID property up to 5.0, `properties.inputs` in 5.2 (checked
    on 3.4.1, 4.5.15 and 5.2.3)."""
    key = group_input_identifier(mod.node_group, name)
    inputs = _modifier_inputs(mod)
    if inputs is not None:
        getattr(inputs, key).value = value
    else:
        mod[key] = value


def modifier_input(mod, name):
    """The value of the geometry-nodes modifier's input `name`."""
    key = group_input_identifier(mod.node_group, name)
    inputs = _modifier_inputs(mod)
    return getattr(inputs, key).value if inputs is not None else mod[key]


def set_medium_contrast_look(view_settings):
    """The view transform's neutral, medium-contrast look: 'Medium Contrast'
    (Filmic, 3.x), else '<transform> - Medium Contrast', else
    '<transform> - Base Contrast' (AgX, 4.x); left as it is when none exists.
    Returns the look set."""
    transform = view_settings.view_transform
    # The looks are a dynamic enum (RNA lists only 'None'): try each name.
    for look in ("Medium Contrast", f"{transform} - Medium Contrast", f"{transform} - Base Contrast"):
        try:
            view_settings.look = look
            break
        except TypeError:
            continue
    return view_settings.look
