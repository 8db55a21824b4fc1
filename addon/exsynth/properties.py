# SPDX-License-Identifier: GPL-3.0-or-later
"""The add-on's settings: one PropertyGroup, stored on the Scene as `scene.exsynth`."""

import bpy
from bpy.props import BoolProperty, FloatProperty, IntProperty, PointerProperty

GIB = 1 << 30


class ExSynthSettings(bpy.types.PropertyGroup):
    resolution: IntProperty(
        name="Resolution",
        description="Voxels along the longest side of the object's bounding box",
        default=128, min=8, max=1024, soft_max=512,
    )
    padding: IntProperty(
        name="Padding",
        description="Empty voxels added around the object on every side, so the surface "
        "and its distance field do not touch the grid border",
        default=2, min=0, max=64,
    )
    supersample: IntProperty(
        name="Supersample",
        description="Sub-rays per voxel edge used to measure how much of a surface voxel "
        "is inside (higher: smoother density, slower)",
        default=2, min=1, max=8,
    )
    make_mesh: BoolProperty(
        name="Make Mesh",
        description="Also rebuild a mesh from the voxels (the zero level of the signed distance)",
        default=True,
    )
    seed: IntProperty(
        name="Seed",
        description="Random seed (the same inputs and seed give the same result)",
        default=0, min=0,
    )
    memory_budget_gib: FloatProperty(
        name="Memory Budget",
        description="Refuse a job whose estimated peak memory exceeds this many GiB "
        "(checked before anything is allocated)",
        default=8.0, min=0.001, max=1024.0, soft_max=64.0, precision=3, unit='NONE',
    )

    @property
    def memory_budget_bytes(self) -> int:
        return max(1, int(self.memory_budget_gib * GIB))


CLASSES = (ExSynthSettings,)


def attach():
    bpy.types.Scene.exsynth = PointerProperty(type=ExSynthSettings)


def detach():
    if hasattr(bpy.types.Scene, "exsynth"):
        del bpy.types.Scene.exsynth
