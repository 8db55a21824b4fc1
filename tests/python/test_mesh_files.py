"""exsynth.io.mesh_files (and io.ply): what Blender's importers would drop or change silently, and malformed
OBJ, PLY (ascii and binary) and STL files, refused with the option, the file, what and the fix."""
import re
import struct

import numpy as np
import pytest

from exsynth.io.mesh_files import MeshFileError, check_indices

from conftest import ASSETS

TRIANGLE = "v 0 0 0\nv 1 0 0\nv 0 1 0\n"


@pytest.mark.parametrize("text, message", [
    (TRIANGLE + "f 1 2 4\n", r"4: face vertex 4 is out of range \(the file has 3 vertices"),
    (TRIANGLE + "f 1 2 0\n", "4: face vertex 0 is out of range"),
    (TRIANGLE + "f -1 -2 -4\n", "4: face vertex -4 is out of range"),
    ("v 0 0 0\nf 1 2 3\nv 1 0 0\nv 0 1 0\n", r"2: face vertex 2"),  # used before it is defined
    (TRIANGLE + "f 1 2 x\n", "4: 'x' is not a vertex index"),
    ("v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", "2: vertex 1 is not three finite numbers"),
    ("v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n", "2: vertex 1 is not three finite numbers"),
])
def test_obj_bad_faces_are_named(tmp_path, text, message):
    path = tmp_path / "m.obj"
    path.write_text(text)
    with pytest.raises(MeshFileError, match="--mesh: .*m.obj line " + message):
        check_indices("--mesh", str(path))


def test_good_obj_files_pass(tmp_path):
    path = tmp_path / "m.obj"
    path.write_text(TRIANGLE + "vt 0 0\nf 1/1 2/1 3/1\nf -3 -2 -1\nl 1 2\n")
    check_indices("--mesh", str(path))
    check_indices("--mesh", str(ASSETS / "meshes" / "bunny.obj"))


def ply(faces):
    return ("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
            f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n"
            "0 0 0\n1 0 0\n0 1 0\n" + "".join(f"{len(f)} {' '.join(map(str, f))}\n" for f in faces))


def test_ascii_ply(tmp_path):
    path = tmp_path / "m.ply"
    path.write_text(ply([[0, 1, 2]]))
    check_indices("--b", str(path))
    path.write_text(ply([[0, 1, 2], [0, 1, 3]]))
    with pytest.raises(MeshFileError, match=r"--b: .*m.ply line 14: face 1 names vertex 3, which is out of range "
                                            r"\(the file has 3 vertices, numbered from 0\); fix or re-export"):
        check_indices("--b", str(path))


FORMATS = ["ascii", "binary_little_endian", "binary_big_endian"]
TRI = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float64)


def write_ply(path, fmt, verts, faces=None, normals=None, vtype="float", count="uchar", index="int",
              header=None):
    """A PLY file of vertices (x y z [nx ny nz]) and faces (lists of indices)
    in any of the three formats; `header` replaces the generated header."""
    props = ["x", "y", "z"] + (["nx", "ny", "nz"] if normals is not None else [])
    rows = np.asarray(verts, np.float64) if normals is None else np.c_[verts, normals]
    lines = ["ply", f"format {fmt} 1.0", f"element vertex {len(rows)}"] + [f"property {vtype} {p}" for p in props]
    if faces is not None:
        lines += [f"element face {len(faces)}", f"property list {count} {index} vertex_indices"]
    text = header if header is not None else "\n".join(lines + ["end_header"]) + "\n"
    if fmt == "ascii":
        body = "".join(" ".join(f"{v:.9g}" for v in r) + "\n" for r in rows)
        body += "".join(f"{len(f)} {' '.join(map(str, f))}\n" for f in faces or [])
        path.write_bytes(text.encode() + body.encode())
    else:
        from exsynth.io.ply import TYPES
        order = "<" if fmt == "binary_little_endian" else ">"
        body = rows.astype(order + TYPES[vtype]).tobytes()
        for f in faces or []:
            body += np.array([len(f)], order + TYPES[count]).tobytes() + np.array(f, order + TYPES[index]).tobytes()
        path.write_bytes(text.encode() + body)
    return str(path)


def message(path, fmt, option="--mesh"):
    with pytest.raises(MeshFileError) as info:
        check_indices(option, str(path))
    text = str(info.value)
    assert text.startswith(f"{option}: {path}"), text
    return text


