# SPDX-License-Identifier: GPL-3.0-or-later
"""exsynth.point_texture (and `./exsynth run points`): geometry textures grown
over a plane and over a mesh, as point clouds and surfaces; bad input, cancel."""

import threading
import time

import bpy
import numpy as np
import pytest

from exsynth import cli, jobs
from exsynth.io import point_cloud, point_files
from helpers import BUNNY_OBJ, add_faceless_mesh, scene_state

SMALL = dict(pts_density=2500.0, pts_width=1.0, pts_depth=1.0, pts_patch_size=0.45)


def grow(**settings):
    s = bpy.context.scene.exsynth
    for key, value in {**SMALL, **settings}.items():
        setattr(s, key, value)
    return bpy.ops.exsynth.point_texture()


def test_builtin_over_a_plane_makes_a_point_cloud_with_discs():
    bpy.context.scene.cursor.location = (2.0, 1.0, 0.0)
    assert grow(pts_preset='WEAVE') == {'FINISHED'}
    obj = bpy.data.objects["weave_points"]
    assert bpy.context.view_layer.objects.active == obj
    assert tuple(obj.location) == (2.0, 1.0, 0.0)
    mesh = obj.data
    assert len(mesh.vertices) > 1000 and len(mesh.polygons) == 0
    pos, nrm = point_cloud.read_point_cloud(obj)
    np.testing.assert_allclose(np.linalg.norm(nrm, axis=1), 1.0, atol=1e-3)
    local = pos - np.array([2.0, 1.0, 0.0])
    assert local[:, :2].min() >= -1e-3 and local[:, :2].max() <= 1.0 + 1e-3
    mod = obj.modifiers["ExSynth Discs"]
    assert mod.type == 'NODES' and mod.node_group.name == point_cloud.NODE_GROUP
    # The modifier turns the points into instances (discs) for the renderer.
    deps = bpy.context.evaluated_depsgraph_get()
    instances = [i for i in deps.object_instances if i.is_instance and i.parent and i.parent.original == obj]
    assert len(instances) == len(mesh.vertices)


def test_make_surface_adds_a_mesh_with_a_material():
    assert grow(pts_preset='BUMPS', pts_make_mesh=True) == {'FINISHED'}
    surf = bpy.data.objects["bumps_surface"]
    assert len(surf.data.polygons) > 500 and surf.data.materials[0] is not None
    assert sorted(o.name for o in bpy.context.selected_objects) == ["bumps_points", "bumps_surface"]


