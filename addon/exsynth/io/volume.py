# SPDX-License-Identifier: GPL-3.0-or-later
"""Engine grids -> .vdb file -> Blender Volume object.

Blender Volumes are file-backed, so every grid the add-on shows is first
written as OpenVDB into a cache folder: `//exsynth_cache/` beside the saved
.blend (stored relative, so the project can move), or Blender's session temp
folder for an unsaved file (deleted when Blender quits).
"""

import os

import bpy

from .. import _native

CACHE_FOLDER = "exsynth_cache"


def cache_dir():
    if bpy.data.filepath:
        return os.path.normpath(bpy.path.abspath("//" + CACHE_FOLDER))
    return os.path.join(bpy.app.tempdir, CACHE_FOLDER)


def new_cache_path(stem, ext=".vdb"):
    """A path in the cache folder no existing file uses: an earlier result's
    file must not be overwritten while its Volume (or an undo step) uses it."""
    stem = bpy.path.clean_name(stem)
    folder = cache_dir()
    path = os.path.join(folder, stem + ext)
    n = 1
    while os.path.exists(path):
        path = os.path.join(folder, f"{stem}_{n:03d}{ext}")
        n += 1
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


def new_volume_object(name, path, collection, created):
    """A Volume object reading `path`; its transform is the identity because
    the file's grid transform already places the voxels in world space."""
    volume = created.add(bpy.data.volumes.new(name))
    volume.filepath = bpy.path.relpath(path) if bpy.data.filepath else path
    if not volume.grids.load():
        raise OSError(f"Blender could not read the volume file {path}: {volume.grids.error_message}")
    obj = created.add(bpy.data.objects.new(name, volume))
    collection.objects.link(obj)
    return obj
