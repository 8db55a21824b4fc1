# SPDX-License-Identifier: GPL-3.0-or-later
"""What the field overlay draws, free of bpy (pytest runs it without
Blender): short strokes along the field at a subset of the vertices, and
the places where the field is singular.

Singular means one of:
- undefined: a vertex whose vector is zero, not finite or not unit-ish;
- a vortex, source, sink or saddle: a vertex around whose one-ring the field
  turns by a whole turn (its discrete index, see vertex_indices);
- a clash: an edge whose two vectors point more than 90 degrees apart (where
  painted strokes meet head-on, or across a seam).
"""

import numpy as np

from .field_brush import normalized


def stroke_indices(vertices, triangles, max_strokes):
    """About `max_strokes` vertices spread evenly over the surface, and their
    spacing: one vertex per cell of a grid whose cell area is the surface's
    area over `max_strokes` (every n-th vertex instead would crowd strokes
    where the mesh is dense, e.g. at a UV sphere's poles). At most
    `max_strokes`: extra cells are thinned by taking every k-th."""
    if max_strokes < 1:
        raise ValueError(f"max_strokes must be at least 1, got {max_strokes}")
    v = np.asarray(vertices, np.float64)
    t = np.asarray(triangles, np.int64)
    if len(v) == 0:
        return np.zeros(0, np.int64), 0.0
    area = 0.5 * np.linalg.norm(np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]]), axis=1).sum()
    if area <= 0:
        return np.arange(0, len(v), max(1, -(-len(v) // max_strokes))), 0.0
    spacing = float(np.sqrt(area / max_strokes))
    cells = np.floor((v - v.min(axis=0)) / spacing).astype(np.int64)
    dims = cells.max(axis=0) + 1
    key = (cells[:, 0] * dims[1] + cells[:, 1]) * dims[2] + cells[:, 2]  # one int64 per cell: fast unique
    _, first = np.unique(key, return_index=True)
    idx = np.sort(first)
    if len(idx) > max_strokes:
        idx = idx[:: -(-len(idx) // max_strokes)]
    return idx, spacing


def mean_edge_length(vertices, triangles):
    v = np.asarray(vertices, np.float64)
    t = np.asarray(triangles, np.int64)
    if len(t) == 0:
        return 0.0
    e = np.concatenate([v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 1]], v[t[:, 0]] - v[t[:, 2]]])
    return float(np.mean(np.linalg.norm(e, axis=1)))


def drawable(field, indices):
    """The indices whose vectors can be drawn (finite, unit-ish); the others
    are marked as singular instead."""
    f = np.asarray(field, np.float64)[indices]
    good = np.all(np.isfinite(f), axis=1) & (np.linalg.norm(np.nan_to_num(f), axis=1) > 0.5)
    return np.asarray(indices)[good]


def strokes(vertices, normals, field, indices, length, lift):
    """Segments (2 k, 3) float32, tail then head for each drawable vertex of
    `indices`, the tail at the vertex lifted by `lift` along its normal (so
    the surface does not hide it), the head `length` along the field."""
    return drawable_strokes(vertices, normals, field, drawable(field, indices), length, lift)


def drawable_strokes(vertices, normals, field, idx, length, lift):
    """`strokes` for indices already filtered by `drawable`."""
    tail = np.asarray(vertices, np.float64)[idx] + lift * np.asarray(normals, np.float64)[idx]
    head = tail + length * normalized(np.asarray(field, np.float64)[idx])
    seg = np.empty((2 * len(idx), 3), np.float32)
    seg[0::2], seg[1::2] = tail, head
    return seg


def facing(points, normals, eye=None, toward_viewer=None):
    """Which points face the viewer: the eye's position for a perspective
    view, else the direction toward the viewer (orthographic), both in the
    points' space. The depth test hides marks on the far side of a model,
    except those just behind its silhouette, whose tangent strokes stick out
    past the rim; this test leaves those out."""
    p = np.asarray(points, np.float64).reshape(-1, 3)
    n = np.asarray(normals, np.float64).reshape(-1, 3)
    to_viewer = np.asarray(eye, np.float64) - p if eye is not None else np.asarray(toward_viewer, np.float64)
    return np.sum(n * to_viewer, axis=-1) > 0


def undefined_vertices(field):
    f = np.asarray(field, np.float64)
    finite = np.all(np.isfinite(f), axis=1)
    length = np.linalg.norm(np.where(finite[:, None], f, 0.0), axis=1)
    return np.nonzero(~finite | (length < 0.5))[0]


def vertex_indices(triangles, field, normals):
    """The field's winding (turns, an integer) around each vertex's one-ring.

    For each triangle (a, b, c) the step from b's vector to c's is measured in
    a's tangent plane and added to a; summed over a's fan this is how often the
    field turns going once around a. Measuring every step of a ring in one
    plane (the vertex's) makes the sum an exact multiple of a turn whatever
    the vertex's own vector is, so a singularity sitting on a vertex (a
    preset's pole on a symmetric mesh) is found as surely as one inside a
    triangle (whose three corners all see it). Open rings (boundary vertices)
    do not close: they count only when the sum is within a quarter turn of
    a whole one.
    """
    t = np.asarray(triangles, np.int64)
    f = np.nan_to_num(np.asarray(field, np.float64))
    n = np.asarray(normals, np.float64)
    total = np.zeros(len(n))
    for k in range(3):
        a, b, c = t[:, k], t[:, (k + 1) % 3], t[:, (k + 2) % 3]
        fb, fc, na = f[b], f[c], n[a]
        # The signed angle from b's vector to c's, both projected into a's
        # tangent plane: atan2(n . (fb x fc), pb . pc), in (-pi, pi].
        nb, nc = np.einsum("ij,ij->i", fb, na), np.einsum("ij,ij->i", fc, na)
        step = np.arctan2(np.einsum("ij,ij->i", np.cross(fb, fc), na), np.einsum("ij,ij->i", fb, fc) - nb * nc)
        total += np.bincount(a, step, minlength=len(n))
    turns = total / (2.0 * np.pi)
    index = np.rint(turns).astype(np.int64)
    index[np.abs(turns - index) > 0.25] = 0
    return index


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
    """Where the field is singular, lifted off the surface: a dict of
    'singular' (S, 3) float32 points at undefined and singular vertices,
    'clashes' (C, 3) at the middle of clashing edges, and the surface
    normals there ('singular_normals', 'clash_normals')."""
    v = np.asarray(vertices, np.float64)
    nrm = np.asarray(normals, np.float64)
    t = np.asarray(triangles, np.int64)
    at = [undefined_vertices(field)]
    clash = np.zeros((0, 2), np.int64)
    if len(t):
        at.append(np.nonzero(vertex_indices(t, field, nrm) != 0)[0])
        clash = clash_edges(mesh_edges(t) if edges is None else edges, field)
    at = np.concatenate(at)
    clash_normals = nrm[clash].mean(axis=1)
    return {"singular": (v[at] + lift * nrm[at]).astype(np.float32), "singular_normals": nrm[at].astype(np.float32),
            "clashes": (v[clash].mean(axis=1) + lift * clash_normals).astype(np.float32),
            "clash_normals": clash_normals.astype(np.float32)}
