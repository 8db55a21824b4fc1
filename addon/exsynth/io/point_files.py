# SPDX-License-Identifier: GPL-3.0-or-later
"""Oriented point files (no bpy): read .ply (ASCII or binary, through io.ply,
vertex x y z nx ny nz), .xyz / .pwn (text, six numbers a line); write .ply
(binary) and .obj (v and vn lines). A mesh (.obj, .stl, a .ply without
normals) is refused with what to give instead.

Messages start with the file's path (the CLI puts the option in front)."""

import os

import numpy as np

from . import ply

POINT_EXTENSIONS = (".ply", ".xyz", ".pwn")
MESH_EXTENSIONS = (".obj", ".stl")
GIVE = ("give an oriented point set: a .ply with x y z nx ny nz per vertex, or a .xyz / .pwn of six numbers a "
        "line (x y z nx ny nz)")


class PointFileError(ValueError):
    """The file is not an oriented point set we can read; the message says why."""


def is_point_file(path):
    """Whether read_points should read the file: a point file, or a mesh it
    refuses with a clear message (not an image)."""
    return os.path.splitext(path)[1].lower() in POINT_EXTENSIONS + MESH_EXTENSIONS


def read_points(path):
    """(positions N by 3 float64, normals N by 3 float64) from a point file."""
    ext = os.path.splitext(path)[1].lower()
    if ext == ".ply":
        pos, nrm = _read_ply(path)
    elif ext in (".xyz", ".pwn"):
        pos, nrm = _read_text(path)
    elif ext in MESH_EXTENSIONS:
        raise PointFileError(f"{path}: a mesh ({ext}) has no per-point normals, it is not an oriented point set; "
                             + GIVE)
    else:
        raise PointFileError(f"{path}: unsupported point file '{ext}' (use .ply, .xyz or .pwn)")
    if len(pos) == 0:
        raise PointFileError(f"{path}: the file holds no points; " + GIVE)
    finite = np.isfinite(pos).all(axis=1) & np.isfinite(nrm).all(axis=1)
    if not finite.all():
        raise PointFileError(f"{path}: point {int(np.argmin(finite))} (of {len(pos)}) has a NaN or infinite "
                             "position or normal; remove or fix it")
    length = np.linalg.norm(nrm, axis=1)
    if np.any(length < 1e-8):
        raise PointFileError(f"{path}: point {int(np.argmax(length < 1e-8))} has a zero normal; every point needs "
                             "a direction")
    return pos.astype(np.float64), (nrm / length[:, None]).astype(np.float64)


def _read_text(path):
    with open(path, "rb") as f:
        rows = [(n, line.split()) for n, line in enumerate(f, 1) if line.strip() and not line.lstrip().startswith(b"#")]
    if not rows:
        return np.zeros((0, 3)), np.zeros((0, 3))
    n, words = min(rows, key=lambda r: len(r[1]))
    if len(words) < 6:
        raise PointFileError(f"{path} line {n}: {len(words)} numbers; an oriented point set needs six a line "
                             f"(x y z nx ny nz){': the file has no normals' if len(words) == 3 else ''}; " + GIVE)
    try:
        data = np.array([w[:6] for _, w in rows], np.float64)
    except ValueError:
        n, word = next((n, x) for n, w in rows for x in w[:6] if not ply._is_number(x))
        raise PointFileError(f"{path} line {n}: '{word.decode('ascii', 'replace')}' is not a number; fix or "
                             "re-export the file") from None
    return data[:, :3], data[:, 3:6]


def _read_ply(path):
    try:
        data = ply.read(path)
    except ply.PlyError as exc:
        raise PointFileError(f"{path}: {exc}") from None
    vertex = data.data.get("vertex", {})
    faces = data.element("face").count if data.element("face") else 0
    for names, what in (("xyz", "no positions (x y z)"), (("nx", "ny", "nz"), "no normals (nx ny nz)")):
        if not all(c in vertex for c in names):
            mesh = f"a mesh ({faces} faces) whose vertices have " if faces else "its vertices have "
            raise PointFileError(f"{path}: {mesh}{what}, it is not an oriented point set; " + GIVE)
        if any(isinstance(vertex[c], ply.List) for c in names):
            raise PointFileError(f"{path}: the vertices' {' '.join(names)} are lists, not numbers; " + GIVE)
    pos = np.stack([np.asarray(vertex[c], np.float64) for c in "xyz"], axis=1)
    nrm = np.stack([np.asarray(vertex[c], np.float64) for c in ("nx", "ny", "nz")], axis=1)
    return pos, nrm


def write_points(path, positions, normals):
    """Write an oriented point set; the format follows the extension (.ply or .obj)."""
    pos = np.ascontiguousarray(positions, np.float32)
    nrm = np.ascontiguousarray(normals, np.float32)
    ext = os.path.splitext(path)[1].lower()
    tmp = path + ".part"  # no partial output file under the real name
    try:
        if ext == ".ply":
            rows = np.empty(len(pos), dtype=[(c, "<f4") for c in ("x", "y", "z", "nx", "ny", "nz")])
            for i, c in enumerate("xyz"):
                rows[c] = pos[:, i]
                rows["n" + c] = nrm[:, i]
            header = ("ply\nformat binary_little_endian 1.0\ncomment exsynth point texture\n"
                      f"element vertex {len(pos)}\n" + "".join(f"property float {c}\n" for c in rows.dtype.names)
                      + "end_header\n")
            with open(tmp, "wb") as f:
                f.write(header.encode("ascii"))
                f.write(rows.tobytes())
        elif ext == ".obj":
            with open(tmp, "w") as f:
                f.write("# exsynth point texture: points (v) with normals (vn)\n")
                np.savetxt(f, pos, fmt="v %.6f %.6f %.6f")
                np.savetxt(f, nrm, fmt="vn %.6f %.6f %.6f")
        else:
            raise PointFileError(f"{path}: unsupported output '{ext}' (use .ply or .obj)")
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)
