# SPDX-License-Identifier: GPL-3.0-or-later
"""Selection in the view layer: results are selected and active when an
operator or a headless job hands them over."""


def select_only(view_layer, objects, active=None):
    """Deselect everything, select `objects`, make `active` (default: the
    first of them) the active object."""
    for other in list(view_layer.objects.selected):
        other.select_set(False)
    for obj in objects:
        obj.select_set(True)
    view_layer.objects.active = active if active is not None else objects[0]
