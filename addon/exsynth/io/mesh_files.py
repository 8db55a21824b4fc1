# SPDX-License-Identifier: GPL-3.0-or-later
"""Checks on mesh files that Blender's importers hide.

Blender's OBJ and PLY importers silently drop faces whose vertex indices are
out of range, and turn a NaN coordinate into some number, so a broken file
would give a different mesh with no word of why. The headless jobs read the
files themselves first, whatever the format (OBJ; PLY ascii, binary little-
and big-endian, through io.ply; STL ascii and binary), and refuse a face
naming a missing vertex, a vertex that is not finite, or a malformed file,
naming the option, the file, the line or element, and the fix.

The jobs write their result meshes themselves too (write_obj), at full
precision. The field job also reads OBJ files itself (read_obj): its output has one
row per vertex of the file, in the file's order, and Blender's OBJ importer
drops vertices that no face uses.

No bpy here.
"""

import math
import os
import struct

import numpy as np

from . import ply

FIX = "fix or re-export the file"


class MeshFileError(ValueError):
    """The file is malformed; the message names the option, file and line."""


def check_indices(option, path):
    """Raise MeshFileError if the OBJ, PLY or STL file is malformed, a face
    names a vertex it does not have, or a vertex is not finite. Other
    extensions (images, .npy) are not looked at."""
    lower = path.lower()
    if lower.endswith(".obj"):
        _check_obj(option, path)
    elif lower.endswith(".ply"):
        _check_ply(option, path)
    elif lower.endswith(".stl"):
        _check_stl(option, path)


check_mesh_file = check_indices


def _check_obj(option, path):
    vertices = 0
    with open(path, "rb") as f:
        for number, line in enumerate(f, 1):
            if line.startswith(b"v "):
                vertices += 1
                coordinates = line.split()[1:4]
                try:
                    finite = len(coordinates) == 3 and all(math.isfinite(float(t)) for t in coordinates)
                except ValueError:
                    finite = False
                if not finite:  # Blender 4.5's importer reads "nan" as 0 and carries on
                    raise MeshFileError(f"{option}: {path} line {number}: vertex {vertices - 1} is not three finite "
                                        "numbers; remove or fix it")
            elif line.startswith((b"f ", b"l ")):
                for token in line.split()[1:]:
                    field = token.split(b"/")[0]
                    try:
                        index = int(field)
                    except ValueError:
                        raise MeshFileError(f"{option}: {path} line {number}: '{token.decode(errors='replace')}' "
                                            "is not a vertex index") from None
                    # OBJ indices count from 1; negative ones count back from the last vertex so far.
                    if index == 0 or index > vertices or -index > vertices:
                        raise MeshFileError(
                            f"{option}: {path} line {number}: face vertex {index} is out of range (the file has "
                            f"{vertices} vertices before that line); fix or re-export the file")


def _check_ply(option, path):
    try:
        data = ply.read(path)
    except ply.PlyError as exc:
        raise MeshFileError(f"{option}: {path}: {exc}") from None
    vertex = data.data.get("vertex")
    if vertex is None or not all(c in vertex and not isinstance(vertex[c], ply.List) for c in "xyz"):
        raise MeshFileError(f"{option}: {path}: the PLY file has no vertex element with x y z; {FIX}")
    xyz = np.stack([np.asarray(vertex[c], np.float64) for c in "xyz"], axis=1)
    finite = np.isfinite(xyz).all(axis=1)
    if not finite.all():
        i = int(np.argmin(finite))
        raise MeshFileError(f"{_where(option, path, data, 'vertex', i)}: vertex {i} is not finite "
                            f"({' '.join(f'{v:g}' for v in xyz[i])}); remove or fix it")
    if "face" in data.data:
        _check_ply_faces(option, path, data, len(xyz))


def _check_ply_faces(option, path, data, vertices):
    faces = data.data["face"]
    indices = faces.get("vertex_indices", faces.get("vertex_index"))
    if not isinstance(indices, ply.List) or indices.values.dtype.kind == "f":
        raise MeshFileError(f"{option}: {path}: the PLY faces have no integer list 'vertex_indices'; {FIX}")
    values = indices.values.astype(np.int64)
    bad = (values < 0) | (values >= vertices)
    if bad.any():
        k = int(np.argmax(bad))
        face = int(np.searchsorted(np.cumsum(indices.lengths), k, side="right"))
        raise MeshFileError(
            f"{_where(option, path, data, 'face', face)}: face {face} names vertex {values[k]}, which is out of "
            f"range (the file has {vertices} vertices, numbered from 0); {FIX}")


def _where(option, path, data, element, row):
    """'--mesh: PATH line N' for ASCII PLY, '--mesh: PATH' for binary."""
    lines = data.lines.get(element)
    return f"{option}: {path} line {lines[row]}" if lines is not None else f"{option}: {path}"


