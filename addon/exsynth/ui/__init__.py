# SPDX-License-Identifier: GPL-3.0-or-later
"""Viewport drawing (gpu draw handlers), attached at registration."""

from . import pattern_preview

CLASSES = ()


def attach():
    pattern_preview.attach()


def detach():
    pattern_preview.detach()
