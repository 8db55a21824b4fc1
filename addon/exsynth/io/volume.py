# SPDX-License-Identifier: GPL-3.0-or-later
"""Engine grids -> .vdb file -> Blender Volume object.

Blender Volumes are file-backed, so every grid the add-on shows is first
written as OpenVDB into a cache folder: `//exsynth_cache/` beside the saved
.blend (stored relative, so the project can move), or Blender's session temp
folder for an unsaved file (deleted when Blender quits).
"""

import os

import bpy
import numpy as np

from .. import _native
from . import materials

CACHE_FOLDER = "exsynth_cache"


def cache_dir():
    if bpy.data.filepath:
        return os.path.normpath(bpy.path.abspath("//" + CACHE_FOLDER))
    return os.path.join(bpy.app.tempdir, CACHE_FOLDER)


# Every cache path handed out in this session: Blender (seen in 4.5) keeps
# a file's grids in memory by path, so a new file at a path used before, even
# one since deleted, would show the old grids.
_issued = set()


def new_cache_path(stem, ext=".vdb"):
    """A path in the cache folder no existing file uses and no earlier result
    of this session used: an earlier result's file must not be overwritten
    while its Volume (or an undo step) uses it."""
    stem = bpy.path.clean_name(stem)
    folder = cache_dir()
    path = os.path.join(folder, stem + ext)
    n = 1
    while os.path.exists(path) or path in _issued:
        path = os.path.join(folder, f"{stem}_{n:03d}{ext}")
        n += 1
    _issued.add(path)
    return path


def write_vdb(path, grids, origin, voxel_size, created):
    """Write named (Z, Y, X) float32 grids; `created` records the file (and a
    new folder) so a failed job can remove them."""
    folder = os.path.dirname(path)
    if not os.path.isdir(folder):
        os.makedirs(folder)
        created.add_file(folder)
    created.add_file(path)  # recorded first: a half-written file goes too
    _native.write_vdb(path, grids, origin, voxel_size)
    if not os.path.isfile(path) or os.path.getsize(path) == 0:
        raise OSError(f"the volume file {path} was not written (is the disk full?); nothing was changed")


def new_volume_object(name, path, voxel_size, collection, created):
    """A Volume object reading `path`, whose grid transform already places
    the voxels in world space; the object only corrects Blender's offset."""
    volume = created.add(bpy.data.volumes.new(name))
    volume.filepath = bpy.path.relpath(path) if bpy.data.filepath else path
    if not volume.grids.load():
        raise OSError(f"Blender could not read the volume file {path}: {volume.grids.error_message}")
    obj = created.add(bpy.data.objects.new(name, volume))
    obj.location = [-blender_cell_offset(voxel_size)] * 3
    collection.objects.link(obj)
    return obj


def new_grids_object(name, grids, origin, voxel_size, collection, created):
    """Named grids written to a new cache file and shown as a Volume object
    with the shared "ExSynth Volume" material (which reads `density`)."""
    path = new_cache_path(name)
    write_vdb(path, grids, origin, voxel_size, created)
    obj = new_volume_object(name, path, voxel_size, collection, created)
    obj.data.materials.append(materials.volume_material(created))
    return obj


def sdf_density(sdf, voxel_size):
    """A density for a signed distance (positive outside): 1 inside, 0
    outside, a one-voxel ramp, so the density-reading material shows it."""
    return np.clip(0.5 - sdf / voxel_size, 0.0, 1.0).astype(np.float32)


def blender_cell_offset(voxel_size):
    """How far Blender shows a .vdb's voxels from where OpenVDB puts them.

    OpenVDB (and our files) put the value of voxel (i, j, k) at index point
    (i, j, k). Blender 3.4 treats that point as the voxel's lower corner, so
    renders and Volume to Mesh come out shifted by +half a voxel on every
    axis (measured on 3.4.1: a Cycles render and VOLUME_TO_MESH of the sdf
    both sit 0.5 voxel above _native.isosurface). The file stays correct for
    other tools; the object is moved back instead. Measured with the add-on
    tests (test_voxelize.py::test_volume_lines_up_with_mesh) in each release:
    3.4.1, 4.2.23 and 4.5.15 shift by half a voxel; 5.0.0 and 5.0.1 do not.
    """
    if bpy.app.version >= (5, 0, 0):
        return 0.0
    return 0.5 * voxel_size
