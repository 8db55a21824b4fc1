# SPDX-License-Identifier: GPL-3.0-or-later
"""Solid Texture and Re-bake on the bundled cow with a bundled exemplar:
results, placement, consistency between bakes, exemplar reading, errors,
cancel and rollback. Small solids (16³, 2 levels) keep it fast."""

import os
import time

import bpy
import numpy as np
import pytest

from exsynth import _native, jobs
from exsynth.io import bake as bake_io
from exsynth.io import image as image_io
from exsynth.io import volume as volume_io
from exsynth.operators import solid as solid_ops
from helpers import TEXTURES, add_camera, cancel_once_running, mesh_state, scene_state


def settings():
    return bpy.context.scene.exsynth


def image_pixels(image):
    """(H, W, 4) float32, Blender's order (row 0 at the bottom)."""
    width, height = image.size
    flat = np.empty(width * height * 4, np.float32)
    image.pixels.foreach_get(flat)
    return flat.reshape(height, width, 4)


def read_solid(volume_obj):
    """(values (Z, Y, X, C), origin, voxel_size) of a solid Volume's file, as Re-bake reads it."""
    path = bpy.path.abspath(volume_obj.data.filepath)
    size = volume_obj.data[solid_ops.METADATA]["size"]
    return solid_ops.tile_from_vdb(_native.read_vdb(path), size)


def grid_points(volume_obj, world_points):
    """World points in the solid's grid space (what the .vdb's voxels are placed in)."""
    values, origin, h = read_solid(volume_obj)
    m = solid_ops.world_to_grid(volume_obj, h)
    return np.asarray(world_points, np.float64) @ m[:3, :3].T + m[:3, 3]


def world_corners(obj):
    """World position of every face corner (loop) of a mesh object."""
    mesh = obj.data
    co = np.empty(3 * len(mesh.vertices), np.float32)
    mesh.vertices.foreach_get("co", co)
    loops = np.empty(len(mesh.loops), np.int32)
    mesh.loops.foreach_get("vertex_index", loops)
    m = np.array(obj.matrix_world)
    return (co.reshape(-1, 3) @ m[:3, :3].T + m[:3, 3])[loops]


def corner_colors(obj, name="solid"):
    attr = obj.data.color_attributes[name]
    out = np.empty(4 * len(attr.data), np.float32)
    attr.data.foreach_get("color", out)
    return out.reshape(-1, 4)


def rebake_independently(obj, uv_map, volume_obj, resolution):
    """(image, mask) of _native.bake_volume_to_uv called directly with the
    object's loop triangles and UV map: what the operator should have made."""
    mesh = obj.data
    mesh.calc_loop_triangles()
    loops = np.empty(3 * len(mesh.loop_triangles), np.int32)
    mesh.loop_triangles.foreach_get("loops", loops)
    loops = loops.reshape(-1, 3)
    uv = np.empty(2 * len(mesh.loops), np.float32)
    mesh.uv_layers[uv_map].data.foreach_get("uv", uv)
    positions = grid_points(volume_obj, world_corners(obj))[loops].astype(np.float32)
    values, origin, h = read_solid(volume_obj)
    margin = solid_ops.BakeOptions(resolution).margin
    return _native.bake_volume_to_uv(values, origin, h, positions, uv.reshape(-1, 2)[loops],
                                     resolution, resolution, margin=margin)


def check_baked_image(image, obj, uv_map, volume_obj):
    """The image holds the solid at the mesh's surface: filled where the
    engine says a triangle (or the margin) covers a texel, and not uniform."""
    px = image_pixels(image)[..., :3]
    expected, mask = rebake_independently(obj, uv_map, volume_obj, image.size[0])
    covered = mask > 0
    assert (mask == 1).mean() > 0.15
    assert np.all(px[covered].sum(axis=1) > 0.05)
    assert px[mask == 1].std(axis=0).min() > 0.02
    # 8-bit image: the engine's floats rounded to 1/255.
    np.testing.assert_allclose(px[covered], expected[covered], atol=0.6 / 255)
    return px, mask


def run(op="solid_texture"):
    return getattr(bpy.ops.exsynth, op)()