def _check_stl(option, path):
    size = os.path.getsize(path)
    with open(path, "rb") as f:
        head = f.read(84)
    count = struct.unpack("<I", head[80:84])[0] if len(head) == 84 else None
    if count is not None and size == 84 + 50 * count:
        rows = np.fromfile(path, np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]), count, offset=84)
        finite = np.isfinite(rows["v"]).all(axis=(1, 2))
        if not finite.all():
            i = int(np.argmin(finite))
            raise MeshFileError(f"{option}: {path}: triangle {i} has a vertex that is not finite; remove or fix it")
    elif head.lstrip().startswith(b"solid"):
        _check_ascii_stl(option, path, count, size)
    elif count is None:
        raise MeshFileError(f"{option}: {path}: {size} bytes is too short for a binary STL file and it is not "
                            f"an ASCII STL (it does not start with 'solid'); {FIX}")
    else:
        raise MeshFileError(f"{option}: {path}: a binary STL of {count} triangles has {84 + 50 * count} bytes, "
                            f"the file has {size}: it is cut short or its header is wrong; {FIX}")


def _check_ascii_stl(option, path, count, size):
    corners, triangles, number = None, 0, 0
    with open(path, "rb") as f:
        for number, line in enumerate(f, 1):
            words = line.split()
            key = words[0] if words else b""
            if key == b"outer":
                corners = 0
            elif key == b"vertex":
                try:
                    finite = len(words) == 4 and all(math.isfinite(float(t)) for t in words[1:])
                except ValueError:
                    finite = False
                if not finite:
                    raise MeshFileError(f"{option}: {path} line {number}: a vertex is not three finite numbers; "
                                        "remove or fix it")
                corners = (corners or 0) + 1
            elif key == b"endloop":
                if corners != 3:
                    raise MeshFileError(f"{option}: {path} line {number}: a facet has {corners or 0} vertices; an "
                                        f"STL facet is a triangle of three; {FIX}")
                triangles += 1
    if triangles == 0:
        also = f" nor a binary STL (that would be {84 + 50 * count} bytes, not {size})" if count is not None else ""
        raise MeshFileError(f"{option}: {path}: no triangles as an ASCII STL{also}; {FIX}")


def read_obj(option, path):
    """(vertices V by 3 float64 in the file's order, triangles F by 3 int32,
    polygons fanned) of an OBJ file, indices checked; loose vertices kept."""
    check_indices(option, path)
    vertices, triangles = [], []
    with open(path, "rb") as f:
        for line in f:
            if line.startswith(b"v "):
                vertices.append(line.split()[1:4])
            elif line.startswith(b"f "):
                n = len(vertices)
                idx = [int(t.split(b"/")[0]) for t in line.split()[1:]]
                idx = [i - 1 if i > 0 else n + i for i in idx]
                triangles += [(idx[0], idx[k], idx[k + 1]) for k in range(1, len(idx) - 1)]
    try:
        co = np.array(vertices, np.float64).reshape(-1, 3)
    except ValueError:
        raise MeshFileError(f"{option}: {path} has a vertex line ('v') without three numbers") from None
    return co, np.array(triangles, np.int32).reshape(-1, 3)


def write_obj(path, name, vertices, triangles):
    """An OBJ file of one object, coordinates as given (no axis conversion),
    with 9 significant digits: Blender's OBJ exporter writes 6 decimals, which
    turns a model a millionth of a unit across into a few grid points."""
    v = np.asarray(vertices, np.float64).reshape(-1, 3)
    f = np.asarray(triangles, np.int64).reshape(-1, 3) + 1
    with open(path, "w") as out:
        out.write(f"# exsynth\no {name}\n")
        np.savetxt(out, v, fmt="v %.9g %.9g %.9g")
        np.savetxt(out, f, fmt="f %d %d %d")



def write_textured_obj(obj_file, mtl_file, final, name, vertices, quads, corner_uvs, alpha=False):
    """A smooth-shaded quad mesh with per-corner UVs as OBJ + MTL, the
    material mapping the atlas (Kd; d too with alpha). `obj_file`/`mtl_file`
    are where to write now; `final` = (OBJ, MTL, atlas PNG) are the paths the
    files will have (outputs.OutputFiles renames them), which the files name,
    relative to the OBJ's folder."""
    final_obj, final_mtl, final_png = (os.path.abspath(p) for p in final)
    folder = os.path.dirname(final_obj)
    texture = os.path.relpath(final_png, folder)
    v = np.asarray(vertices, np.float64).reshape(-1, 3)
    q = np.asarray(quads, np.int64).reshape(-1, 4) + 1
    uv = np.asarray(corner_uvs, np.float64).reshape(-1, 2)
    t = np.arange(1, len(uv) + 1, dtype=np.int64).reshape(-1, 4)
    with open(mtl_file, "w") as out:
        out.write(f"# exsynth\nnewmtl {name}\nKd 1 1 1\nmap_Kd {texture}\n")
        if alpha:
            out.write(f"map_d {texture}\n")
    with open(obj_file, "w") as out:
        out.write(f"# exsynth\nmtllib {os.path.relpath(final_mtl, folder)}\no {name}\n")
        np.savetxt(out, v, fmt="v %.9g %.9g %.9g")
        np.savetxt(out, uv, fmt="vt %.9g %.9g")
        out.write(f"usemtl {name}\ns 1\n")
        np.savetxt(out, np.stack([q, t], axis=2).reshape(-1, 8), fmt="f %d/%d %d/%d %d/%d %d/%d")
