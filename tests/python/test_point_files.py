"""exsynth.io.point_files: oriented point sets read back in every PLY format and
as text; malformed files, meshes and files without normals refused with
PointFileError naming the file, what is wrong and what to give (never a
traceback from another exception)."""
import re
import struct

import numpy as np
import pytest

from exsynth.io.point_files import PointFileError, is_point_file, read_points, write_points
from test_mesh_files import FORMATS, HEADER, TRI, header_with, write_ply

NORMALS = np.array([[0, 0, 1], [0, 0, 2], [0, 1, 0]], np.float64)


def refused(path, what):
    with pytest.raises(PointFileError) as info:
        read_points(str(path))
    text = str(info.value)
    assert text.startswith(f"{path}: ") or text.startswith(f"{path} line "), text
    assert re.search(what, text), text
    return text


def test_write_points_reads_back(tmp_path):
    rng = np.random.default_rng(3)
    pos, nrm = rng.normal(size=(50, 3)), rng.normal(size=(50, 3))
    write_points(str(tmp_path / "p.ply"), pos, nrm)
    p, n = read_points(str(tmp_path / "p.ply"))
    np.testing.assert_allclose(p, pos, rtol=1e-6)
    np.testing.assert_allclose(n, nrm / np.linalg.norm(nrm, axis=1, keepdims=True), rtol=1e-5)


@pytest.mark.parametrize("fmt", FORMATS)
@pytest.mark.parametrize("vtype", ["float", "double", "float32"])
def test_point_ply_in_every_format(tmp_path, fmt, vtype):
    p, n = read_points(write_ply(tmp_path / "p.ply", fmt, TRI, normals=NORMALS, vtype=vtype))
    np.testing.assert_allclose(p, TRI)
    np.testing.assert_allclose(n, [[0, 0, 1], [0, 0, 1], [0, 1, 0]])


def test_text_point_files(tmp_path):
    path = tmp_path / "p.xyz"
    path.write_text("# x y z nx ny nz\n0 0 0 0 0 1\n\n1 0 0 0 0 2 7\n")
    p, n = read_points(str(path))
    np.testing.assert_allclose(p, [[0, 0, 0], [1, 0, 0]])
    np.testing.assert_allclose(n, [[0, 0, 1], [0, 0, 1]])


@pytest.mark.parametrize("fmt", FORMATS)
@pytest.mark.parametrize("old, new, what", [
    ("property float x", "property float16 x", "header line 4: unknown property type 'float16'"),
    ("element vertex 3\n", "", "header line 3: a property before any element; fix or re-export the file"),
    ("element vertex 3", "element vertex eight", "header line 3: the count of element 'vertex' is 'eight', not a "
                                                 "non-negative integer; fix or re-export the file"),
    ("element vertex 3", "element vertex 4000000000", "the header claims 4000000000 vertex rows, at least "),
    ("property float x", "property list double float x", "the list 'x' has its length as 'double'"),
    ("ply\n", "PLY\n", "not a PLY file"),
])
def test_malformed_point_ply_is_refused(tmp_path, fmt, old, new, what):
    header = header_with(fmt, old, new)
    header = header.replace("end_header", "property float nx\nproperty float ny\nproperty float nz\nend_header")
    path = write_ply(tmp_path / "bad.ply", fmt, TRI, normals=NORMALS, header=header)
    refused(path, what)


def test_unknown_format_and_missing_end_header(tmp_path):
    path = tmp_path / "bad.ply"
    path.write_bytes(HEADER.format(fmt="binary_middle_endian").encode())
    refused(path, r"header line 2: unknown PLY format 'binary_middle_endian 1.0'")
    path.write_bytes(HEADER.format(fmt="ascii").replace("end_header\n", "").encode())
    refused(path, "the PLY header has no end_header line")


@pytest.mark.parametrize("fmt", FORMATS[1:])
def test_truncated_binary_point_ply_is_refused(tmp_path, fmt):
    path = tmp_path / "cut.ply"
    data = open(write_ply(path, fmt, TRI, normals=NORMALS), "rb").read()
    path.write_bytes(data[:-4])
    refused(path, r"the header claims 3 vertex rows, at least 72 bytes of data, but the file has only 68 bytes "
                  r"after its header: it is cut short or its header is wrong; fix or re-export the file")