# ---- registration --------------------------------------------------------------------
def test_operators_panels_and_settings_are_registered():
    for idname, cls in (("exsynth.solid_texture", "EXSYNTH_OT_solid_texture"),
                        ("exsynth.solid_rebake", "EXSYNTH_OT_solid_rebake")):
        op = getattr(bpy.types, cls)
        assert op.bl_idname == idname and {'REGISTER', 'UNDO'} <= set(op.bl_options)
    for panel in ("EXSYNTH_PT_solid", "EXSYNTH_PT_solid_axes", "EXSYNTH_PT_solid_rebake",
                  "EXSYNTH_PT_solid_advanced"):
        assert getattr(bpy.types, panel).bl_category == "ExSynth"
    s = settings()
    assert (s.solid_size, s.solid_bake_target, s.solid_bake_resolution) == (64, 'IMAGE', 1024)
    # Levels, iterations and size start at the engine's defaults, as the CLI's do.
    engine = (_native.SOLID_DEFAULT_SIZE, _native.DEFAULT_LEVELS, _native.DEFAULT_ITERATIONS)
    assert (s.solid_size, s.solid_levels, s.solid_iterations) == engine
    from exsynth import cli
    args = cli._parser().parse_args(["solid", "--exemplar", "ex.png", "--out", "o.npy"])
    assert (args.size, args.levels, args.iterations) == engine
    rna = s.bl_rna.properties["solid_size"]
    # The engine's size rule: 1 level allows the hard min, the default levels the soft min.
    assert (rna.hard_min, rna.hard_max) == (_native.min_texture_size(1), _native.SOLID_MAX_SIZE)
    assert rna.soft_min == _native.min_texture_size(s.solid_levels) > rna.hard_min
    # One range per option: the engine's; the sliders stop earlier (soft maximum).
    for name, hard in (("solid_levels", _native.MAX_LEVELS), ("solid_iterations", _native.MAX_ITERATIONS)):
        rna = s.bl_rna.properties[name]
        assert rna.hard_max == hard and rna.soft_max <= hard
    assert s.solid_exemplar is None and s.solid_volume is None


# ---- Solid Texture, image bake ---------------------------------------------------------------
def test_bakes_a_filled_image_wired_into_a_new_material(cow, exemplar):
    old_material = bpy.data.materials.new("Old")
    cow.data.materials.append(old_material)
    assert run() == {'FINISHED'}

    image = bpy.data.images["cow_solid"]
    assert tuple(image.size) == (128, 128) and image.packed_file is not None
    assert not image.is_float and image.colorspace_settings.name == "sRGB"

    # Smart UV Project gave the cow a UV map, and the image holds the solid
    # where that map puts the cow's surface.
    assert [uv.name for uv in cow.data.uv_layers] == ["UVMap"]
    check_baked_image(image, cow, "UVMap", bpy.data.objects["crackedground_solid"])

    # A new material shows the image through the UV map; it replaced the old one.
    mat = bpy.data.materials["cow_solid"]
    assert [s.material for s in cow.material_slots] == [mat]
    assert old_material.users == 0
    nodes = mat.node_tree.nodes
    tex = next(n for n in nodes if n.bl_idname == "ShaderNodeTexImage")
    assert tex.image == image
    bsdf = nodes["Principled BSDF"]
    assert bsdf.inputs["Base Color"].links[0].from_node == tex
    uv_node = tex.inputs["Vector"].links[0].from_node
    assert uv_node.bl_idname == "ShaderNodeUVMap" and uv_node.uv_map == "UVMap"


def test_solid_volume_object(cow, exemplar):
    settings().solid_scale = 0.5
    assert run() == {'FINISHED'}
    volume_obj = bpy.data.objects["crackedground_solid"]
    assert volume_obj.type == 'VOLUME'
    assert {g.name for g in volume_obj.data.grids} == {"color", "density"}
    assert volume_obj.hide_get() and volume_obj.hide_render  # it would hide the baked mesh
    assert settings().solid_volume == volume_obj  # ready for Re-bake
    meta = volume_obj.data[solid_ops.METADATA]
    assert (meta["size"], meta["scale"], meta["encoding"]) == (16, pytest.approx(0.5), "srgb")

    path = bpy.path.abspath(volume_obj.data.filepath)
    assert os.path.dirname(path) == volume_io.cache_dir()
    data = _native.read_vdb(path)
    assert data["grids"]["color"].shape == (16, 16, 16, 3)
    h = 0.5 / 16
    assert data["voxel_size"] == pytest.approx(h)
    np.testing.assert_allclose(data["origin"], [h / 2] * 3)

    # The tile's corner sits at the lower corner of the cow's bounding box
    # (Blender < 4.5 draws .vdb voxels half a voxel off: the location undoes it).
    lo, _ = bake_io.world_bounds([cow])
    offset = volume_io.blender_cell_offset(h)
    np.testing.assert_allclose(volume_obj.location, lo - offset, atol=1e-6)

    # Its material shows the color grid (8-bit exemplar: through a gamma of
    # 2.2) as a block: the density grid is 1 over the tile.
    np.testing.assert_array_equal(data["grids"]["density"], 1.0)
    mat = volume_obj.active_material
    shader = mat.node_tree.nodes["Principled Volume"]
    assert shader.inputs["Density Attribute"].default_value == "density"
    gamma = shader.inputs["Color"].links[0].from_node
    assert gamma.bl_idname == "ShaderNodeGamma"
    attr = gamma.inputs["Color"].links[0].from_node
    assert attr.bl_idname == "ShaderNodeAttribute" and attr.attribute_name == "color"


def test_mesh_with_a_uv_map_keeps_it(exemplar):
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.7, location=(0.3, 0.2, 0.1))
    sphere = bpy.context.active_object
    sphere.data.uv_layers.new(name="Second")  # not active: the active one is used
    before = [uv.name for uv in sphere.data.uv_layers]
    assert run() == {'FINISHED'}
    assert [uv.name for uv in sphere.data.uv_layers] == before
    mat = sphere.material_slots[0].material
    uv_node = next(n for n in mat.node_tree.nodes if n.bl_idname == "ShaderNodeUVMap")
    assert uv_node.uv_map == sphere.data.uv_layers.active.name == "UVMap"
    assert image_pixels(bpy.data.images["Sphere_solid"])[..., :3].std() > 0.02


