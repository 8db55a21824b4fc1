#!/usr/bin/env python3
"""Direction-field painting at the issue's size: one diffusion of a painted
stroke on a ~100 k-vertex mesh (the Armadillo subdivided once), and the
per-sample brush cost (numpy, exsynth.field_brush). Prints wall and CPU time.

usage: PYTHONPATH=build/addon /usr/bin/python3 bench/bench_paint.py
"""
import os
import sys
import time

import numpy as np

from exsynth import _native, field_brush, field_glyphs

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def load_obj(path):
    verts, faces = [], []
    with open(path) as f:
        for line in f:
            p = line.split()
            if not p:
                continue
            if p[0] == "v":
                verts.append([float(x) for x in p[1:4]])
            elif p[0] == "f":
                idx = [int(x.split("/")[0]) - 1 for x in p[1:]]
                faces += [[idx[0], idx[k], idx[k + 1]] for k in range(1, len(idx) - 1)]
    return np.array(verts, np.float64), np.array(faces, np.int64)


def subdivide(verts, tris):
    """1-to-4 midpoint subdivision."""
    edges = np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]])
    key = np.sort(edges, axis=1)
    uniq, inv = np.unique(key, axis=0, return_inverse=True)
    mid = len(verts) + inv.reshape(3, -1).T  # (F, 3): mids of edges 01, 12, 20
    out_v = np.concatenate([verts, 0.5 * (verts[uniq[:, 0]] + verts[uniq[:, 1]])])
    a, b, c = mid[:, 0], mid[:, 1], mid[:, 2]
    t = tris
    out_t = np.concatenate([np.stack([t[:, 0], a, c], 1), np.stack([t[:, 1], b, a], 1),
                            np.stack([t[:, 2], c, b], 1), np.stack([a, b, c], 1)])
    return out_v, out_t


def timed(fn, repeat=3):
    walls, cpus = [], []
    for _ in range(repeat):
        w0, c0 = time.perf_counter(), time.process_time()
        out = fn()
        walls.append(time.perf_counter() - w0)
        cpus.append(time.process_time() - c0)
    return out, float(np.median(walls)), float(np.median(cpus))


def main():
    verts, tris = subdivide(*load_obj(os.path.join(ROOT, "assets", "meshes", "armadillo.obj")))
    n = len(verts)
    print(f"mesh: Armadillo subdivided once, {n} vertices, {len(tris)} triangles; "
          f"load average {os.getloadavg()[0]:.1f}")
    # One stroke: the brush (radius 3 % of the size) dragged along 40 samples.
    size = float(np.ptp(verts, axis=0).max())
    radius = 0.03 * size
    normals = field_brush.vertex_normals(verts, tris)
    constraints = np.zeros((n, 3), np.float32)
    field = np.zeros((n, 3), np.float32)
    start = verts[np.argmax(verts[:, 1])]
    path = start + np.linspace(0.0, 0.3 * size, 40)[:, None] * np.array([1.0, 0.0, 0.0])
    path = verts[[int(np.argmin(np.sum((verts - p) ** 2, axis=1))) for p in path]]

    def stroke():
        c = constraints.copy()
        for k in range(1, len(path)):
            d = path[k] - path[k - 1]
            field_brush.apply_brush(c, field, verts, normals, path[k], radius, d, mode="PAINT")
        return c

    c, wall, cpu = timed(stroke)
    painted = int(np.count_nonzero(np.any(c != 0, axis=1)))
    print(f"brush: 40 samples, {painted} painted vertices: {1000 * wall / 40:.1f} ms wall, "
          f"{1000 * cpu / 40:.1f} ms CPU per sample")
    _, wall, cpu = timed(lambda: _native.diffuse_direction_field(verts, tris, c))
    print(f"diffusion of that stroke: {1000 * wall:.0f} ms wall, {1000 * cpu:.0f} ms CPU "
          f"(user+sys of this process, 2 threads); load average {os.getloadavg()[0]:.1f}")
    # The same stroke's share of the mesh on the original 26 k-vertex Armadillo.
    small_v, small_t = load_obj(os.path.join(ROOT, "assets", "meshes", "armadillo.obj"))
    small_c = np.zeros((len(small_v), 3))
    small_c[np.unique(np.argmin(np.linalg.norm(small_v[:, None] - verts[np.any(c != 0, axis=1)][None, :200], axis=2),
                                axis=0))] = (1.0, 0.0, 0.0)
    _, wall, cpu = timed(lambda: _native.diffuse_direction_field(small_v, small_t, small_c))
    print(f"diffusion on the original {len(small_v)}-vertex Armadillo: {1000 * wall:.0f} ms wall, {1000 * cpu:.0f} ms CPU")
    field = _native.diffuse_direction_field(verts, tris, c)
    edges = field_glyphs.mesh_edges(tris)

    def overlay():
        idx, spacing = field_glyphs.stroke_indices(verts, tris, 4000)
        seg = field_glyphs.strokes(verts, normals, field, idx, 0.8 * spacing, 0.0)
        return seg, field_glyphs.singular_points(verts, tris, field, normals, 0.0, edges=edges)

    (seg, (sing, clash)), wall, cpu = timed(overlay)
    print(f"overlay geometry (4000 strokes, singularities): {1000 * wall:.0f} ms wall, {1000 * cpu:.0f} ms CPU; "
          f"{len(seg) // 2} strokes, {len(sing)} singular, {len(clash)} clash points")
    f32 = field.astype(np.float32)
    _, wall, cpu = timed(lambda: hash(f32.tobytes()), repeat=10)
    print(f"per-draw change check (hash of the field): {1000 * wall:.1f} ms wall")
    return 0


if __name__ == "__main__":
    sys.exit(main())
