# SPDX-License-Identifier: GPL-3.0-or-later
"""`./exsynth run` with values a user gets wrong: every flag is checked by
its own name (exit 2, before the job), no value is changed or ignored
silently, no impossible number in a message, and a job's files appear all
together or not at all."""

import os

import numpy as np
import pytest

from exsynth import cli
from helpers import TEXTURES, immutable, write_grid_obj

EXEMPLAR = os.path.join(TEXTURES, "crackedground.png")


def run(capsys, *args):
    code = cli.main([str(a) for a in args])
    captured = capsys.readouterr()
    assert "Traceback" not in captured.err
    return code, captured.err


def surface(tmp_path, *extra):
    return ["surface", "--mesh", write_grid_obj(tmp_path / "plane.obj", 2), "--exemplar", EXEMPLAR,
            "--face-resolution", "4", "--out", tmp_path / "a.obj", "--texture-out", tmp_path / "t.png", *extra]


@pytest.mark.skipif(os.geteuid() != 0, reason="marking a file immutable needs root (CAP_LINUX_IMMUTABLE)")
def test_an_immutable_texture_out_is_refused_and_nothing_changes(tmp_path, capsys):
    """The issue's case: the new .obj and .mtl were left beside the old .png."""
    for name in ("a.obj", "a.mtl", "t.png"):
        (tmp_path / name).write_text("old " + name)
    with immutable(tmp_path / "t.png"):
        code, err = run(capsys, *surface(tmp_path))
    assert code == 2
    assert f"--texture-out: {tmp_path / 't.png'} exists and cannot be replaced" in err and ".exsynth-" not in err
    assert sorted(os.listdir(tmp_path)) == ["a.mtl", "a.obj", "plane.obj", "t.png"]
    assert all((tmp_path / n).read_text() == "old " + n for n in ("a.obj", "a.mtl", "t.png"))