def test_alpha_and_float_exemplars(cow, exemplar):
    # A float copy of the exemplar with alpha: the bake is a float RGBA image
    # and the Volume gets an alpha grid.
    rgba = image_pixels(exemplar)
    rgba[..., 3] = np.linspace(0.2, 1.0, 128)[None, :]
    floaty = bpy.data.images.new("floaty", 128, 128, alpha=True, float_buffer=True)
    floaty.pixels.foreach_set(rgba.ravel())
    floaty.pack()
    s = settings()
    s.solid_exemplar, s.solid_use_alpha = floaty, True
    assert run() == {'FINISHED'}
    image = bpy.data.images["cow_solid"]
    assert image.is_float
    volume_obj = bpy.data.objects["floaty_solid"]
    assert {g.name for g in volume_obj.data.grids} == {"color", "alpha", "density"}
    assert volume_obj.data[solid_ops.METADATA]["encoding"] == "linear"
    values, _, _ = read_solid(volume_obj)
    assert values.shape == (16, 16, 16, 4) and 0.15 < values[..., 3].mean() < 1.0
    mat = bpy.data.materials["cow_solid"]
    assert mat.node_tree.nodes["Principled BSDF"].inputs["Alpha"].is_linked


def test_per_axis_exemplars(cow, exemplar):
    s = settings()
    s.solid_exemplar_y = bpy.data.images.load(os.path.join(TEXTURES, "drkwood2.png"))
    s.solid_exemplar_z = bpy.data.images.load(os.path.join(TEXTURES, "granite1.png"))
    assert run() == {'FINISHED'}
    assert "cow_solid" in bpy.data.images


# ---- colour attribute ------------------------------------------------------------------
def test_color_attribute_mode(cow, exemplar):
    settings().solid_bake_target = 'ATTRIBUTE'
    images_before = set(bpy.data.images.keys())
    assert run() == {'FINISHED'}
    assert set(bpy.data.images.keys()) == images_before  # no image in this mode
    assert len(cow.data.uv_layers) == 0  # and no UVs needed
    attr = cow.data.color_attributes["solid"]
    assert (attr.domain, attr.data_type) == ('CORNER', 'FLOAT_COLOR')
    assert cow.data.color_attributes.active_color.name == "solid"
    colors = corner_colors(cow)
    assert colors[:, :3].std(axis=0).min() > 0.005 and np.all(colors[:, 3] == 1)

    # The solid's (sRGB-encoded) values at the corners, made linear.
    volume_obj = bpy.data.objects["crackedground_solid"]
    values, origin, h = read_solid(volume_obj)
    expected = _native.sample_volume(values, origin, h, grid_points(volume_obj, world_corners(cow)))
    np.testing.assert_allclose(colors[:, :3], image_io.srgb_to_linear(expected), atol=1e-4)

    node = bpy.data.materials["cow_solid"].node_tree.nodes["Color Attribute"]
    assert node.layer_name == "solid"


# ---- Re-bake -------------------------------------------------------------------------
def twin_of(obj, name, location):
    """A separate mesh object whose vertices sit where `obj`'s are in world
    space, under a different object transform."""
    mesh = obj.data.copy()
    mesh.name = name
    m = np.array(obj.matrix_world)
    co = np.empty(3 * len(mesh.vertices), np.float32)
    mesh.vertices.foreach_get("co", co)
    world = co.reshape(-1, 3) @ m[:3, :3].T + m[:3, 3]
    mesh.vertices.foreach_set("co", (world - np.asarray(location)).astype(np.float32).ravel())
    twin = bpy.data.objects.new(name, mesh)
    twin.location = location
    bpy.context.collection.objects.link(twin)
    return twin


def select_only(*objects):
    for other in list(bpy.context.selected_objects):
        other.select_set(False)
    for obj in objects:
        obj.select_set(True)
    bpy.context.view_layer.objects.active = objects[0]


def test_rebake_gives_the_same_colours_at_the_same_world_positions(cow, exemplar):
    settings().solid_bake_target = 'ATTRIBUTE'
    assert run() == {'FINISHED'}
    first = corner_colors(cow)
    twin = twin_of(cow, "twin", (-2.0, 3.0, 0.5))
    bpy.context.view_layer.update()
    select_only(twin)
    assert run("solid_rebake") == {'FINISHED'}
    np.testing.assert_allclose(corner_colors(twin), first, atol=1e-5)
    assert len(bpy.data.volumes) == 1  # no new solid

    # The solid lives in its Volume object's space and tiles: moved by one
    # tile it gives the same colours, by half a tile different ones.
    volume_obj = settings().solid_volume
    scale = volume_obj.data[solid_ops.METADATA]["scale"]
    volume_obj.location.x += scale
    assert run("solid_rebake") == {'FINISHED'}
    np.testing.assert_allclose(corner_colors(twin), first, atol=1e-4)
    volume_obj.location.x += 0.5 * scale
    assert run("solid_rebake") == {'FINISHED'}
    assert np.abs(corner_colors(twin) - first).mean() > 0.01


