# SPDX-License-Identifier: GPL-3.0-or-later
"""Operators: thin wrappers that collect inputs, run a job (jobs.py), build results."""

from . import analogy, field, field_paint, points, solid, surface, voxelize

CLASSES = (*voxelize.CLASSES, *solid.CLASSES, *field.CLASSES, *field_paint.CLASSES, *analogy.CLASSES, *surface.CLASSES, *points.CLASSES)
