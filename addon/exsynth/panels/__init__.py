# SPDX-License-Identifier: GPL-3.0-or-later
"""Sidebar panels (3D viewport, N-panel, tab "ExSynth")."""

from . import analogy, field, main, points, solid, surface

CLASSES = (*main.CLASSES, *solid.CLASSES, *field.CLASSES, *analogy.CLASSES, *surface.CLASSES, *points.CLASSES)