def test_rebake_image_onto_a_cut_mesh(cow, exemplar):
    # The cow cut with a Boolean (applied) gets the solid's colours on its
    # new faces too. The cut faces took the cube's UVs: New UV Map unwraps
    # the mesh again, into 'SolidUV' beside the maps it has.
    assert run() == {'FINISHED'}
    bpy.ops.mesh.primitive_cube_add(size=0.5, location=tuple(cow.matrix_world.translation))
    cutter = bpy.context.active_object
    cut = twin_of(cow, "cut", (0.0, 0.0, 0.0))
    mod = cut.modifiers.new("cut", 'BOOLEAN')
    mod.object, mod.operation = cutter, 'DIFFERENCE'
    with bpy.context.temp_override(object=cut, active_object=cut):
        bpy.ops.object.modifier_apply(modifier=mod.name)
    bpy.data.objects.remove(cutter)
    assert len(cut.data.polygons) != len(cow.data.polygons)
    select_only(cut)
    settings().solid_new_uvs = True
    assert run("solid_rebake") == {'FINISHED'}
    assert [uv.name for uv in cut.data.uv_layers] == ["UVMap", "SolidUV"]
    assert cut.data.uv_layers.active.name == "UVMap"  # the active map is left as it was
    check_baked_image(bpy.data.images["cut_solid"], cut, "SolidUV", settings().solid_volume)
    mat = cut.material_slots[0].material
    assert next(n for n in mat.node_tree.nodes if n.bl_idname == "ShaderNodeUVMap").uv_map == "SolidUV"

    # Again: the same map gets new UVs (no 'SolidUV.001').
    assert run("solid_rebake") == {'FINISHED'}
    assert [uv.name for uv in cut.data.uv_layers] == ["UVMap", "SolidUV"]


def test_rebake_from_a_color_volume_made_elsewhere(cow, tmp_path):
    # No Solid Texture metadata: the file's box is the tile, its colours linear.
    values = np.random.default_rng(1).random((6, 5, 4, 3)).astype(np.float32) + 0.1
    path = str(tmp_path / "foreign.vdb")
    _native.write_vdb(path, {"color": values}, (0.05, 0.05, 0.05), 0.1)
    volume_obj = volume_io.new_volume_object("foreign", path, 0.1, bpy.context.collection, jobs.Created())
    s = settings()
    s.solid_volume, s.solid_bake_target = volume_obj, 'ATTRIBUTE'
    bpy.context.view_layer.update()
    select_only(cow)
    assert run("solid_rebake") == {'FINISHED'}
    expected = _native.sample_volume(values, (0.05, 0.05, 0.05), 0.1, world_corners(cow))
    np.testing.assert_allclose(corner_colors(cow)[:, :3], expected, atol=1e-5)


@pytest.mark.parametrize("interpolation", _native.INTERPOLATION_CHOICES)
def test_rebake_reads_the_solid_with_the_chosen_interpolation(cow, tmp_path, interpolation):
    values = np.random.default_rng(2).random((6, 5, 4, 3)).astype(np.float32) + 0.1
    path = str(tmp_path / "noise.vdb")
    _native.write_vdb(path, {"color": values}, (0.05, 0.05, 0.05), 0.1)
    volume_obj = volume_io.new_volume_object("noise", path, 0.1, bpy.context.collection, jobs.Created())
    s = settings()
    assert s.solid_bake_interpolation == _native.DEFAULT_INTERPOLATION.upper()
    s.solid_volume, s.solid_bake_target = volume_obj, 'ATTRIBUTE'
    s.solid_bake_interpolation = interpolation.upper()
    bpy.context.view_layer.update()
    select_only(cow)
    assert run("solid_rebake") == {'FINISHED'}
    corners = world_corners(cow)
    got = corner_colors(cow)[:, :3]
    np.testing.assert_allclose(got, _native.sample_volume(values, (0.05, 0.05, 0.05), 0.1, corners,
                                                          interpolation=interpolation), atol=1e-5)
    other = next(c for c in _native.INTERPOLATION_CHOICES if c != interpolation)
    assert np.abs(got - _native.sample_volume(values, (0.05, 0.05, 0.05), 0.1, corners,
                                              interpolation=other)).max() > 0.01


# ---- exemplar reading ------------------------------------------------------------------
def test_exemplar_rows_are_flipped_to_top_first():
    image = bpy.data.images.new("halves", 6, 4, alpha=True)
    px = np.zeros((4, 6, 4), np.float32)
    px[:2] = (0, 0, 1, 1)  # Blender's rows 0-1: the bottom, blue
    px[2:] = (1, 0, 0, 0.5)  # the top, red, half transparent
    image.pixels.foreach_set(px.ravel())
    rgb = image_io.exemplar_pixels(image)
    assert rgb.shape == (4, 6, 3) and rgb.dtype == np.float32 and rgb.flags.c_contiguous
    np.testing.assert_allclose(rgb[0, 0], (1, 0, 0))
    np.testing.assert_allclose(rgb[-1, 0], (0, 0, 1))
    rgba = image_io.exemplar_pixels(image, use_alpha=True)
    assert rgba.shape == (4, 6, 4) and rgba[0, 0, 3] == pytest.approx(0.5, abs=0.01)
    assert image_io.encoding_of(image) == "srgb"


