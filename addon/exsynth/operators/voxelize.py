# SPDX-License-Identifier: GPL-3.0-or-later
"""Voxelize the active mesh: a Volume with `density` and `sdf` grids and,
optionally, a mesh rebuilt from the voxels (the zero level of the sdf)."""

import dataclasses

import bpy
import numpy as np

from .. import _native
from ..io import mesh as mesh_io
from ..io import volume as volume_io
from ..io.selection import select_only
from ..jobs import InputError, Job, JobOperator, active_mesh


@dataclasses.dataclass
class Voxels:
    """What a VoxelizeJob returns; arrays are indexed [z, y, x]."""

    name: str
    density: np.ndarray
    sdf: np.ndarray
    origin: np.ndarray  # world position of the centre of voxel [0, 0, 0]
    voxel_size: float
    surface: tuple = None  # (vertices V by 3, triangles F by 3) when make_mesh

    @property
    def dims_xyz(self):
        return tuple(reversed(self.density.shape))

    def warning(self):
        """What to tell the user when the mesh encloses nothing: an open or
        flat mesh gives an all-empty density, which is valid but rarely meant."""
        if float(self.density.max(initial=0.0)) >= 0.5:
            return None
        return (f"'{self.name}' encloses no volume (it is open, flat or too thin for the voxel size), so the "
                "density is empty and the rebuilt mesh has no faces; close the mesh (e.g. a Solidify "
                "modifier) or raise the resolution")


@dataclasses.dataclass
class VoxelizeJob(Job):
    name: str
    vertices: np.ndarray  # world space, V by 3
    triangles: np.ndarray  # F by 3
    resolution: int = 128
    voxel_size: float = 0.0
    padding: int = 2
    supersample: int = 2
    make_mesh: bool = True
    memory_budget: int = 0  # bytes; 0 = the engine's default

    label = "voxelize"

    def run(self, ctx):
        self.share(ctx, 0.0, 0.85 if self.make_mesh else 1.0)
        grids = _native.voxelize(
            self.vertices, self.triangles,
            resolution=self.resolution, voxel_size=self.voxel_size, padding=self.padding,
            supersample=self.supersample, compute_sdf=True,
            memory_budget=self.memory_budget, ctx=ctx,
        )
        voxels = Voxels(self.name, grids["density"], grids["sdf"], grids["origin"], grids["voxel_size"])
        if self.make_mesh:
            # The sdf is positive outside, so the isosurface's normals face out.
            self.share(ctx, 0.85, 1.0)
            voxels.surface = _native.isosurface(
                voxels.sdf, voxels.origin, voxels.voxel_size, isovalue=0.0, ctx=ctx
            )
        return voxels


def source_triangles(obj, depsgraph):
    """World-space triangles of `obj`, or an InputError saying what to select."""
    active_mesh(obj, "the mesh to voxelize", "run Voxelize again")
    verts, tris = mesh_io.world_triangles([obj], depsgraph)
    if len(tris) == 0:
        raise InputError(
            f"the mesh '{obj.name}' has no faces (only vertices or edges), so it has no inside "
            "to voxelize. Give it faces (Edit Mode, select, F) or select another mesh"
        )
    return verts, tris


def add_voxel_objects(context, voxels, created):
    """Volume object `<name>_voxels` (+ mesh `<name>_voxel_mesh`) in the active
    collection, selected, the Volume active. Returns the new objects."""
    collection = context.collection
    vol_obj = volume_io.new_grids_object(f"{voxels.name}_voxels", {"density": voxels.density, "sdf": voxels.sdf},
                                         voxels.origin, voxels.voxel_size, collection, created)
    new_objects = [vol_obj]
    if voxels.surface is not None:
        new_objects.append(mesh_io.new_surface_object(f"{voxels.name}_voxel_mesh", *voxels.surface, collection,
                                                      created))

    select_only(context.view_layer, new_objects, active=vol_obj)
    return new_objects


class EXSYNTH_OT_voxelize(JobOperator, bpy.types.Operator):
    """Voxelize the active mesh into a Volume (density and signed-distance grids) and optionally a rebuilt mesh. Settings: ExSynth tab of the sidebar"""

    bl_idname = "exsynth.voxelize"
    bl_label = "Voxelize"
    bl_options = {'REGISTER', 'UNDO'}

    def make_job(self, context):
        if context.mode != 'OBJECT':
            raise InputError("works in Object Mode only. Press Tab to leave Edit Mode and run it again")
        settings = context.scene.exsynth
        obj = context.active_object
        verts, tris = source_triangles(obj, context.evaluated_depsgraph_get())
        return VoxelizeJob(
            name=obj.name, vertices=verts, triangles=tris,
            resolution=settings.resolution, padding=settings.padding,
            supersample=settings.supersample, make_mesh=settings.make_mesh,
            memory_budget=settings.memory_budget_bytes,
        )

    def finish(self, context, voxels, created):
        add_voxel_objects(context, voxels, created)
        nx, ny, nz = voxels.dims_xyz
        summary = f"ExSynth: voxelized '{voxels.name}' into {nx}×{ny}×{nz} voxels of {voxels.voxel_size:.4g}"
        if voxels.surface is not None:
            summary += f", mesh of {len(voxels.surface[1])} triangles"
        if voxels.warning():
            self.report({'WARNING'}, f"ExSynth Voxelize: {voxels.warning()}")
        return summary


CLASSES = (EXSYNTH_OT_voxelize,)