def bunny():
    from exsynth.io.mesh_files import read_obj
    return read_obj("--mesh", str(ASSETS / "meshes" / "bunny.obj"))


@pytest.mark.parametrize("fmt", FORMATS)
def test_good_ply_files_pass_in_every_format(tmp_path, fmt):
    v, f = bunny()
    check_indices("--mesh", write_ply(tmp_path / "bunny.ply", fmt, v, f.tolist()))
    # Triangles and quads (binary: read row by row), other types, no faces at all.
    mixed = [[0, 1, 2], [0, 1, 2, 3], [3, 2, 1]]
    quad = np.r_[TRI, [[1, 1, 0]]]
    check_indices("--mesh", write_ply(tmp_path / "mixed.ply", fmt, quad, mixed, vtype="double", count="uint8",
                                      index="uint32"))
    check_indices("--mesh", write_ply(tmp_path / "points.ply", fmt, TRI, normals=TRI + 1))
    check_indices("--mesh", write_ply(tmp_path / "empty.ply", fmt, TRI, []))


NAN = TRI.copy()
NAN[1, 0] = np.nan
INF = TRI.copy()
INF[2, 2] = -np.inf


@pytest.mark.parametrize("fmt", FORMATS)
@pytest.mark.parametrize("verts, faces, what", [
    (NAN, [[0, 1, 2]], r"vertex 1 is not finite \(nan 0 0\); remove or fix it"),
    (INF, [[0, 1, 2]], r"vertex 2 is not finite \(0 1 -inf\); remove or fix it"),
    (TRI, [[0, 1, 2], [0, 1, 3]], r"face 1 names vertex 3, which is out of range \(the file has 3 vertices, "
                                   r"numbered from 0\); fix or re-export the file"),
    (TRI, [[0, 1, 2], [0, -1, 2]], r"face 1 names vertex -1, which is out of range"),
    (TRI, [[0, 1, 2, 0], [0, 1, 2], [2, 1, 7]], "face 2 names vertex 7"),  # mixed lengths: read row by row
])
def test_bad_ply_vertices_and_faces_are_named_in_every_format(tmp_path, fmt, verts, faces, what):
    text = message(write_ply(tmp_path / "bad.ply", fmt, verts, faces), fmt)
    assert re.search(what, text), text
    # ASCII names the line; binary formats name the vertex or face alone.
    assert (" line " in text) == (fmt == "ascii")


@pytest.mark.parametrize("verts, faces", [(NAN, [[0, 1, 2]]), (TRI, [[0, 1, 2], [0, 1, 3]]), (TRI, [[3, 0, 1]])])
def test_ascii_and_binary_ply_of_one_mesh_get_the_same_verdict(tmp_path, verts, faces):
    verdicts = set()
    for fmt in FORMATS:
        text = message(write_ply(tmp_path / f"{fmt}.ply", fmt, verts, faces), fmt)
        verdicts.add(re.sub(r"^.*?\.ply( line \d+)?: ", "", text))
    assert len(verdicts) == 1, verdicts


HEADER = "ply\nformat {fmt} 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n"


def header_with(fmt, old, new):
    text = HEADER.format(fmt=fmt)
    assert old in text
    return text.replace(old, new)


@pytest.mark.parametrize("fmt", FORMATS)
@pytest.mark.parametrize("old, new, what", [
    ("element vertex 3", "element vertex eight", r"header line 3: the count of element 'vertex' is 'eight', not "
                                                 r"a non-negative integer; fix or re-export the file"),
    ("element vertex 3", "element vertex -3", "the count of element 'vertex' is '-3', not a non-negative integer"),
    ("element vertex 3", "element vertex 2.5", "the count of element 'vertex' is '2.5'"),
    ("element vertex 3", "element vertex", "header line 3: an element line is 'element NAME COUNT'"),
    ("property float x", "property float16 x", r"header line 4: unknown property type 'float16' \(use one of char, "),
    ("property float x", "property list uchar half x", "header line 4: unknown property type 'half'"),
    ("property float x", "property list float int x", "header line 4: the list 'x' has its length as 'float'; a "
                                                       "length must be an integer type"),
    ("property float y", "property float x", "header line 5: element 'vertex' has two properties named 'x'"),
    ("property float x", "property x", "header line 4: a property line is 'property TYPE NAME'"),
    ("element vertex 3\n", "", "header line 3: a property before any element; fix or re-export the file"),
    # ASCII: the first vertex row is taken for the header; binary: the rest of the file
    ("end_header\n", "", r"header line 7: unknown header line '0 0 0' \(is end_header missing\?\)|"
                          r"^[^:]*: [^:]*: the PLY header has no end_header line"),
    ("ply\n", "plx\n", r"not a PLY file \(its first line is not 'ply'\)"),
    ("end_header", "end_header_\nend_header", "header line 7: unknown header line 'end_header_'"),
    ("element vertex 3", "element vertex 4000000000", r"the header claims 4000000000 vertex rows, at least "
                                                     r"\d+ bytes of data, but the file has only \d+ bytes after its "
                                                     r"header: it is cut short or its header is wrong"),
])
def test_malformed_ply_headers_are_refused(tmp_path, fmt, old, new, what):
    header = header_with(fmt, old, new)
    text = message(write_ply(tmp_path / "bad.ply", fmt, TRI, header=header), fmt)
    assert re.search(what, text), text
    assert text.endswith("fix or re-export the file") or "give a PLY file" in text, text