def test_packed_exemplar_reads_like_the_file():
    on_disk = bpy.data.images.load(os.path.join(TEXTURES, "drkwood2.png"))
    packed = bpy.data.images.load(os.path.join(TEXTURES, "drkwood2.png"), check_existing=False)
    packed.pack()
    np.testing.assert_array_equal(image_io.exemplar_pixels(packed), image_io.exemplar_pixels(on_disk))


# ---- errors: message names the problem, scene unchanged ------------------------------------
def run_expecting_error(match, op="solid_texture", objects=()):
    before = scene_state()
    meshes = [mesh_state(o) for o in objects]
    with pytest.raises(RuntimeError, match=match):
        run(op)
    assert scene_state() == before
    assert [mesh_state(o) for o in objects] == meshes


def test_no_exemplar(cow):
    run_expecting_error(r"no exemplar image chosen\. Pick or open one", objects=[cow])


def test_exemplar_smaller_than_the_neighbourhood(cow, exemplar):
    tiny = bpy.data.images.new("tiny", 4, 4)
    tiny.pixels.foreach_set(np.random.default_rng(0).random(64).astype(np.float32))
    settings().solid_exemplar = tiny
    # The mesh has no UV map: Smart UV Project ran on a copy; the cow stays without.
    run_expecting_error(r"exemplar for view x \(4x4 pixels\).*smaller than the 8x8 neighbourhood", objects=[cow])


def test_exemplar_without_pixels(cow, exemplar):
    ghost = bpy.data.images.new("ghost", 8, 8)
    ghost.source = 'FILE'
    ghost.filepath = "/nonexistent/ghost.png"
    settings().solid_exemplar = ghost
    run_expecting_error(r"exemplar image 'ghost' has no pixels \(file '/nonexistent/ghost\.png'\)",
                        objects=[cow])


def test_no_mesh_selected(cow, exemplar):
    cow.select_set(False)
    run_expecting_error(r"no mesh selected to bake onto\. Select one or more mesh objects")


def test_only_a_camera_selected(exemplar):
    cam = add_camera()
    cam.select_set(True)
    run_expecting_error(r"no mesh selected to bake onto \(selected: 'Cam' \(camera\)\)")


def test_mesh_without_faces(exemplar):
    mesh = bpy.data.meshes.new("Dots")
    mesh.vertices.add(3)
    mesh.vertices.foreach_set("co", np.eye(3, dtype=np.float32).ravel())
    obj = bpy.data.objects.new("Dots", mesh)
    bpy.context.collection.objects.link(obj)
    obj.select_set(True)
    run_expecting_error(r"the mesh 'Dots' has no faces")


def test_size_too_small_for_the_levels(cow, exemplar):
    settings().solid_levels = 3  # 16 voxels at the coarsest of 3 levels: 4
    started = []
    jobs.job_started_hooks.append(started.append)
    run_expecting_error(r"Size 16 is too small for 3 Levels.*at least 29\. Raise Size or use fewer Levels "
                        r"\(1 level allows Size 8\)", objects=[cow])
    assert started == []  # refused before the engine starts


def test_smallest_size_one_level_allows(cow, exemplar):
    s = settings()
    s.solid_levels, s.solid_size = 1, _native.min_texture_size(1)
    assert s.solid_size == 8  # the property's min lets it through
    assert run() == {'FINISHED'}


def test_over_the_memory_budget(cow, exemplar):
    s = settings()
    s.solid_size = 256
    s.memory_budget_gib = 0.001
    run_expecting_error(r"memory budget", objects=[cow])


def test_edit_mode(cow, exemplar):
    bpy.ops.object.mode_set(mode='EDIT')
    try:
        run_expecting_error(r"Object Mode only")
    finally:
        bpy.ops.object.mode_set(mode='OBJECT')


def test_rebake_without_a_solid(cow):
    run_expecting_error(r"no solid chosen\. Pick the solid's Volume object", op="solid_rebake",
                        objects=[cow])


def test_rebake_from_a_volume_that_is_not_a_solid(cow):
    settings().resolution = 16
    assert bpy.ops.exsynth.voxelize() == {'FINISHED'}
    settings().solid_volume = bpy.data.objects["cow_voxels"]
    select_only(cow)
    run_expecting_error(r"'cow_voxels' has no 'color' grid, so it is not a solid", op="solid_rebake",
                        objects=[cow])


def test_existing_attribute_of_another_kind(cow, exemplar):
    cow.data.attributes.new("solid", 'FLOAT', 'POINT')
    settings().solid_bake_target = 'ATTRIBUTE'
    run_expecting_error(r"already has an attribute 'solid' of another kind", objects=[cow])