def test_selected_faces_of_an_object_as_exemplar():
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=20, y_subdivisions=20, size=2.0)
    grid = bpy.context.active_object
    co = np.empty(3 * len(grid.data.vertices), np.float32)
    grid.data.vertices.foreach_get("co", co)
    co = co.reshape(-1, 3)
    co[:, 2] = 0.1 * np.sin(6 * co[:, 0]) * np.cos(6 * co[:, 1])
    grid.data.vertices.foreach_set("co", co.ravel())
    grid.data.update()
    sel = np.ones(len(grid.data.polygons), bool)
    sel[: len(sel) // 4] = False
    grid.data.polygons.foreach_set("select", sel)
    assert grow(pts_exemplar_source='SELECTED', pts_object=grid, pts_density=1500.0, pts_width=2.0,
                pts_depth=2.0, pts_patch_size=0.5) == {'FINISHED'}
    pos, _ = point_cloud.read_point_cloud(bpy.data.objects["Grid_points"])
    assert len(pos) > 2000 and np.abs(pos[:, 2]).max() < 0.15


def test_over_a_mesh_follows_its_surface():
    bpy.ops.mesh.primitive_uv_sphere_add(radius=1.0, segments=48, ring_count=24)
    sphere = bpy.context.active_object
    before = scene_state()
    assert grow(pts_preset='BUMPS', pts_output='TARGET', pts_target=sphere, pts_scale=0.5, pts_density=1200.0,
                pts_patch_size=0.5) == {'FINISHED'}
    pos, nrm = point_cloud.read_point_cloud(bpy.data.objects["Sphere_bumps_points"])
    r = np.linalg.norm(pos, axis=1)
    assert len(pos) > 3000 and np.all(np.abs(r - 1.0) < 0.12)
    assert np.mean(np.einsum("ij,ij->i", nrm, pos / r[:, None]) > 0.5) > 0.9
    assert sorted(o.name for o in bpy.data.objects) == sorted(before["objects"] + ["Sphere_bumps_points"])


def test_point_file_exemplar(tmp_path):
    from exsynth import _native
    ex = _native.make_point_exemplar("bumps", density=2500)
    path = str(tmp_path / "bumps.ply")
    point_files.write_points(path, ex["positions"], ex["normals"])
    pos, nrm = point_files.read_points(path)
    np.testing.assert_allclose(pos, ex["positions"], atol=1e-6)
    assert grow(pts_exemplar_source='FILE', pts_file=path, pts_patch_size=0.4) == {'FINISHED'}
    assert len(bpy.data.objects["bumps_points"].data.vertices) > 1000


# ---- bad input and cancel: the scene stays as it was ---------------------------
def test_file_without_normals(tmp_path):
    path = tmp_path / "plain.xyz"
    np.savetxt(path, np.random.default_rng(0).uniform(size=(50, 3)))
    before = scene_state()
    with pytest.raises(RuntimeError, match="no normals"):
        grow(pts_exemplar_source='FILE', pts_file=str(path))
    assert scene_state() == before


def test_patch_larger_than_the_exemplar():
    before = scene_state()
    with pytest.raises(RuntimeError, match="lower the patch size"):
        grow(pts_patch_size=3.0)
    assert scene_state() == before


def test_target_without_faces_and_missing_target():
    with pytest.raises(RuntimeError, match="pick a target mesh"):
        grow(pts_output='TARGET', pts_target=None)
    obj = add_faceless_mesh()
    with pytest.raises(RuntimeError, match="has no faces"):
        grow(pts_output='TARGET', pts_target=obj)


def test_over_the_memory_budget():
    bpy.context.scene.exsynth.memory_budget_gib = 0.001
    before = scene_state()
    with pytest.raises(RuntimeError, match="memory budget"):
        grow(pts_width=40.0, pts_depth=40.0)
    assert scene_state() == before


def test_cancel_while_patches_are_placed():
    def hook(ctx):
        def watch():
            deadline = time.monotonic() + 30
            while not (ctx.stage.startswith("placing") and ctx.progress > 0.1) and time.monotonic() < deadline:
                time.sleep(0.001)
            ctx.cancel()
        threading.Thread(target=watch, daemon=True).start()

    jobs.job_started_hooks.append(hook)
    before = scene_state()
    assert grow(pts_width=3.0, pts_depth=3.0) == {'CANCELLED'}
    assert scene_state() == before


# ---- CLI ---------------------------------------------------------------------------
def test_cli_preset_plane_ply_and_mesh(tmp_path, capsys):
    out, surf = tmp_path / "cm.ply", tmp_path / "cm.obj"
    rc = cli.main(["points", "--preset", "chainmail", "--size", "1", "1", "--density", "2500",
                   "--out", str(out), "--mesh-out", str(surf), "--seed", "3"])
    assert rc == 0
    assert "points: chainmail (chainmail weights) ->" in capsys.readouterr().out
    pos, nrm = point_files.read_points(str(out))
    assert len(pos) > 1000 and pos[:, :2].min() >= -1e-3 and pos[:, :2].max() <= 1 + 1e-3
    assert surf.stat().st_size > 1000


def test_cli_height_field_png_and_target(tmp_path, capsys):
    img = bpy.data.images.new("hf", 48, 48)
    y, x = np.mgrid[0:48, 0:48]
    grey = (0.5 + 0.5 * np.sin(x / 3.0) * np.cos(y / 4.0)).astype(np.float32)
    img.pixels.foreach_set(np.repeat(grey.ravel(), 4).astype(np.float32))
    png = str(tmp_path / "hf.png")
    img.filepath_raw = png
    img.file_format = 'PNG'
    img.save()
    out = tmp_path / "hf.obj"
    assert cli.main(["points", "--exemplar", png, "--size", "30", "30", "--height-scale", "3", "--density",
                     "30000", "--out", str(out)]) == 0
    text = out.read_text()
    assert text.count("\nv ") > 1000 and text.count("\nvn ") == text.count("\nv ")
    assert "(heightfield weights)" in capsys.readouterr().out  # Table 1's height-field row
    out2 = tmp_path / "bunny.ply"
    assert cli.main(["points", "--preset", "bumps", "--target", BUNNY_OBJ, "--density", "150", "--scale", "1.5",
                     "--patch-size", "0.6", "--axis", "0", "1", "0", "--out", str(out2)]) == 0
    pos, _ = point_files.read_points(str(out2))
    assert len(pos) > 1000


def test_cli_bad_arguments(tmp_path, capsys):
    assert cli.main(["points", "--preset", "bumps", "--size", "1", "1", "--out", str(tmp_path / "x.txt")]) == 2
    assert cli.main(["points", "--preset", "bumps", "--size", "1", "1", "--patch-size", "5",
                     "--out", str(tmp_path / "x.ply")]) == 2  # the engine's check: a bad argument too
    assert "lower the patch size" in capsys.readouterr().err
    assert not (tmp_path / "x.ply").exists()


def test_cli_target_field_presets_curve_and_own_field(tmp_path, capsys):
    # The presets of 'run analogy' (around_axis, along_axis, along_curve with
    # --curve) and a per-vertex --field. The wrong-shape error names the
    # target's vertex count, which the right-shape run then uses.
    base = ["points", "--preset", "bumps", "--target", BUNNY_OBJ, "--density", "150", "--scale", "1.5",
            "--patch-size", "0.6"]
    curve = tmp_path / "curve.npy"
    np.save(curve, np.array([[0.0, -1.0, 0.0], [0.0, 0.0, 0.5], [0.0, 1.0, 0.0]]))
    out = tmp_path / "curve.ply"
    assert cli.main(base + ["--field-preset", "along_curve", "--curve", str(curve), "--out", str(out)]) == 0
    pos, nrm = point_files.read_points(str(out))
    assert len(pos) > 1000 and np.allclose(np.linalg.norm(nrm, axis=1), 1.0, atol=1e-3)
    bad = tmp_path / "bad.npy"
    np.save(bad, np.ones((3, 3)))
    capsys.readouterr()
    assert cli.main(base + ["--field", str(bad), "--out", str(tmp_path / "bad.ply")]) == 2
    err = capsys.readouterr().err
    assert "--target has" in err and "one direction per vertex" in err, err
    assert not (tmp_path / "bad.ply").exists()
    count = int(err.split("--target has ")[1].split()[0])
    field = tmp_path / "field.npy"
    np.save(field, np.tile([1.0, 0.0, 0.0], (count, 1)))
    out2 = tmp_path / "field.ply"
    assert cli.main(base + ["--field", str(field), "--out", str(out2)]) == 0
    assert len(point_files.read_points(str(out2))[0]) > 1000


def test_cli_field_arguments_that_do_not_fit(tmp_path, capsys):
    base = ["points", "--preset", "bumps", "--density", "150", "--out", str(tmp_path / "x.ply")]
    curve = tmp_path / "curve.npy"
    np.save(curve, np.zeros((2, 3)))
    nan = tmp_path / "nan.npy"
    np.save(nan, np.full((4, 3), np.nan))
    cases = [
        (["--target", BUNNY_OBJ, "--field-preset", "along_curve"], "needs --curve"),
        (["--target", BUNNY_OBJ, "--curve", str(curve)], "--curve goes with --field-preset along_curve"),
        (["--size", "1", "1", "--curve", str(curve), "--field-preset", "along_curve"], "with --target"),
        (["--size", "1", "1", "--field", str(nan)], "with --target"),
        (["--target", BUNNY_OBJ, "--field-preset", "along_curve", "--curve", str(tmp_path / "none.npy")], "--curve"),
        (["--target", BUNNY_OBJ, "--field-preset", "sideways"], "invalid choice"),
    ]
    for extra, message in cases:
        capsys.readouterr()
        assert cli.main(base + extra) == 2, extra
        assert message in capsys.readouterr().err, (extra, message)
    assert not (tmp_path / "x.ply").exists()


def test_the_panels_weights_are_the_presets_and_custom_weights_start_from_the_default():
    from exsynth import _native
    from exsynth.operators.points import options_from

    s = bpy.context.scene.exsynth
    keys = ("w_p", "w_n", "w_v", "w_l", "w_d")
    default = _native.point_texture_preset("default")
    assert {k: s.bl_rna.properties[f"pts_{k}"].default for k in keys} == {k: default[k] for k in keys}
    s.pts_custom_weights = False
    for built_in, preset in (("bumps", "heightfield"), ("chainmail", "chainmail"), ("weave", "weave"),
                             ("flowers", "flowers")):
        opts, ref = options_from(s, built_in), _native.point_texture_preset(preset)
        assert {k: opts[k] for k in keys} == {k: ref[k] for k in keys}, built_in
    try:
        s.pts_custom_weights, s.pts_w_v = True, 7.0
        assert options_from(s, "bumps")["w_v"] == 7.0
    finally:
        s.pts_custom_weights = False
        s.property_unset("pts_w_v")
