# SPDX-License-Identifier: GPL-3.0-or-later
"""Checks on mesh files that Blender's importers hide.

Blender's OBJ and PLY importers silently drop faces whose vertex indices are
out of range, so a broken file would give a mesh with holes and no word of
why. The headless jobs read the face indices themselves first (OBJ, ASCII
PLY; STL has no indices) and refuse such a file, naming the line.

The jobs write their result meshes themselves too (write_obj), at full
precision. The field job also reads OBJ files itself (read_obj): its output has one
row per vertex of the file, in the file's order, and Blender's OBJ importer
drops vertices that no face uses.

No bpy here.
"""

import math
import os

import numpy as np


class MeshFileError(ValueError):
    """The file is malformed; the message names the option, file and line."""


def check_indices(option, path):
    """Raise MeshFileError if a face of the OBJ or ASCII PLY file names a vertex
    it does not have, or (OBJ) a vertex is not three finite numbers."""
    lower = path.lower()
    if lower.endswith(".obj"):
        _check_obj(option, path)
    elif lower.endswith(".ply"):
        _check_ascii_ply(option, path)


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


def _check_ascii_ply(option, path):
    with open(path, "rb") as f:
        if f.readline().strip() != b"ply":
            return
        header, line_number = [], 1
        for line in f:
            line_number += 1
            header.append(line.split())
            if line.strip() == b"end_header":
                break
        if not any(h[:2] == [b"format", b"ascii"] for h in header):
            return  # binary PLY: Blender's importer is the only reader
        elements = [(h[1].decode(), int(h[2])) for h in header if h[:1] == [b"element"]]
        counts = dict(elements)
        vertices = counts.get("vertex", 0)
        for name, count in elements:
            for _ in range(count):
                line = f.readline()
                line_number += 1
                if name != "face":
                    continue
                try:
                    values = [int(t) for t in line.split()]
                except ValueError:
                    raise MeshFileError(f"{option}: {path} line {line_number}: a face must be a list of vertex "
                                        "indices") from None
                for index in values[1:1 + values[0]] if values else []:
                    if not 0 <= index < vertices:
                        raise MeshFileError(
                            f"{option}: {path} line {line_number}: face vertex {index} is out of range (the file "
                            f"has {vertices} vertices, numbered from 0); fix or re-export the file")


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
