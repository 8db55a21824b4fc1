# SPDX-License-Identifier: GPL-3.0-or-later
"""Bad or unusual input files and options for `./exsynth run`: the message
names the option the user passed and the fix, nothing is written, and odd
but valid inputs (a millionth-sized model, loose vertices) work."""

import os

import bpy
import numpy as np
import pytest

from exsynth import cli
from exsynth.operators import voxelize as voxelize_ops
from helpers import BUNNY_OBJ, TEXTURES, read_obj, scene_state

B = ["analogy", "--b", BUNNY_OBJ, "--resolution", "24"]


def run(capsys, *args):
    code = cli.main(list(args))
    return code, capsys.readouterr().err


def scaled_bunny(path, scale):
    lines = []
    for line in open(BUNNY_OBJ).read().splitlines():
        if line.startswith("v "):
            line = "v " + " ".join(f"{float(t) * scale:.9e}" for t in line.split()[1:4])
        lines.append(line)
    path.write_text("\n".join(lines) + "\n")
    return str(path)


@pytest.mark.parametrize("args, message", [
    (["--preset", "dilate", "--dilation", "-5"], "'--dilation' must be a finite number > 0"),
    (["--preset", "spikes", "--spike-height", "5"], "--spike-height (5) plus half the thickness"),
])
def test_pair_options_are_named_as_the_user_gave_them(tmp_path, capsys, args, message):
    code, err = run(capsys, *B, *args, "--out", str(tmp_path / "x.obj"))
    assert code == 2 and message in err
    assert "padding" not in err and "feature_height" not in err
    assert os.listdir(tmp_path) == []


def test_a_nan_vertex_is_named(tmp_path, capsys):
    text = open(BUNNY_OBJ).read().replace("v 1.301895 0.122622 2.550061", "v nan 0.122622 2.550061", 1)
    assert "v nan" in text
    (tmp_path / "nan.obj").write_text(text)
    code, err = run(capsys, "analogy", "--b", str(tmp_path / "nan.obj"), "--preset", "spikes", "--resolution", "24",
                    "--out", str(tmp_path / "x.obj"))
    assert code == 2
    assert "nan.obj line 2: vertex 0 is not three finite numbers" in err
    assert os.listdir(tmp_path) == ["nan.obj"]


def test_a_millionth_sized_model_works(tmp_path, capsys):
    """Voxels of ~1e-8 units (OpenVDB cannot hold such a transform)."""
    tiny = scaled_bunny(tmp_path / "tiny.obj", 1e-6)
    out = tmp_path / "x.obj"
    code, err = run(capsys, "analogy", "--b", tiny, "--preset", "spikes", "--resolution", "24", "--out", str(out))
    assert code == 0, err
    verts, faces = read_obj(out)
    assert len(faces) > 100
    assert 1e-7 < np.ptp(verts, axis=0).max() < 2e-5  # the bunny is 9.7e-6 across, plus its spikes
    # A .vdb cannot store such voxels: refused with what to do, nothing written.
    code, err = run(capsys, "voxelize", "--mesh", tiny, "--resolution", "16", "--out", str(tmp_path / "t.vdb"))
    assert code == 2 and "too small for an OpenVDB file" in err and "scale the model up" in err
    assert sorted(os.listdir(tmp_path)) == ["tiny.obj", "x.obj"]


def test_a_folder_given_as_an_input_file(tmp_path, capsys):
    code, err = run(capsys, "voxelize", "--mesh", str(tmp_path), "--out", str(tmp_path / "x.npy"))
    assert code == 2 and f"--mesh: {tmp_path} is a folder; give a file in it" in err


def test_out_of_range_face_indices_are_reported(tmp_path, capsys):
    """Blender's importer would drop the face and carry on with a hole."""
    path = tmp_path / "broken.obj"
    path.write_text(open(BUNNY_OBJ).read() + "f 1 2 99999\n")
    code, err = run(capsys, "voxelize", "--mesh", str(path), "--out", str(tmp_path / "x.npy"))
    assert code == 2
    assert "face vertex 99999 is out of range (the file has 1839 vertices" in err
    assert os.listdir(tmp_path) == ["broken.obj"]


def test_field_keeps_every_vertex_of_the_file(tmp_path, capsys):
    """One row per vertex of the file, in its order, loose vertices included;
    --paint with one row per file vertex is accepted."""
    path = tmp_path / "loose.obj"
    path.write_text(open(BUNNY_OBJ).read() + "v 9 9 9\n")
    out = tmp_path / "f.npy"
    code, err = run(capsys, "field", "--mesh", str(path), "--preset", "around_axis", "--out", str(out))
    assert code == 0, err
    field = np.load(out)
    assert field.shape == (1840, 3)
    np.testing.assert_allclose(np.linalg.norm(field, axis=1), 1.0, atol=1e-5)
    paint = np.zeros((1840, 3))
    paint[0] = (1, 0, 0)
    np.save(tmp_path / "paint.npy", paint)
    code, err = run(capsys, "field", "--mesh", str(path), "--paint", str(tmp_path / "paint.npy"), "--out", str(out))
    assert code == 0, err
    assert np.load(out).shape == (1840, 3)


def test_field_paint_with_nan_names_the_option(tmp_path, capsys):
    paint = np.zeros((1839, 3))
    paint[7] = np.nan
    np.save(tmp_path / "paint.npy", paint)
    code, err = run(capsys, "field", "--mesh", BUNNY_OBJ, "--paint", str(tmp_path / "paint.npy"),
                    "--out", str(tmp_path / "f.npy"))
    assert code == 2
    assert "--paint: row 7 of" in err and "'given'" not in err


