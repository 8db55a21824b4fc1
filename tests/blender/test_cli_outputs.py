# SPDX-License-Identifier: GPL-3.0-or-later
"""`./exsynth run` writes all its files or none: unwritable paths are refused
before the job starts, a failed, cancelled or interrupted job leaves no new
file and an existing one untouched, and a bad number never reaches the
engine (no traceback)."""

import os
import signal
import subprocess

import numpy as np
import pytest

from exsynth import _native, cli
from exsynth.io import image as image_io
from exsynth.operators import solid as solid_ops
from helpers import BUNNY_OBJ, ROOT, TEXTURES

CRACKED = os.path.join(TEXTURES, "crackedground.png")
FAST_SOLID = ["--size", "8", "--levels", "1", "--iterations", "1"]


def run(capsys, *args):
    code = cli.main(list(args))
    return code, capsys.readouterr().err


def test_out_is_a_folder(tmp_path, capsys):
    code, err = run(capsys, "analogy", "--b", BUNNY_OBJ, "--preset", "spikes", "--resolution", "24",
                    "--out", str(tmp_path))
    assert code == 2
    assert f"--out: {tmp_path} is a folder; give a file name" in err
    assert os.listdir(tmp_path) == []


@pytest.mark.parametrize("job", [
    ["voxelize", "--mesh", BUNNY_OBJ, "--resolution", "16"],
    ["analogy", "--b", BUNNY_OBJ, "--preset", "spikes", "--resolution", "24"],
])
def test_mesh_out_that_cannot_be_written(tmp_path, capsys, job):
    out = tmp_path / "x.npy"
    mesh_out = "/proc/exsynth_cannot_write.obj"
    args = [*job, "--out", mesh_out] if job[0] == "analogy" else [*job, "--out", str(out), "--mesh-out", mesh_out]
    code, err = run(capsys, *args)
    assert code == 2
    assert f"cannot write {mesh_out}" in err
    assert os.listdir(tmp_path) == []


def test_no_partial_output_when_a_later_file_fails(tmp_path, capsys):
    """The issue's case: the bake cannot be written, so the solid is not left either."""
    out = tmp_path / "S.npy"
    code, err = run(capsys, "solid", "--exemplar", CRACKED, *FAST_SOLID, "--mesh", BUNNY_OBJ,
                    "--bake-out", "/proc/exsynth_bake.png", "--out", str(out))
    assert code == 2 and "--bake-out: cannot write" in err
    assert os.listdir(tmp_path) == []


def test_a_failed_job_leaves_the_existing_file_untouched(tmp_path, capsys):
    out = tmp_path / "x.vdb"
    out.write_bytes(b"an earlier result")
    code, err = run(capsys, "voxelize", "--mesh", BUNNY_OBJ, "--resolution", "400", "--memory-budget", "0.001",
                    "--out", str(out))
    assert code == 1 and "over the memory budget" in err and "nothing was written" in err
    assert out.read_bytes() == b"an earlier result"
    assert os.listdir(tmp_path) == ["x.vdb"]


def test_an_exporter_that_writes_nothing_fails_the_job(tmp_path, capsys, monkeypatch):
    """Blender's OBJ exporter returns FINISHED without a file on some paths:
    the job must fail, not print '-> path' and exit 0."""
    monkeypatch.setattr(cli, "export_obj", lambda *args: None)
    out, mesh_out = tmp_path / "x.npy", tmp_path / "m.obj"
    code, err = run(capsys, "voxelize", "--mesh", BUNNY_OBJ, "--resolution", "16", "--out", str(out),
                    "--mesh-out", str(mesh_out))
    assert code == 1
    assert f"--mesh-out: nothing was written to {mesh_out}" in err
    assert os.listdir(tmp_path) == []


def test_successful_outputs_replace_old_files(tmp_path, capsys):
    out = tmp_path / "x.npy"
    out.write_bytes(b"old")
    code, _ = run(capsys, "voxelize", "--mesh", BUNNY_OBJ, "--resolution", "16", "--out", str(out))
    assert code == 0
    assert np.load(out).ndim == 4
    assert os.listdir(tmp_path) == ["x.npy"]


@pytest.mark.parametrize("option, message", [
    (["--memory-budget", "inf"], "argument --memory-budget: inf GiB is out of range"),
    (["--memory-budget", "1e30"], "argument --memory-budget: 1e30 GiB is out of range"),
    (["--memory-budget", "-1"], "argument --memory-budget: -1 GiB is out of range"),
    (["--resolution", str(2**31)], "argument --resolution: 2147483648 is far too large"),
    (["--voxel-size", "nan"], "argument --voxel-size: nan is not a finite number"),
])
def test_numbers_out_of_range_are_refused_by_name(tmp_path, capsys, option, message):
    code, err = run(capsys, "voxelize", "--mesh", BUNNY_OBJ, "--out", str(tmp_path / "x.npy"), *option)
    assert code == 2
    assert message in err
    assert "Traceback" not in err
    assert os.listdir(tmp_path) == []