# ---- cancel and rollback ------------------------------------------------------------
def test_cancel_before_the_engine_starts(cow, exemplar):
    cow.data.materials.append(bpy.data.materials.new("Old"))
    jobs.job_started_hooks.append(lambda ctx: ctx.cancel())
    before, mesh_before = scene_state(), mesh_state(cow)
    assert run() == {'CANCELLED'}
    assert scene_state() == before
    assert mesh_state(cow) == mesh_before  # no UV map, the old material


def test_cancel_while_the_engine_runs(cow, exemplar):
    seen = {}
    jobs.job_started_hooks.append(cancel_once_running(seen))
    s = settings()
    s.solid_size, s.solid_levels = 96, 3  # seconds of work
    before, mesh_before = scene_state(), mesh_state(cow)
    t0 = time.perf_counter()
    assert run() == {'CANCELLED'}
    assert 0.0 < seen["progress"] < 1.0
    assert time.perf_counter() - t0 < 15
    assert scene_state() == before and mesh_state(cow) == mesh_before


@pytest.mark.parametrize("error", [OSError("disk full (test)"), KeyError("bug (test)")])
def test_failure_after_the_mesh_was_changed_is_rolled_back(cow, exemplar, monkeypatch, error):
    # Fail at the very end: the .vdb, Volume, image, material, the cow's new
    # UV map and its replaced material slot all exist by then.
    def fail(*args):
        raise error

    monkeypatch.setattr(solid_ops, "set_solid_volume", fail)
    cow.data.materials.append(bpy.data.materials.new("Old"))
    before, mesh_before = scene_state(), mesh_state(cow)
    with pytest.raises(RuntimeError, match="test"):
        run()
    assert scene_state() == before
    assert mesh_state(cow) == mesh_before


def test_failed_attribute_bake_restores_the_old_attribute(cow, exemplar, monkeypatch):
    settings().solid_bake_target = 'ATTRIBUTE'
    assert run() == {'FINISHED'}
    old = corner_colors(cow)
    settings().seed = 7
    monkeypatch.setattr(solid_ops, "set_solid_volume", lambda *a: (_ for _ in ()).throw(OSError("x (test)")))
    with pytest.raises(RuntimeError, match="test"):
        run()
    np.testing.assert_array_equal(corner_colors(cow), old)
    assert cow.material_slots[0].material.name == "cow_solid"


def test_failed_rebake_restores_the_uvs_it_replaced(cow, exemplar, monkeypatch):
    assert run() == {'FINISHED'}  # the cow gets 'UVMap'
    settings().solid_new_uvs = True
    assert run() == {'FINISHED'}  # and 'SolidUV'
    solid_uv = cow.data.uv_layers["SolidUV"].data
    marked = np.full(2 * len(solid_uv), 0.25, np.float32)
    solid_uv.foreach_set("uv", marked)
    monkeypatch.setattr(solid_ops, "set_solid_volume", lambda *a: (_ for _ in ()).throw(OSError("x (test)")))
    before, mesh_before = scene_state(), mesh_state(cow)
    with pytest.raises(RuntimeError, match="test"):
        run()
    assert scene_state() == before and mesh_state(cow) == mesh_before
    uv = np.empty_like(marked)
    cow.data.uv_layers["SolidUV"].data.foreach_get("uv", uv)
    np.testing.assert_array_equal(uv, marked)


# ---- CLI: `./exsynth run solid|image` (in-process) --------------------------------------
CRACKED = os.path.join(TEXTURES, "crackedground.png")
FAST = ["--size", "16", "--levels", "2", "--iterations", "2"]


@pytest.mark.parametrize("ext", [".npy", ".vdb"])
def test_cli_solid_writes_the_solid(tmp_path, capsys, ext):
    from exsynth import cli

    out = tmp_path / f"solid{ext}"
    assert cli.main(["solid", "--exemplar", CRACKED, *FAST, "--out", str(out)]) == 0
    if ext == ".npy":
        solid = np.load(out)
        assert solid.shape == (16, 16, 16, 3) and solid.dtype == np.float32
    else:
        data = _native.read_vdb(str(out))
        solid = data["grids"]["color"]
        assert set(data["grids"]) == {"color"} and solid.shape == (16, 16, 16, 3)
        assert data["voxel_size"] == pytest.approx(1 / 16)  # no mesh: one tile is 1 unit
        np.testing.assert_allclose(data["origin"], [1 / 32] * 3)
    assert 0.0 <= solid.min() and solid.max() <= 1.0 and solid.std() > 0.02
    assert "solid: 16x16x16 voxels x 3 channels" in capsys.readouterr().out


