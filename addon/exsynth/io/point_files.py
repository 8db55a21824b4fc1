# SPDX-License-Identifier: GPL-3.0-or-later
"""Oriented point files (no bpy): read .ply (ASCII or binary little-endian,
vertex x y z nx ny nz), .xyz / .pwn (text, six numbers a line); write .ply
(binary) and .obj (v and vn lines)."""

import os

import numpy as np

_PLY_TYPES = {"char": "i1", "uchar": "u1", "int8": "i1", "uint8": "u1", "short": "i2", "ushort": "u2",
              "int16": "i2", "uint16": "u2", "int": "i4", "uint": "u4", "int32": "i4", "uint32": "u4",
              "float": "f4", "float32": "f4", "double": "f8", "float64": "f8"}


class PointFileError(ValueError):
    """The file is not an oriented point set we can read; the message says why."""


def read_points(path):
    """(positions N by 3 float64, normals N by 3 float64) from a point file."""
    ext = os.path.splitext(path)[1].lower()
    if ext == ".ply":
        pos, nrm = _read_ply(path)
    elif ext in (".xyz", ".pwn"):
        try:
            data = np.loadtxt(path, ndmin=2)
        except ValueError as exc:
            raise PointFileError(f"{path}: not a table of numbers ({exc})")
        if data.shape[1] < 6:
            raise PointFileError(f"{path}: {data.shape[1]} numbers a line; an oriented point set needs six "
                                 "(x y z nx ny nz): the file has no normals")
        pos, nrm = data[:, :3], data[:, 3:6]
    else:
        raise PointFileError(f"{path}: unsupported point file '{ext}' (use .ply, .xyz or .pwn)")
    if len(pos) == 0:
        raise PointFileError(f"{path}: the file holds no points")
    length = np.linalg.norm(nrm, axis=1)
    if not np.all(np.isfinite(pos)) or not np.all(np.isfinite(nrm)):
        raise PointFileError(f"{path}: some positions or normals are NaN or infinite")
    if np.any(length < 1e-8):
        raise PointFileError(f"{path}: some normals are zero; every point needs a direction")
    return pos.astype(np.float64), (nrm / length[:, None]).astype(np.float64)


def _read_ply(path):
    with open(path, "rb") as f:
        if f.readline().strip() != b"ply":
            raise PointFileError(f"{path}: not a PLY file")
        fmt, elements, current = None, [], None
        while True:
            line = f.readline()
            if not line:
                raise PointFileError(f"{path}: the PLY header has no end_header")
            words = line.decode("ascii", "replace").split()
            if not words:
                continue
            if words[0] == "format":
                fmt = words[1]
            elif words[0] == "element":
                current = [words[1], int(words[2]), []]
                elements.append(current)
            elif words[0] == "property":
                if words[1] == "list":
                    current[2].append((words[4], None, (words[2], words[3])))
                else:
                    current[2].append((words[2], _PLY_TYPES[words[1]], None))
            elif words[0] == "end_header":
                break
        if not elements or elements[0][0] != "vertex":
            raise PointFileError(f"{path}: the PLY file's first element is not 'vertex'")
        name, count, props = elements[0]
        names = [p[0] for p in props]
        if not {"x", "y", "z"} <= set(names):
            raise PointFileError(f"{path}: the PLY vertices have no x y z")
        if not {"nx", "ny", "nz"} <= set(names):
            raise PointFileError(f"{path}: the PLY vertices have no normals (nx ny nz); an oriented point set "
                                 "is needed: export with normals")
        if any(p[1] is None for p in props):
            raise PointFileError(f"{path}: list properties on PLY vertices are not supported")
        if fmt == "ascii":
            data = np.loadtxt(f, max_rows=count, ndmin=2)
            cols = {n: data[:, i] for i, n in enumerate(names)}
        elif fmt in ("binary_little_endian", "binary_big_endian"):
            end = "<" if fmt == "binary_little_endian" else ">"
            dtype = np.dtype([(n, end + t) for n, t, _ in props])
            data = np.frombuffer(f.read(dtype.itemsize * count), dtype=dtype, count=count)
            cols = {n: data[n].astype(np.float64) for n in names}
        else:
            raise PointFileError(f"{path}: unknown PLY format '{fmt}'")
    pos = np.stack([cols["x"], cols["y"], cols["z"]], axis=1)
    nrm = np.stack([cols["nx"], cols["ny"], cols["nz"]], axis=1)
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