def test_truncated_ascii_point_ply_names_the_line(tmp_path):
    path = tmp_path / "cut.ply"
    text = open(write_ply(path, "ascii", TRI, normals=NORMALS)).read()
    path.write_text(text.rsplit("0 1 0", 1)[0])
    refused(path, r"line 13: 3 values for a vertex row of 6 properties \(x y z nx ny nz\)")
    path.write_text(text.replace("0 0 2", "0 0 two"))
    refused(path, "line 12: 'two' is not a number")
    header, rows = text.split("end_header\n")
    path.write_text(header.replace("property float x", "property list uchar float x") + "end_header\n"
                    + "".join("1 " + row + "\n" for row in rows.splitlines()))
    refused(path, "the vertices' x y z are lists, not numbers")


@pytest.mark.parametrize("fmt", FORMATS)
def test_a_mesh_or_a_ply_without_normals_is_not_a_point_set(tmp_path, fmt):
    give = r"give an oriented point set: a \.ply with x y z nx ny nz per vertex, or a \.xyz / \.pwn"
    refused(write_ply(tmp_path / "mesh.ply", fmt, TRI, [[0, 1, 2]]),
            r"mesh.ply: a mesh \(1 faces\) whose vertices have no normals \(nx ny nz\), it is not an oriented "
            r"point set; " + give)
    refused(write_ply(tmp_path / "bare.ply", fmt, TRI), "bare.ply: its vertices have no normals " + r"\(nx ny nz\)")


@pytest.mark.parametrize("ext", [".obj", ".stl", ".OBJ"])
def test_mesh_files_are_refused_with_what_to_give(tmp_path, ext):
    path = tmp_path / f"bunny{ext}"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    assert is_point_file(str(path))
    refused(path, rf"a mesh \({ext.lower()}\) has no per-point normals, it is not an oriented point set; give ")


def test_is_point_file_leaves_images_to_the_image_loader():
    assert is_point_file("a.ply") and is_point_file("a.XYZ") and is_point_file("a.pwn")
    assert not is_point_file("a.png") and not is_point_file("a.exr")


@pytest.mark.parametrize("text, what", [
    ("", "the file holds no points; give an oriented point set"),
    ("# only a comment\n\n", "the file holds no points"),
    ("0 0 0\n1 0 0\n", r"p.xyz line 1: 3 numbers; an oriented point set needs six a line \(x y z nx ny nz\): the "
                       "file has no normals; give"),
    ("0 0 0 0 0 1\n1 0 0 0 1\n", "p.xyz line 2: 5 numbers; an oriented point set needs six"),
    ("0 0 0 0 0 1\n1 0 zero 0 0 1\n", "p.xyz line 2: 'zero' is not a number; fix or re-export the file"),
    ("0 0 0 0 0 1\n1 0 0 nan 0 1\n", r"point 1 \(of 2\) has a NaN or infinite position or normal; remove or fix"),
    ("0 0 0 0 0 1\n1 0 0 0 0 0\n", "point 1 has a zero normal"),
])
def test_bad_text_point_files(tmp_path, text, what):
    path = tmp_path / "p.xyz"
    path.write_text(text)
    refused(path, what)


def test_a_binary_file_named_xyz(tmp_path):
    path = tmp_path / "p.xyz"
    path.write_bytes(struct.pack("<6f", 0, 0, 0, 0, 0, 1) + b"\xff\xfe\n" * 3)
    with pytest.raises(PointFileError, match=r"p.xyz line \d+: .*(is not a number|numbers; an oriented)"):
        read_points(str(path))


@pytest.mark.parametrize("fmt", FORMATS)
def test_non_finite_or_zero_normals_in_ply(tmp_path, fmt):
    bad = NORMALS.copy()
    bad[2, 1] = np.inf
    refused(write_ply(tmp_path / "inf.ply", fmt, TRI, normals=bad), r"point 2 \(of 3\) has a NaN or infinite")
    bad[2] = 0
    refused(write_ply(tmp_path / "zero.ply", fmt, TRI, normals=bad), "point 2 has a zero normal")
