# SPDX-License-Identifier: GPL-3.0-or-later
"""Sidebar panels (3D viewport, N-panel, tab "ExSynth")."""

from . import analogy, field, main, points, solid

CLASSES = (*main.CLASSES, *solid.CLASSES, *field.CLASSES, *analogy.CLASSES, *points.CLASSES)
