# SPDX-License-Identifier: GPL-3.0-or-later
"""The math of painting a direction field, free of bpy (pytest runs it
without Blender): a stroke sample's screen direction turned into a tangent at
the hit, the brush falloff, mirror symmetry, and what Paint, Erase and Comb
do to the painted constraints. The diffusion of the constraints into a field
is the engine's (`_native.diffuse_direction_field`).

Arrays: positions and vectors are (V, 3); constraints are float32 (V, 3)
with zero meaning "free" (the engine's convention), non-zero a unit
direction.
"""

import numpy as np

MODES = ("PAINT", "ERASE", "COMB")
# Comb bends a direction by at most this much of the stroke's direction per
# sample at the brush centre: a drag of ~10 samples turns it fully.
COMB_RATE = 0.35
# Below this |cos| between the view ray and the surface normal (grazing, about
# 84 degrees), projecting along the view ray stretches a tiny screen motion
# into a long tangent of uncertain direction: project orthogonally instead.
GRAZING_COS = 0.1


def normalized(v, eps=1e-12):
    """Rows scaled to unit length; rows shorter than eps become zero."""
    v = np.asarray(v, np.float64)
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return np.where(n > eps, v / np.maximum(n, eps), 0.0)


def vertex_normals(vertices, triangles):
    """Unit area-weighted vertex normals (as the engine's field uses);
    vertices without area get a zero normal."""
    v = np.asarray(vertices, np.float64)
    t = np.asarray(triangles, np.int64)
    face = np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]])
    corners = t.ravel()  # each face's cross product goes to its three corners
    faces3 = np.repeat(face, 3, axis=0)
    n = np.stack([np.bincount(corners, faces3[:, k], minlength=len(v)) for k in range(3)], axis=1)
    return normalized(n)


def tangent_from_view(view_delta, normal, view_dir):
    """The unit tangent at a hit whose screen image runs along a stroke.

    view_delta: the stroke's screen motion as a 3D vector in the view plane at
    the hit's depth; normal: the surface normal at the hit; view_dir: the view
    ray's direction there. The tangent is the motion carried along the view
    ray into the tangent plane (so it projects back onto the stroke on screen);
    at grazing angles it is the orthogonal projection. Zero when the motion is
    zero or along the normal.
    """
    w = np.asarray(view_delta, np.float64)
    n = normalized(normal)
    v = normalized(view_dir)
    vn = float(np.dot(v, n))
    if abs(vn) > GRAZING_COS:
        t = w - v * (np.dot(w, n) / vn)
    else:
        t = w - n * np.dot(w, n)
    return normalized(t)


def falloff(distance, radius):
    """Brush weight in [0, 1]: 1 at the centre, a smooth (1 - (d/r)^2)^2
    fall to 0 at the radius (zero slope there), 0 outside."""
    if not np.isfinite(radius) or radius <= 0:
        raise ValueError(f"the brush radius must be a positive number, got {radius}")
    q = np.clip(1.0 - (np.asarray(distance, np.float64) / radius) ** 2, 0.0, 1.0)
    return q * q


def mirror(points, vectors, axis):
    """Points and vectors reflected across the plane through the origin
    normal to coordinate `axis` (0, 1, 2: local X, Y, Z)."""
    if axis not in (0, 1, 2):
        raise ValueError(f"the mirror axis must be 0, 1 or 2 (X, Y, Z), got {axis!r}")
    p = np.array(points, np.float64, copy=True)
    d = np.array(vectors, np.float64, copy=True)
    p[..., axis] *= -1.0
    d[..., axis] *= -1.0
    return p, d


def mirrored_samples(point, direction, axes):
    """The sample and its mirror images across every combination of the
    enabled axes (X and Y give 4 samples, X, Y and Z 8)."""
    samples = [(np.asarray(point, np.float64), np.asarray(direction, np.float64))]
    for axis in sorted(set(axes)):
        samples += [mirror(p, d, axis) for p, d in samples]
    return samples


def project_tangent(direction, normals):
    """`direction` (3,) projected into each row's tangent plane, unit rows
    (zero where it is along the normal)."""
    d = np.asarray(direction, np.float64)
    n = np.asarray(normals, np.float64)
    return normalized(d[None, :] - n * (n @ d)[:, None], eps=1e-6)


def apply_brush(constraints, field, positions, normals, centre, radius, direction, mode="PAINT", strength=1.0):
    """One stroke sample, in place on `constraints`; returns the indices it changed.

    positions / centre / radius: where the brush reaches (one space, e.g.
    world, so that distances are true); direction (3,), normals and the
    constraints and field vectors: the mesh's own space. `field` may be None
    (no field yet). Modes:
      PAINT: a free vertex takes the stroke's direction; a painted one turns
        towards it by the falloff weight (fully at the centre, barely at the
        rim), so crossing strokes join smoothly. The diffused field is not
        used: copying it into constraints at the rim would pin the old field
        right next to the stroke and stop the stroke from spreading.
      ERASE: frees every vertex within the radius (a constraint is there or
        not, so no falloff).
      COMB: adds COMB_RATE x weight x the stroke direction to the current
        direction each sample, dragging existing directions along the stroke.
    """
    if mode not in MODES:
        raise ValueError(f"mode must be one of {', '.join(MODES)}, got {mode!r}")
    if not np.isfinite(strength) or not 0.0 < strength <= 1.0:
        raise ValueError(f"the brush strength must be in (0, 1], got {strength}")
    d2 = np.sum((np.asarray(positions, np.float64) - np.asarray(centre, np.float64)) ** 2, axis=1)
    weight = falloff(np.sqrt(d2), radius)
    idx = np.nonzero(weight > 0.0)[0]
    if len(idx) == 0:
        return idx
    if mode == "ERASE":
        idx = idx[np.any(constraints[idx] != 0.0, axis=1)]
        constraints[idx] = 0.0
        return idx
    t = project_tangent(direction, np.asarray(normals)[idx])
    ok = np.any(t != 0.0, axis=1)
    idx, t, w = idx[ok], t[ok], strength * weight[idx[ok]]
    current = normalized(constraints[idx])
    if field is not None and mode == "COMB":
        free = ~np.any(current != 0.0, axis=1)
        current[free] = normalized(np.asarray(field, np.float64)[idx[free]])
    unknown = ~np.any(current != 0.0, axis=1)  # nothing to turn: take the stroke's
    current[unknown] = t[unknown]
    if mode == "PAINT":
        new = (1.0 - w)[:, None] * current + w[:, None] * t
    else:
        new = current + (COMB_RATE * w)[:, None] * t
    new = normalized(new)
    cancelled = ~np.any(new != 0.0, axis=1)  # exactly opposite, half-way: the stroke wins
    new[cancelled] = t[cancelled]
    constraints[idx] = new.astype(constraints.dtype)
    return idx


def has_constraints(constraints):
    return bool(np.any(constraints != 0.0))