@pytest.mark.parametrize("name", ["binary_middle_endian", "ascii2", "BINARY_LITTLE_ENDIAN"])
def test_unknown_ply_formats_are_refused(tmp_path, name):
    path = tmp_path / "bad.ply"
    path.write_bytes(HEADER.format(fmt=name).encode() + b"0 0 0\n" * 3)
    assert f"header line 2: unknown PLY format '{name} 1.0' (ascii, binary_little_endian or binary_big_endian); " \
           "fix or re-export the file" in message(path, "ascii")


def test_a_ply_header_without_a_format_line_is_refused(tmp_path):
    path = tmp_path / "bad.ply"
    path.write_bytes(HEADER.format(fmt="ascii").replace("format ascii 1.0\n", "").encode() + b"0 0 0\n" * 3)
    assert "bad.ply: the PLY header has no format line; fix or re-export the file" in message(path, "ascii")


def test_a_ply_file_cut_within_its_header_is_refused(tmp_path):
    path = tmp_path / "cut.ply"
    path.write_bytes(HEADER.format(fmt="binary_little_endian").encode()[:40])
    assert "the PLY header has no end_header line (the file is cut short or not a PLY file); fix or re-export" \
        in message(path, "binary")


@pytest.mark.parametrize("fmt", FORMATS[1:])
def test_truncated_binary_ply_is_refused(tmp_path, fmt):
    path = tmp_path / "cut.ply"
    data = open(write_ply(path, fmt, TRI, [[0, 1, 2], [2, 1, 0]]), "rb").read()
    path.write_bytes(data[:-5])  # within the last face
    assert re.search(r"the file ends within its 2 face rows \(5 bytes missing\): it is cut short; fix or re-export",
                     message(path, fmt))
    path.write_bytes(data[:len(data) - 25])  # too short for the faces' lengths alone: refused before reading
    assert "the header claims 2 face rows, at least 38 bytes of data, but the file has only 37 bytes" \
        in message(path, fmt)


def test_truncated_or_malformed_ascii_ply_names_the_line(tmp_path):
    good = ply([[0, 1, 2], [0, 1, 2]])
    path = tmp_path / "bad.ply"
    for text, what in [
        (good.rsplit("3 0 1 2", 1)[0], "the file ends at line 13, after 1 of its 2 face rows: it is cut short"),
        (good.replace("1 0 0\n", "1 zero 0\n"), "line 11: 'zero' is not a number"),
        (good.replace("1 0 0\n", "1 0\n"), r"line 11: 2 values for a vertex row of 3 properties \(x y z\)"),
        (good.replace("1 0 0\n", "nan 0 0\n"), r"line 11: vertex 1 is not finite \(nan 0 0\)"),
        (good.replace("3 0 1 2\n", "3 0 1\n", 1), "line 13: the face row ends before its 'vertex_indices'"),
        (good.replace("3 0 1 2\n", "3 0 1 2 2\n", 1), "line 13: 1 values left over at the end of the face row"),
        (good.replace("3 0 1 2\n", "3 0 one 2\n", 1), "line 13: the face row's 'vertex_indices' is not a length "
                                                     "and that many integers"),
        (good.replace("3 0 1 2\n", "-3 0 1 2\n", 1), "line 13: the face row's 'vertex_indices' is not a length"),
        (good.replace("list uchar int", "list uchar float"), "the PLY faces have no integer list 'vertex_indices'"),
        (good.replace("property float x", "property float w"), "the PLY file has no vertex element with x y z"),
    ]:
        path.write_text(text)
        assert re.search(what, message(path, "ascii")), (what, message(path, "ascii"))


