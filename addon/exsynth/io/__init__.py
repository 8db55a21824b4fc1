# SPDX-License-Identifier: GPL-3.0-or-later
"""Conversions between Blender data and the numpy arrays the engine works on
(no operators or panels here, so nothing to register)."""
