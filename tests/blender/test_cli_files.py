# SPDX-License-Identifier: GPL-3.0-or-later
"""Bad mesh and point files for `./exsynth run`, end to end: a binary PLY with
a NaN vertex or a face naming a missing vertex (Blender's importer would turn
the NaN into a number or drop the face and the job run on another mesh) and
malformed point exemplars are refused with exit code 2, the option, the file
and the problem on stderr, no traceback and nothing written."""

import os

import numpy as np
import pytest

from exsynth import cli
from exsynth.io.mesh_files import read_obj
from helpers import BUNNY_OBJ, TEXTURES

EXEMPLAR = os.path.join(TEXTURES, "crackedground.png")


def run(capsys, *args):
    code = cli.main(list(args))
    return code, capsys.readouterr().err


def binary_ply(path, verts, faces, order="<"):
    header = (f"ply\nformat binary_{'little' if order == '<' else 'big'}_endian 1.0\nelement vertex {len(verts)}\n"
              "property float x\nproperty float y\nproperty float z\n"
              f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n")
    rows = np.zeros(len(faces), [("n", "u1"), ("i", order + "i4", 3)])
    rows["n"], rows["i"] = 3, faces
    path.write_bytes(header.encode() + np.asarray(verts, order + "f4").tobytes() + rows.tobytes())
    return str(path)


def bad_bunny(tmp_path, what, order="<"):
    verts, faces = read_obj("--mesh", BUNNY_OBJ)
    if what == "nan":
        verts[5, 1] = np.nan
    else:
        faces[7, 2] = 99999
    return binary_ply(tmp_path / f"{what}.ply", verts, faces, order)


JOBS = {
    "surface": lambda p, out: ["surface", "--mesh", p, "--exemplar", EXEMPLAR, "--out", str(out / "x.obj"),
                               "--texture-out", str(out / "x.png")],
    "field": lambda p, out: ["field", "--mesh", p, "--preset", "around_axis", "--out", str(out / "x.npy")],
    "analogy": lambda p, out: ["analogy", "--preset", "spikes", "--b", p, "--resolution", "24",
                               "--out", str(out / "x.obj")],
    "points": lambda p, out: ["points", "--preset", "chainmail", "--target", p, "--out", str(out / "x.ply")],
}
OPTION = {"surface": "--mesh", "field": "--mesh", "analogy": "--b", "points": "--target"}


def refused(capsys, tmp_path, args, *messages):
    before = sorted(os.listdir(tmp_path))
    code, err = run(capsys, *args)
    assert code == 2, err
    for m in messages:
        assert m in err, err
    assert "Traceback" not in err, err
    assert sorted(os.listdir(tmp_path)) == before  # no output file, not even a partial one
    return err


@pytest.mark.parametrize("job", JOBS)
@pytest.mark.parametrize("order", ["<", ">"])
def test_a_nan_vertex_in_a_binary_ply_is_refused(tmp_path, capsys, job, order):
    path = bad_bunny(tmp_path, "nan", order)
    refused(capsys, tmp_path, JOBS[job](path, tmp_path),
            f"{OPTION[job]}: {path}: vertex 5 is not finite (", "nan", "); remove or fix it")


@pytest.mark.parametrize("job", JOBS)
def test_a_missing_face_vertex_in_a_binary_ply_is_refused(tmp_path, capsys, job):
    path = bad_bunny(tmp_path, "face")
    refused(capsys, tmp_path, JOBS[job](path, tmp_path),
            f"{OPTION[job]}: {path}: face 7 names vertex 99999, which is out of range (the file has 1839 "
            "vertices, numbered from 0); fix or re-export the file")


def test_a_good_binary_ply_still_runs(tmp_path, capsys):
    verts, faces = read_obj("--mesh", BUNNY_OBJ)
    path = binary_ply(tmp_path / "bunny.ply", verts, faces, ">")
    code, err = run(capsys, *JOBS["field"](path, tmp_path))
    assert code == 0, err
    assert np.load(tmp_path / "x.npy").shape == (1839, 3)


POINT_HEADER = ("ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
                "property float z\nproperty float nx\nproperty float ny\nproperty float nz\nend_header\n")


@pytest.mark.parametrize("header, body, message", [
    (POINT_HEADER.replace("vertex 2", "vertex 4000000000"), 48, "the header claims 4000000000 vertex rows"),
    (POINT_HEADER.replace("float nx", "float16 nx"), 48, "header line 7: unknown property type 'float16'"),
    (POINT_HEADER.replace("element vertex 2\n", ""), 48, "header line 3: a property before any element"),
    (POINT_HEADER.replace("vertex 2", "vertex eight"), 48, "the count of element 'vertex' is 'eight'"),
    (POINT_HEADER, 40, "the header claims 2 vertex rows, at least 48 bytes of data, but the file has only 40"),
    (POINT_HEADER.replace("property float nx\nproperty float ny\nproperty float nz\n", ""), 24,
     "its vertices have no normals (nx ny nz), it is not an oriented point set; give an oriented point set"),
])
def test_a_malformed_points_exemplar_is_refused(tmp_path, capsys, header, body, message):
    path = tmp_path / "bad.ply"
    values = np.tile(np.array([0, 0, 0, 0, 0, 1], "<f4"), 2)[:body // 4]
    path.write_bytes(header.encode() + values.tobytes())
    err = refused(capsys, tmp_path, ["points", "--exemplar", str(path), "--size", "2", "2", "--out",
                                     str(tmp_path / "x.ply")],
                  f"--exemplar: {path}: ", message)
    assert "fix or re-export the file" in err or "give an oriented point set" in err, err


@pytest.mark.parametrize("name, body, message", [
    ("cow.obj", None, "a mesh (.obj) has no per-point normals, it is not an oriented point set; give an oriented"),
    ("part.stl", b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
                 b"endloop\nendfacet\nendsolid x\n", "a mesh (.stl) has no per-point normals"),
    ("empty.xyz", b"", "the file holds no points; give an oriented point set"),
])
def test_a_mesh_or_an_empty_file_as_points_exemplar_is_refused(tmp_path, capsys, name, body, message):
    """A mesh was called an unreadable image; an empty .xyz was said to have no normals."""
    path = tmp_path / name
    path.write_bytes(open(BUNNY_OBJ, "rb").read() if body is None else body)
    refused(capsys, tmp_path, ["points", "--exemplar", str(path), "--size", "2", "2", "--out",
                               str(tmp_path / "x.ply")], f"--exemplar: {path}: ", message)