def image_job(tmp_path, *extra):
    return ["image", "--exemplar", CRACKED, "--width", "16", "--height", "16",
            "--out", str(tmp_path / "x.png"), *extra]


@pytest.mark.parametrize("seed, message", [
    ("-1", "argument --seed: -1 is out of range; give 0 .. 2**64-1"),
    (str(2**64), "is out of range; give 0 .. 2**64-1"),
    ("1.5", "argument --seed: '1.5' is not a whole number"),
])
def test_a_seed_out_of_range_is_refused_by_name(tmp_path, capsys, seed, message):
    code, err = run(capsys, *image_job(tmp_path, "--seed", seed))
    assert code == 2 and message in err and "Traceback" not in err
    assert os.listdir(tmp_path) == []


def test_seed_up_to_2_64_minus_1_works(tmp_path, capsys):
    code, _ = run(capsys, *image_job(tmp_path, "--seed", str(2**64 - 1)))
    assert code == 0 and os.listdir(tmp_path) == ["x.png"]


@pytest.mark.parametrize("job", [["voxelize", "--mesh", BUNNY_OBJ],
                                 ["analogy", "--b", BUNNY_OBJ, "--preset", "spikes"]])
def test_no_seed_where_nothing_is_random(tmp_path, capsys, job):
    """The voxelizer and the analogy are deterministic: --seed did nothing there, so it is gone."""
    code, err = run(capsys, *job, "--out", str(tmp_path / "x.npy"), "--seed", "3")
    assert code == 2 and "unrecognized arguments: --seed 3" in err
    assert os.listdir(tmp_path) == []