def test_cli_solid_bakes_onto_a_mesh(tmp_path, capsys):
    from exsynth import cli
    from helpers import COW_OBJ

    out, png, obj = tmp_path / "s.npy", tmp_path / "bake" / "cow.png", tmp_path / "cow_uv.obj"
    assert cli.main(["solid", "--exemplar", CRACKED, *FAST, "--out", str(out), "--mesh", COW_OBJ,
                     "--bake-out", str(png), "--bake-size", "128", "--mesh-out", str(obj)]) == 0
    image = bpy.data.images.load(str(png))
    assert tuple(image.size) == (128, 128)
    px = image_pixels(image)[..., :3]
    filled = px.sum(axis=2) > 0
    # At 128² the cow's many small UV islands each get a texel and a 4-texel
    # margin, so most of the image fills; the background must still show.
    assert 0.15 < filled.mean() < 0.99 and px[filled].std(axis=0).min() > 0.02
    lines = obj.read_text().splitlines()
    assert sum(l.startswith("vt ") for l in lines) > 100  # the UVs the bake used
    assert "% covered" in capsys.readouterr().out
    # The same solid (same seed) read trilinearly: the same texels covered, other values.
    soft = tmp_path / "bake" / "cow_linear.png"
    assert cli.main(["solid", "--exemplar", CRACKED, *FAST, "--out", str(tmp_path / "s2.npy"), "--mesh", COW_OBJ,
                     "--bake-out", str(soft), "--bake-size", "128", "--bake-interpolation", "linear"]) == 0
    px_soft = image_pixels(bpy.data.images.load(str(soft)))[..., :3]
    np.testing.assert_array_equal(px_soft.sum(axis=2) > 0, filled)
    assert np.abs(px_soft - px).max() > 0.02


def test_cli_image_writes_a_png_of_the_requested_size(tmp_path, capsys):
    from exsynth import cli

    for args, name in (([], "a.png"), (["--tileable", "--seed", "3"], "b.png"),
                       (["--method", "optimization", "--levels", "2", "--iterations", "2"], "c.png"),
                       (["--width", "7", "--height", "5"], "d.png")):
        out = tmp_path / name
        assert cli.main(["image", "--exemplar", CRACKED, "--width", "40", "--height", "24",
                         *args, "--out", str(out)]) == 0
        image = bpy.data.images.load(str(out))
        assert tuple(image.size) == ((7, 5) if name == "d.png" else (40, 24))
        assert image_pixels(image)[..., :3].std() > 0.02
    out = capsys.readouterr().out
    assert "image (coordinates): 40x24, tileable" in out and "image (optimization): 40x24 from" in out
    assert "image (coordinates): 7x5 from" in out  # below the optimiser's size rule


def test_cli_bad_arguments(tmp_path, monkeypatch, capsys):
    from exsynth import cli
    from helpers import COW_OBJ

    monkeypatch.chdir(tmp_path)
    tiny = tmp_path / "tiny.png"
    image_io.save_png(str(tiny), np.random.default_rng(0).random((4, 4, 3)).astype(np.float32), "srgb")
    cases = [
        (["--exemplar", "/nonexistent/x.png", "--out", "s.npy"], 2, "--exemplar: no such file"),
        (["--exemplar", CRACKED, "--out", "s.txt"], 2, "--out: unsupported file type '.txt'"),
        (["--exemplar", CRACKED, "--out", "s.npy", "--mesh", COW_OBJ], 2,
         "--mesh and --bake-out go together"),
        (["--exemplar", CRACKED, "--out", "s.npy", "--size", "0"], 2, "--size must be > 0"),
        (["--exemplar", CRACKED, "--out", "s.npy", "--bake-interpolation", "nearest"], 2,
         "--bake-interpolation: invalid choice: 'nearest'"),
        (["--exemplar", str(tiny), *FAST, "--method", "optimization", "--out", "s.npy"], 2,
         "smaller than the 8x8 neighbourhood"),
        (["--exemplar", str(tiny), *FAST, "--method", "coordinates", "--out", "s.npy"], 2,
         "too small for method 'coordinates'"),
    ]
    for args, code, message in cases:
        assert cli.main(["solid", *args]) == code, args
        assert message in capsys.readouterr().err
    assert cli.main(["image", "--exemplar", CRACKED, "--width", "0", "--height", "8", "--out", "x.png"]) == 2
    assert "--width and --height must be > 0" in capsys.readouterr().err
    assert not any(tmp_path.glob("s.*")) and not (tmp_path / "x.png").exists()


# ---- method (the core's names) ---------------------------------------------------------------
def test_method_setting_lists_the_cores_methods_and_default():
    rna = settings().bl_rna.properties["solid_method"]
    assert [item.identifier.lower() for item in rna.enum_items] == list(_native.SOLID_METHODS)
    assert settings().solid_method.lower() == _native.SOLID_DEFAULT_METHOD


def test_coordinates_method_makes_a_solid_of_exemplar_texels(cow, exemplar):
    settings().solid_method = 'COORDINATES'
    assert run() == {'FINISHED'}
    volume_obj = bpy.data.objects["crackedground_solid"]
    values, _, _ = read_solid(volume_obj)
    assert values.shape[:3] == (16, 16, 16)
    assert values[..., :3].std(axis=(0, 1, 2)).min() > 0.02  # not a flat solid
    image = bpy.data.images["cow_solid"]
    assert image.packed_file is not None


def test_coordinates_method_refuses_an_exemplar_too_small_for_its_levels(cow, exemplar):
    settings().solid_method = 'COORDINATES'
    settings().solid_levels = 3
    settings().solid_size = 32
    exemplar.scale(16, 16)
    run_expecting_error("too small for method 'coordinates'", objects=[cow])