def cube_obj(path):
    corners = [(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    quads = [(1, 3, 4, 2), (5, 6, 8, 7), (1, 2, 6, 5), (3, 7, 8, 4), (1, 5, 7, 3), (2, 4, 8, 6)]
    path.write_text("".join(f"v {x} {y} {z}\n" for x, y, z in corners) + "".join(f"f {a} {b} {c} {d}\n"
                                                                              for a, b, c, d in quads))
    return path


CASES = {  # id: (job arguments with {d} = the test folder, what stderr must say)
    "points scale 1e-9": (["points", "--preset", "chainmail", "--target", "{d}/cube.obj", "--scale", "1e-9"],
                          r"--scale 1e-09: about [\d.]+e\+\d+ points need about [\d.e+]+ GiB, over the memory budget"
                          r" of 8 GiB; raise --scale \(the default for this target: [\d.]+\)"),
    "points negative scale": (["points", "--preset", "chainmail", "--target", "{d}/cube.obj", "--scale", "-1"],
                              r"--scale must be > 0 target units per exemplar unit \(got -1\)"),
    "points scale with size": (["points", "--preset", "chainmail", "--size", "2", "2", "--scale", "3"],
                               r"--scale goes with --target MESH"),
    "points axis with size": (["points", "--preset", "bumps", "--size", "2", "2", "--axis", "1", "0", "0"],
                              r"--axis goes with --target MESH"),
    "points pixel size with preset": (["points", "--preset", "bumps", "--size", "2", "2", "--pixel-size", "2"],
                                      r"--pixel-size goes with a height-field image"),
    "points tiny patch": (["points", "--preset", "bumps", "--size", "1", "1", "--patch-size", "1e-9"],
                          r"the patch size 1e-09 is less than two of the exemplar's point spacings"),
    "points height overflow": (["points", "--exemplar", EXEMPLAR, "--size", "2", "2", "--height-scale", "1e30"],
                               r"--height-scale 1e\+30 makes the heights overflow|--exemplar crackedground.png as a "
                               r"height field at --height-scale 1e\+30.*sampling [\d.]+e\+\d+ points"),
    "points height huge": (["points", "--exemplar", EXEMPLAR, "--size", "2", "2", "--height-scale", "1e20"],
                           r"--exemplar crackedground.png as a height field at --height-scale 1e\+20, --pixel-size "
                           r"1, --density 8000: sampling [\d.]+e\+\d+ points"),
    "points text field": (["points", "--preset", "bumps", "--target", "{d}/cube.obj", "--field", "{d}/text.npy"],
                          r"--field: .*text.npy holds <U1 values, not numbers"),
    "surface texels": (["surface", "--mesh", "{d}/cube.obj", "--exemplar", EXEMPLAR, "--texels-per-unit", "1e12"],
                       r"--texels-per-unit 1e\+12 asks for [\d.e+]+ texels along the largest face, over "
                       r"max_face_resolution 512; give --texels-per-unit at most [\d.]+ for this mesh"),
    "surface face resolution": (["surface", "--mesh", "{d}/cube.obj", "--exemplar", EXEMPLAR, "--method",
                                 "multiscale", "--face-resolution", "600"], r"--face-resolution must be in 1..512"),
    "surface exemplar scale": (["surface", "--mesh", "{d}/cube.obj", "--exemplar", EXEMPLAR, "--face-resolution",
                                "4", "--exemplar-scale", "1e9"], r"--exemplar-scale 1e\+09 steps so far per texel"
                               r".*give --exemplar-scale at most 25.6"),
    "surface zero field": (["surface", "--mesh", "{d}/cube.obj", "--exemplar", EXEMPLAR, "--face-resolution", "4",
                            "--field", "{d}/zero.npy"], r"--field: .*zero.npy is zero everywhere"),
    "field text paint": (["field", "--mesh", "{d}/cube.obj", "--paint", "{d}/text.npy"],
                         r"--paint: .*text.npy holds <U1 values, not numbers"),
    "analogy resolution 1": (["analogy", "--b", "{d}/cube.obj", "--preset", "spikes", "--resolution", "1"],
                             r"--resolution 1 is too coarse for a built-in pair.*at least 2"),
    "solid wide exemplar-z": (["solid", "--exemplar", EXEMPLAR, "--exemplar-z", "{d}/wide.png", "--size", "8",
                               "--levels", "1", "--iterations", "1", "--rotate-exemplar", "off"],
                              r"the exemplar for view z \(4096x16 pixels, analysed at 256x1 within "
                              r"max_exemplar_size\) is 256x1"),
}
OUTS = {"points": [".ply"], "surface": [".obj", "--texture-out", ".png"], "field": [".npy"], "analogy": [".obj"],
        "solid": [".npy"]}


@pytest.mark.parametrize("case", CASES)
def test_a_bad_value_is_refused_by_its_flag(tmp_path, capsys, case):
    import re

    import bpy

    cube_obj(tmp_path / "cube.obj")
    np.save(tmp_path / "zero.npy", np.zeros((8, 3)))
    np.save(tmp_path / "text.npy", np.array([["a", "b", "c"]] * 8))
    wide = bpy.data.images.new("wide", 4096, 16)
    wide.filepath_raw, wide.file_format = str(tmp_path / "wide.png"), 'PNG'
    wide.save()
    bpy.data.images.remove(wide)
    job, pattern = CASES[case]
    out = OUTS[job[0]]
    outs = ["--out", tmp_path / f"out{out[0]}"] + ([out[1], tmp_path / f"out{out[2]}"] if len(out) > 1 else [])
    before = sorted(os.listdir(tmp_path))
    code, err = run(capsys, *[a.format(d=tmp_path) for a in job], *outs)
    assert code == 2, err
    assert re.search(pattern, err), err
    assert sorted(os.listdir(tmp_path)) == before  # nothing written


def test_points_on_a_target_with_defaults_says_what_it_will_do(tmp_path, capsys):
    """The default scale follows the target's area, and the estimate is shown
    before the work: the issue's 2-unit cube did not finish in 120 s."""
    from exsynth import _native

    cube_obj(tmp_path / "cube.obj")
    code, err = run(capsys, "points", "--preset", "bumps", "--density", "1500", "--target", tmp_path / "cube.obj",
                    "--out", tmp_path / "o.ply")
    assert code == 0, err
    assert "(from the target area): about" in err and "patches" in err and "on a 2-core machine" in err
    from exsynth.io import point_files

    pos, _ = point_files.read_points(str(tmp_path / "o.ply"))
    # The default asks for POINTS_DEFAULT_OUTPUT points; the run makes 0.6-1.2 of that (measured).
    assert 0.4 * _native.POINTS_DEFAULT_OUTPUT < len(pos) < 1.5 * _native.POINTS_DEFAULT_OUTPUT