def test_ctrl_c_cancels_the_job_and_writes_nothing(tmp_path):
    """SIGINT to `./exsynth run` (Blender itself only notes it and carries on)."""
    out = tmp_path / "solid.npy"
    # A bpy module sets OCIO to its own colour config (5.2's is OCIO 2.5, which
    # Debian's Blender, started by ./exsynth, cannot read): not for the child.
    env = {k: v for k, v in os.environ.items() if not (k == "OCIO" and "site-packages" in v)}
    proc = subprocess.Popen(
        [os.path.join(ROOT, "exsynth"), "run", "solid", "--exemplar", CRACKED, "--size", "64", "--out", str(out)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        lines = []
        for line in proc.stderr:  # the CLI names each stage as the job reaches it
            lines.append(line)
            if line.startswith("exsynth solid: "):
                break
        proc.send_signal(signal.SIGINT)
        _, rest = proc.communicate(timeout=120)
    finally:
        proc.kill()
    err = "".join(lines) + rest
    assert proc.returncode == cli.EXIT_INTERRUPTED, err
    assert "interrupted (Ctrl-C); nothing was written" in err
    assert "Traceback" not in err
    assert os.listdir(tmp_path) == []


def test_solid_method_coordinates_and_a_bad_method(tmp_path, capsys):
    out = tmp_path / "s.npy"
    code, err = run(capsys, "solid", "--exemplar", CRACKED, "--size", "16", "--levels", "2", "--iterations", "1",
                    "--method", "coordinates", "--out", str(out))
    assert code == 0, err
    solid = np.load(out)
    assert solid.shape == (16, 16, 16, 3) and solid.std(axis=(0, 1, 2)).min() > 0.02
    code, err = run(capsys, "solid", "--exemplar", CRACKED, "--size", "16", "--method", "lazy",
                    "--out", str(tmp_path / "t.npy"))
    assert code == 2
    # (Python 3.13's argparse lists choices unquoted, 3.11's quoted.)
    assert "--method" in err and "optimization" in err and "coordinates" in err and "'lazy'" in err
    assert not (tmp_path / "t.npy").exists()


def test_solid_feature_weight(tmp_path, capsys):
    outs = []
    for weight in ("0", "3"):
        outs.append(tmp_path / f"w{weight}.npy")
        code, err = run(capsys, "solid", "--exemplar", CRACKED, "--size", "16", "--levels", "2", "--iterations", "1",
                        "--feature-weight", weight, "--out", str(outs[-1]))
        assert code == 0, err
    plain, featured = (np.load(p) for p in outs)
    assert plain.shape == featured.shape == (16, 16, 16, 3) and not np.array_equal(plain, featured)
    for weight, message in (("-1", "--feature-weight must be >= 0 (got -1.0)"),
                            ("101", "--feature-weight must be a number in [0, 100]")):
        code, err = run(capsys, "solid", "--exemplar", CRACKED, *FAST_SOLID, "--feature-weight", weight,
                        "--out", str(tmp_path / "bad.npy"))
        assert code != 0 and message in err, err
    assert not (tmp_path / "bad.npy").exists()


def solid_as_the_engine_makes(tmp_path, capsys, args, option, value, other):
    """`solid` with `args` on a 16^3 solid is the engine's with option=value, and not with `other`."""
    out = tmp_path / "o.npy"
    code, err = run(capsys, "solid", "--exemplar", CRACKED, "--size", "16", "--levels", "2", "--iterations", "1",
                    *args, "--out", str(out))
    assert code == 0, err
    ex = solid_ops.read_exemplars(image_io.load(CRACKED))[0]
    direct = lambda v: _native.synthesize_solid(ex, size=16, levels=2, iterations=1, seed=0, **{option: v})["solid"]
    np.testing.assert_allclose(np.load(out), direct(value), atol=1e-6)
    assert not np.array_equal(np.load(out), direct(other))


def refuses(tmp_path, capsys, args, message, code=None):
    """`solid` with `args` fails with `message` (and `code`, when given) and writes nothing."""
    bad = tmp_path / "bad.npy"
    got, err = run(capsys, "solid", "--exemplar", CRACKED, *FAST_SOLID, *args, "--out", str(bad))
    assert (got == code if code is not None else got != 0) and message in err, err
    assert not bad.exists()


def test_solid_feature_threshold(tmp_path, capsys):
    solid_as_the_engine_makes(tmp_path, capsys, ["--feature-threshold", "0"], "feature_threshold", 0.0, 1.0)
    for value in ("-1", "11"):
        refuses(tmp_path, capsys, ["--feature-threshold", value],
                f"--feature-threshold must be in 0..10 (got {float(value)})")


def test_solid_feature_scale(tmp_path, capsys):
    solid_as_the_engine_makes(tmp_path, capsys, ["--feature-scale", "16"], "feature_scale", 16, 0)
    for value in ("-1", "65"):
        refuses(tmp_path, capsys, ["--feature-scale", value],
                f"--feature-scale must be in 0..64 exemplar pixels (got {value})")
    refuses(tmp_path, capsys, ["--feature-scale", "2.5"], "invalid int value: '2.5'", code=2)


def test_solid_rotate_exemplar(tmp_path, capsys):
    # The flag alone turns the exemplar; auto (the default) and off by name.
    solid_as_the_engine_makes(tmp_path, capsys, ["--rotate-exemplar"], "rotate_exemplar", "on", "off")
    solid_as_the_engine_makes(tmp_path, capsys, ["--rotate-exemplar", "off"], "rotate_exemplar", "off", "on")
    refuses(tmp_path, capsys, ["--rotate-exemplar", "yes"], "invalid choice: 'yes'", code=2)


def test_solid_histogram_values(tmp_path, capsys):
    solid_as_the_engine_makes(tmp_path, capsys, ["--histogram-values", "0.1"], "histogram_values", 0.1, 0.0)
    for value, message in (("-1", "--histogram-values must be >= 0 (got -1.0)"),
                           ("101", "--histogram-values must be a number in [0, 100]")):
        refuses(tmp_path, capsys, ["--histogram-values", value], message)


def test_solid_structure_sigma(tmp_path, capsys):
    default = _native.SOLID_DEFAULT_STRUCTURE_SIGMA
    value = 0.0 if default else 1.5  # the flag away from the default reaches the engine
    solid_as_the_engine_makes(tmp_path, capsys, ["--structure-sigma", str(value)], "structure_sigma", value, default)
    for bad in ("-1", "9"):
        refuses(tmp_path, capsys, ["--structure-sigma", bad],
                f"--structure-sigma must be in 0..8 voxels (got {float(bad)})")


@pytest.mark.parametrize("method", ["coordinates", "optimization"])
def test_run_image_keeps_to_the_memory_budget_with_either_method(tmp_path, capsys, method):
    out = tmp_path / "x.png"
    code, err = run(capsys, "image", "--exemplar", CRACKED, "--method", method, "--width", "4096", "--height", "4096",
                    "--memory-budget", "0.001", "--out", str(out))
    assert code == 1 and "over the memory budget" in err and "nothing was written" in err
    assert os.listdir(tmp_path) == []


def test_solid_says_when_the_exemplar_was_turned(tmp_path, capsys):
    # crackedground's features are round: the default (auto) turns it, and the line says so.
    out = tmp_path / "o.npy"
    for flag, said in (([], True), (["--rotate-exemplar", "off"], False)):
        code = cli.main(["solid", "--exemplar", CRACKED, "--size", "16", "--levels", "2", "--iterations", "1",
                         *flag, "--out", str(out)])
        printed = capsys.readouterr().out
        assert code == 0 and ("exemplar also matched in its quarter turns" in printed) == said, printed