# ---- histogram values (the optimiser's histogram-matched exemplar values) ----------------------
def made_as_the_engine_makes(exemplar, option, value, other):
    """Runs the operator (its setting already set to `value`): the solid is the
    engine's with option=value, and the value matters (not the one with `other`)."""
    assert run() == {'FINISHED'}
    made, _, _ = read_solid(bpy.data.objects["crackedground_solid"])
    ex = solid_ops.read_exemplars(exemplar)[0]
    direct = lambda v: _native.synthesize_solid(ex, size=16, levels=2, iterations=2, seed=settings().seed,
                                                method="optimization", **{option: v})["solid"]
    np.testing.assert_allclose(made, direct(value), atol=1e-6)
    assert not np.array_equal(made, direct(other))


def test_histogram_values_default_to_the_engines_and_reach_it(cow, exemplar):
    assert settings().solid_histogram_values == pytest.approx(_native.SOLID_DEFAULT_HISTOGRAM_VALUES)
    assert _native.SOLID_DEFAULT_HISTOGRAM_VALUES > 0
    settings().solid_histogram_values = 0.1
    made_as_the_engine_makes(exemplar, "histogram_values", 0.1, 0.0)


def test_structure_sigma_defaults_to_the_engines_and_reaches_it(cow, exemplar):
    assert settings().solid_structure_sigma == pytest.approx(_native.SOLID_DEFAULT_STRUCTURE_SIGMA)
    default = _native.SOLID_DEFAULT_STRUCTURE_SIGMA
    value = 0.0 if default else 1.5  # the setting away from the default reaches the engine
    settings().solid_structure_sigma = value
    made_as_the_engine_makes(exemplar, "structure_sigma", value, default or 0.0)


# ---- feature weight (the optimiser's feature-distance channel) --------------------------------
def test_feature_weight_defaults_to_the_engines_and_reaches_it(cow, exemplar):
    assert settings().solid_feature_weight == pytest.approx(_native.SOLID_DEFAULT_FEATURE_WEIGHT)
    assert _native.SOLID_DEFAULT_FEATURE_WEIGHT > 0
    assert run() == {'FINISHED'}
    featured, _, _ = read_solid(bpy.data.objects["crackedground_solid"])
    settings().solid_feature_weight = 0.0
    assert run() == {'FINISHED'}
    plain, _, _ = read_solid(bpy.data.objects["crackedground_solid.001"])
    assert featured.shape == plain.shape and not np.array_equal(featured, plain)
    # What the engine makes from the same exemplar with the weight off.
    ex = solid_ops.read_exemplars(exemplar)[0]
    direct = _native.synthesize_solid(ex, size=16, levels=2, iterations=2, seed=settings().seed,
                                      method="optimization", feature_weight=0.0)["solid"]
    np.testing.assert_allclose(plain, direct, atol=1e-6)


def test_feature_threshold_defaults_to_the_engines_and_reaches_it(cow, exemplar):
    assert settings().solid_feature_threshold == pytest.approx(_native.SOLID_DEFAULT_FEATURE_THRESHOLD)
    rna = settings().bl_rna.properties["solid_feature_threshold"]
    assert (rna.hard_min, rna.hard_max) == (0.0, pytest.approx(_native.SOLID_MAX_FEATURE_THRESHOLD))
    settings().solid_feature_threshold = 0.0
    made_as_the_engine_makes(exemplar, "feature_threshold", 0.0, 1.0)


def test_feature_scale_defaults_to_the_engines_and_reaches_it(cow, exemplar):
    assert settings().solid_feature_scale == _native.SOLID_DEFAULT_FEATURE_SCALE == 0
    rna = settings().bl_rna.properties["solid_feature_scale"]
    assert (rna.hard_min, rna.hard_max) == (0, _native.SOLID_MAX_FEATURE_SCALE)
    settings().solid_feature_scale = 16
    made_as_the_engine_makes(exemplar, "feature_scale", 16, 0)


def test_rotate_exemplar_defaults_to_the_engines_and_reaches_it(cow, exemplar):
    assert settings().solid_rotate_exemplar == _native.SOLID_DEFAULT_ROTATE_EXEMPLAR.upper() == "AUTO"
    items = settings().bl_rna.properties["solid_rotate_exemplar"].enum_items
    assert tuple(i.identifier.lower() for i in items) == _native.ROTATE_EXEMPLAR_CHOICES
    # crackedground's features are round: auto turns it, as on does; off differs.
    made_as_the_engine_makes(exemplar, "rotate_exemplar", "on", "off")
    assert bpy.data.objects["crackedground_solid"].data[solid_ops.METADATA]["turned"].to_list() == [1, 1, 1]


def test_rotate_exemplar_off_reaches_the_engine(cow, exemplar):
    settings().solid_rotate_exemplar = 'OFF'
    made_as_the_engine_makes(exemplar, "rotate_exemplar", "off", "on")
    assert bpy.data.objects["crackedground_solid"].data[solid_ops.METADATA]["turned"].to_list() == [0, 0, 0]