def test_binary_ply_with_a_negative_list_length_is_refused(tmp_path):
    path = tmp_path / "neg.ply"
    write_ply(path, "binary_little_endian", TRI, [[0, 1, 2]], count="char")
    data = bytearray(path.read_bytes())
    data[-13] = 0xFF  # the face's length: -1
    path.write_bytes(bytes(data))
    assert "face row 0: the list 'vertex_indices' has a negative length (-1)" in message(path, "binary")


def write_binary_stl(path, triangles, header=b"exsynth"):
    rows = np.zeros(len(triangles), np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]))
    rows["v"] = triangles
    path.write_bytes(header.ljust(80, b" ") + struct.pack("<I", len(triangles)) + rows.tobytes())
    return str(path)


def ascii_stl(triangles):
    return "solid t\n" + "".join("facet normal 0 0 1\nouter loop\n" + "".join(f"vertex {p[0]} {p[1]} {p[2]}\n"
                                                                         for p in t) + "endloop\nendfacet\n"
                                 for t in triangles) + "endsolid t\n"


def test_good_stl_files_pass(tmp_path):
    v, f = bunny()
    check_indices("--mesh", write_binary_stl(tmp_path / "b.stl", v[f]))
    check_indices("--mesh", write_binary_stl(tmp_path / "solid.stl", v[f], header=b"solid but binary"))
    (tmp_path / "a.stl").write_text(ascii_stl(v[f][:50]))
    check_indices("--mesh", str(tmp_path / "a.stl"))


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_stl_vertices_are_refused(tmp_path, bad):
    tris = np.array([TRI, TRI + 1])
    tris[1, 2, 1] = bad
    path = write_binary_stl(tmp_path / "b.stl", tris)
    assert message(path, "stl").endswith("b.stl: triangle 1 has a vertex that is not finite; remove or fix it")
    (tmp_path / "a.stl").write_text(ascii_stl(tris))
    assert message(tmp_path / "a.stl", "stl").endswith(
        "a.stl line 13: a vertex is not three finite numbers; remove or fix it")


def test_malformed_stl_files_are_refused(tmp_path):
    path = write_binary_stl(tmp_path / "cut.stl", np.array([TRI, TRI]))
    open(path, "r+b").truncate(180)
    assert "cut.stl: a binary STL of 2 triangles has 184 bytes, the file has 180: it is cut short or its " \
           "header is wrong; fix or re-export the file" in message(path, "stl")
    (tmp_path / "short.stl").write_bytes(b"\x00" * 20)
    assert "20 bytes is too short for a binary STL file" in message(tmp_path / "short.stl", "stl")
    for text, what in [(ascii_stl([TRI]).replace("vertex 0.0 1.0 0.0\n", ""), "line 6: a facet has 2 vertices"),
                       (ascii_stl([TRI]).replace("vertex 1.0", "vertex one"), "line 5: a vertex is not three finite"),
                       (ascii_stl([TRI]).replace("vertex 1.0 0.0 0.0", "vertex 1 0"), "line 5: a vertex is not"),
                       ("solid t\nendsolid t\n", "no triangles as an ASCII STL; fix or re-export")]:
        (tmp_path / "a.stl").write_text(text)
        assert what in message(tmp_path / "a.stl", "stl")


def test_write_obj_keeps_tiny_coordinates_and_read_obj_reads_them_back(tmp_path):
    from exsynth.io.mesh_files import read_obj, write_obj

    rng = np.random.default_rng(1)
    v = rng.normal(size=(10, 3)) * 1e-6
    f = np.array([[0, 1, 2], [2, 3, 4], [9, 8, 7]], np.int32)
    path = tmp_path / "tiny.obj"
    write_obj(str(path), "tiny", v, f)
    v2, f2 = read_obj("--mesh", str(path))
    np.testing.assert_allclose(v2, v, rtol=1e-8)
    np.testing.assert_array_equal(f2, f)


def test_read_obj_fans_polygons_and_keeps_loose_vertices(tmp_path):
    from exsynth.io.mesh_files import read_obj

    path = tmp_path / "quad.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 5 5 5\nf 1 2 3 4\nf -5 -4 -3\n")
    v, f = read_obj("--mesh", str(path))
    assert v.shape == (5, 3)
    np.testing.assert_array_equal(f, [[0, 1, 2], [0, 2, 3], [0, 1, 2]])
