# SPDX-License-Identifier: GPL-3.0-or-later
"""What the field overlay draws, free of bpy (pytest runs it without
Blender): short strokes along the field at a subset of the vertices, and
the places where the field is singular.

Singular means one of:
- undefined: a vertex whose vector is zero, not finite or not unit-ish;
- a vortex, source or saddle: a triangle around which the field turns by a
  whole turn (its discrete index, the sum of the angle steps between its
  corners' vectors in the triangle's plane, is a non-zero multiple of 2 pi);
- a clash: an edge whose two vectors point more than 90 degrees apart (where
  painted strokes meet head-on, or across a seam).
"""

import numpy as np

from .field_brush import normalized


def stroke_indices(n_vertices, max_strokes):
    """Every k-th vertex, k chosen so that at most `max_strokes` are drawn."""
    if max_strokes < 1:
        raise ValueError(f"max_strokes must be at least 1, got {max_strokes}")
    stride = max(1, -(-n_vertices // max_strokes))
    return np.arange(0, n_vertices, stride), stride


def mean_edge_length(vertices, triangles):
    v = np.asarray(vertices, np.float64)
    t = np.asarray(triangles, np.int64)
    if len(t) == 0:
        return 0.0
    e = np.concatenate([v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 1]], v[t[:, 0]] - v[t[:, 2]]])
    return float(np.mean(np.linalg.norm(e, axis=1)))


def strokes(vertices, normals, field, indices, length, lift):
    """Segments (2 k, 3) float32, tail then head for each drawn vertex, the
    tail at the vertex lifted by `lift` along its normal (so the surface does
    not hide it), the head `length` along the field. Undefined vectors are
    left out (they are marked as singular instead)."""
    f = np.asarray(field, np.float64)[indices]
    good = np.all(np.isfinite(f), axis=1) & (np.linalg.norm(f, axis=1) > 0.5)
    idx = np.asarray(indices)[good]
    tail = np.asarray(vertices, np.float64)[idx] + lift * np.asarray(normals, np.float64)[idx]
    head = tail + length * normalized(f[good])
    seg = np.empty((2 * len(idx), 3), np.float32)
    seg[0::2], seg[1::2] = tail, head
    return seg


def undefined_vertices(field):
    f = np.asarray(field, np.float64)
    finite = np.all(np.isfinite(f), axis=1)
    length = np.linalg.norm(np.where(finite[:, None], f, 0.0), axis=1)
    return np.nonzero(~finite | (length < 0.5))[0]


def triangle_indices(vertices, triangles, field):
    """The field's discrete index (turns, an integer) around each triangle."""
    v = np.asarray(vertices, np.float64)
    t = np.asarray(triangles, np.int64)
    f = np.nan_to_num(np.asarray(field, np.float64))
    p0, p1, p2 = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
    n = normalized(np.cross(p1 - p0, p2 - p0))
    e1 = normalized(p1 - p0)
    e2 = np.cross(n, e1)
    angles = []
    for k in range(3):
        fk = f[t[:, k]]
        angles.append(np.arctan2(np.sum(fk * e2, axis=1), np.sum(fk * e1, axis=1)))
    total = np.zeros(len(t))
    for k in range(3):
        step = angles[(k + 1) % 3] - angles[k]
        total += (step + np.pi) % (2.0 * np.pi) - np.pi  # wrapped into [-pi, pi)
    return np.rint(total / (2.0 * np.pi)).astype(np.int64)


def mesh_edges(triangles):
    """The unique edges (E, 2) of a triangle list, lower index first."""
    t = np.asarray(triangles, np.int64)
    e = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    if len(e) == 0:
        return e
    base = int(e.max()) + 1
    key = np.unique(e[:, 0] * base + e[:, 1])  # one int64 per edge: much faster than unique rows
    return np.stack([key // base, key % base], axis=1)


def clash_edges(edges, field, min_dot=0.0):
    """The edges (from mesh_edges) whose vectors have a dot product below `min_dot`."""
    e = np.asarray(edges, np.int64)
    f = normalized(np.nan_to_num(np.asarray(field, np.float64)))
    dots = np.sum(f[e[:, 0]] * f[e[:, 1]], axis=1)
    defined = np.any(f[e[:, 0]] != 0, axis=1) & np.any(f[e[:, 1]] != 0, axis=1)
    return e[defined & (dots < min_dot)]


def singular_points(vertices, triangles, field, normals, lift, edges=None):
    """(points (S, 3) float32 where the field is singular, clash points
    (C, 3) float32 at the middle of clashing edges), lifted off the surface."""
    v = np.asarray(vertices, np.float64)
    nrm = np.asarray(normals, np.float64)
    bad_v = undefined_vertices(field)
    pts = [v[bad_v] + lift * nrm[bad_v]]
    t = np.asarray(triangles, np.int64)
    if len(t):
        singular = t[triangle_indices(v, t, field) != 0]
        pts.append(v[singular].mean(axis=1) + lift * nrm[singular].mean(axis=1))
        clash = clash_edges(mesh_edges(t) if edges is None else edges, field)
        clash_pts = v[clash].mean(axis=1) + lift * nrm[clash].mean(axis=1)
    else:
        clash_pts = np.zeros((0, 3))
    return np.concatenate(pts).astype(np.float32), clash_pts.astype(np.float32)
