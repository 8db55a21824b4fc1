# SPDX-License-Identifier: GPL-3.0-or-later
"""exsynth.voxelize on the bundled bunny: objects, grids, placement, volume."""

import os
import re

import bpy
import numpy as np
import pytest

from exsynth import _native
from exsynth.io import volume as volume_io
from helpers import bbox, enclosed_volume, volume_surface_points, world_mesh

RESOLUTION = 40


def voxelize(resolution=RESOLUTION, make_mesh=True):
    settings = bpy.context.scene.exsynth
    settings.resolution = resolution
    settings.make_mesh = make_mesh
    return bpy.ops.exsynth.voxelize()


def test_creates_volume_and_mesh_objects(bunny):
    before = {o.name for o in bpy.data.objects}
    assert voxelize() == {'FINISHED'}

    new = {o.name for o in bpy.data.objects} - before
    assert new == {"bunny_voxels", "bunny_voxel_mesh"}
    vol_obj, mesh_obj = bpy.data.objects["bunny_voxels"], bpy.data.objects["bunny_voxel_mesh"]
    assert vol_obj.type == 'VOLUME' and mesh_obj.type == 'MESH'
    assert "bunny" in bpy.data.objects  # the original stays
    assert {g.name for g in vol_obj.data.grids} == {"density", "sdf"}
    assert vol_obj.active_material.name == "ExSynth Volume"
    nodes = {n.bl_idname for n in vol_obj.active_material.node_tree.nodes}
    assert "ShaderNodeVolumePrincipled" in nodes
    assert mesh_obj.active_material.name == "ExSynth Surface"

    # In the active collection, selected, the Volume active, the original not selected.
    assert {o.name for o in bpy.context.collection.objects} >= new
    assert {o.name for o in bpy.context.view_layer.objects.selected} == new
    assert bpy.context.view_layer.objects.active == vol_obj

    # The file sits in the cache folder and holds what the Volume shows.
    path = bpy.path.abspath(vol_obj.data.filepath)
    assert os.path.dirname(path) == volume_io.cache_dir()
    # Numbered when an earlier test of this session used the name (see volume_io._issued).
    assert re.fullmatch(r"bunny_voxels(_\d{3})?\.vdb", os.path.basename(path))
    assert set(_native.read_vdb(path)["grids"]) == {"density", "sdf"}


def test_volume_bounds_match_the_bunny(bunny):
    assert voxelize() == {'FINISHED'}
    vol_obj = bpy.data.objects["bunny_voxels"]
    lo, hi = bbox(world_mesh(bunny)[0])
    h = _native.read_vdb(bpy.path.abspath(vol_obj.data.filepath))["voxel_size"]
    assert h == pytest.approx((hi - lo).max() / RESOLUTION, rel=0.05)

    # Blender's own reading of the density grid (Volume to Mesh at 0.5).
    v_lo, v_hi = bbox(volume_surface_points(vol_obj, "density", 0.5))
    np.testing.assert_allclose(v_lo, lo, atol=1.0 * h)
    np.testing.assert_allclose(v_hi, hi, atol=1.0 * h)

    # The object's bounding box covers the bunny plus padding; Blender rounds
    # its far side up to whole 8-voxel leaf nodes.
    corners = np.array(vol_obj.matrix_world) @ np.c_[np.array(vol_obj.bound_box), np.ones(8)].T
    b_lo, b_hi = corners[:3].min(axis=1), corners[:3].max(axis=1)
    padding = bpy.context.scene.exsynth.padding
    assert np.all(b_lo <= lo) and np.all(b_hi >= hi)
    assert np.all(lo - b_lo <= (padding + 1) * h)
    assert np.all(b_hi - hi <= (padding + 9) * h)


def test_volume_lines_up_with_mesh(bunny):
    # Blender's placement of the sdf grid must match the isosurface the
    # engine computed from the same grid (guards the half-voxel correction
    # in io/volume.py::blender_cell_offset).
    assert voxelize() == {'FINISHED'}
    vol_obj, mesh_obj = bpy.data.objects["bunny_voxels"], bpy.data.objects["bunny_voxel_mesh"]
    h = _native.read_vdb(bpy.path.abspath(vol_obj.data.filepath))["voxel_size"]
    b_lo, b_hi = bbox(volume_surface_points(vol_obj, "sdf", 0.0))
    m_lo, m_hi = bbox(world_mesh(mesh_obj)[0])
    np.testing.assert_allclose(b_lo, m_lo, atol=0.1 * h)
    np.testing.assert_allclose(b_hi, m_hi, atol=0.1 * h)


def test_rebuilt_mesh_encloses_the_same_volume(bunny):
    assert voxelize() == {'FINISHED'}
    original = enclosed_volume(*world_mesh(bunny))
    rebuilt = enclosed_volume(*world_mesh(bpy.data.objects["bunny_voxel_mesh"]))
    assert original > 0
    assert rebuilt > 0, "the rebuilt mesh's normals point inwards"
    assert rebuilt == pytest.approx(original, rel=0.03)


def test_without_make_mesh_only_the_volume_is_added(bunny):
    before = {o.name for o in bpy.data.objects}
    assert voxelize(make_mesh=False) == {'FINISHED'}
    assert {o.name for o in bpy.data.objects} - before == {"bunny_voxels"}
    assert "ExSynth Surface" not in bpy.data.materials


def test_second_run_keeps_the_first_file(bunny):
    assert voxelize() == {'FINISHED'}
    bpy.context.view_layer.objects.active = bunny
    assert voxelize() == {'FINISHED'}
    paths = {bpy.path.abspath(v.filepath) for v in bpy.data.volumes}
    assert len(paths) == 2 and all(os.path.isfile(p) for p in paths)
    assert len(bpy.data.materials.keys()) == 2  # the materials are shared, not duplicated


def test_saved_file_caches_beside_the_blend_with_relative_paths(bunny, tmp_path):
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "scene.blend"))
    assert voxelize() == {'FINISHED'}
    volume = bpy.data.objects["bunny_voxels"].data
    assert volume.filepath == "//exsynth_cache/bunny_voxels.vdb"
    assert (tmp_path / "exsynth_cache" / "bunny_voxels.vdb").is_file()


def test_panel_grid_estimate_is_the_grid_voxelize_makes(bunny):
    # The estimate reads the object's dimensions (rotation not included):
    # unrotated, they are its world bounding box.
    from exsynth.panels.main import _grid_estimate

    bunny.rotation_euler = (0.0, 0.0, 0.0)
    bpy.context.view_layer.update()
    settings = bpy.context.scene.exsynth
    settings.padding = 3
    assert voxelize() == {'FINISHED'}
    path = bpy.path.abspath(bpy.data.objects["bunny_voxels"].data.filepath)
    z, y, x = _native.read_vdb(path)["grids"]["density"].shape
    assert _grid_estimate(bunny, settings) == f"about {x} × {y} × {z} voxels"