def test_an_open_mesh_is_voxelized_with_a_warning(tmp_path, capsys):
    path = tmp_path / "plane.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 4 3\n")
    code, err = run(capsys, "voxelize", "--mesh", str(path), "--resolution", "16", "--out", str(tmp_path / "x.npy"))
    assert code == 0
    assert "warning: 'plane' encloses no volume" in err


def test_the_voxelize_operator_warns_about_an_empty_result():
    voxels = voxelize_ops.Voxels("Plane", np.zeros((2, 2, 2), np.float32), np.ones((2, 2, 2), np.float32),
                                 np.zeros(3), 1.0)
    assert "encloses no volume" in voxels.warning()
    voxels.density[0, 0, 0] = 1.0
    assert voxels.warning() is None


def test_geometric_texture_names_a_nan_vertex(bunny):
    bunny.data.vertices[3].co = (float("nan"), 0.0, 0.0)
    before = scene_state()
    with pytest.raises(RuntimeError, match=r"vertex 3 of the active object 'bunny' is not finite"):
        bpy.ops.exsynth.geometric_texture()
    assert scene_state() == before


def moved_bunny(path, dx):
    lines = []
    for line in open(BUNNY_OBJ).read().splitlines():
        if line.startswith("v "):
            x, y, z = (float(t) for t in line.split()[1:4])
            line = f"v {x + dx:.6f} {y:.6f} {z:.6f}"
        lines.append(line)
    path.write_text("\n".join(lines) + "\n")
    return str(path)


def test_a_prime_away_from_a_is_the_cause_named(tmp_path, capsys):
    far = moved_bunny(tmp_path / "far.obj", 300.0)
    code, err = run(capsys, *B, "--a", BUNNY_OBJ, "--a-prime", far, "--out", str(tmp_path / "x.obj"))
    assert code == 2
    assert "A′ lies away from A (their bounding boxes do not overlap)" in err and "voxel_size" not in err
    assert os.listdir(tmp_path) == ["far.obj"]


def test_analogy_budget_message_names_what_the_cli_can_change(tmp_path, capsys):
    # A pattern size by hand: the grid stays at --resolution, so lowering it helps (test_pattern_size.py has
    # the fitted case, where the message names --pattern-size instead).
    code, err = run(capsys, *B, "--preset", "spikes", "--pattern-size", "0.5", "--memory-budget", "0.001",
                    "--out", str(tmp_path / "x.obj"))
    assert code == 1
    assert "over the memory budget" in err and "lower the resolution or raise the memory budget" in err
    assert "voxel_size" not in err
    assert os.listdir(tmp_path) == []


@pytest.mark.parametrize("args, message", [
    (["image", "--method", "optimization", "--width", "64", "--height", "3", "--out", "x.png"],
     "--width and --height must be 29..16384 pixels with --levels 3 (got 64x3)"),
    (["solid", "--size", "1", "--out", "x.npy"], "--size must be 29..2048 voxels with --levels 3 (got 1)"),
])
def test_texture_sizes_follow_the_engine_rule_by_option_name(tmp_path, monkeypatch, capsys, args, message):
    monkeypatch.chdir(tmp_path)
    code, err = run(capsys, args[0], "--exemplar", os.path.join(TEXTURES, "crackedground.png"), *args[1:])
    assert code == 2 and message in err and "voxels across" not in err
    assert os.listdir(tmp_path) == []


def huge_exr(path, magnitude=1e20, size=40, nan_at=None):
    """A 32-bit float EXR whose values are ~magnitude (a half-float EXR would
    hold inf: Blender saves 16-bit unless the scene's settings say 32),
    with a NaN pixel at `nan_at` if given."""
    image = bpy.data.images.new("huge", size, size, float_buffer=True)
    px = np.ones((size, size, 4), np.float32)
    px[..., :3] = np.random.default_rng(1).random((size, size, 3)) * magnitude
    if nan_at is not None:
        px[nan_at][0] = np.nan
    image.pixels.foreach_set(px.ravel())
    settings = bpy.context.scene.render.image_settings
    old = settings.file_format, settings.color_depth
    settings.file_format, settings.color_depth = "OPEN_EXR", "32"
    try:
        image.save_render(str(path), scene=bpy.context.scene)
    finally:
        settings.file_format, settings.color_depth = old
        bpy.data.images.remove(image)
    return str(path)


def test_an_exemplar_of_1e20_gives_finite_values_of_its_size(tmp_path, capsys):
    exr = huge_exr(tmp_path / "huge.exr")
    code, err = run(capsys, "solid", "--exemplar", exr, "--size", "32", "--out", str(tmp_path / "s.npy"))
    assert code == 0, err
    assert "nan" not in err.lower() and "inf" not in err.lower()
    values = np.load(tmp_path / "s.npy")
    assert np.isfinite(values).all()
    assert 1e19 < np.median(values) < 1e20 and np.ptp(values) > 1e19


def test_a_nan_pixel_in_the_exemplar_is_named(tmp_path, capsys):
    exr = huge_exr(tmp_path / "nan.exr", magnitude=1.0, nan_at=(3, 5))
    code, err = run(capsys, "solid", "--exemplar", exr, "--size", "32", "--out", str(tmp_path / "s.npy"))
    assert code != 0 and "NaN or infinite pixels" in err and "Traceback" not in err
    assert not (tmp_path / "s.npy").exists()
