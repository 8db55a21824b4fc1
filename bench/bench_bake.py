#!/usr/bin/env python3
"""Baking a solid onto a surface: time and kept detail per interpolation.

A 128^3 solid synthesized from the bundled crackedground (seed 1) is baked
onto an oblique square (two triangles over the whole UV square, 1024^2
texels, 3.7 texels per voxel as on the demo cow's cut face; the solid
repeats) with
each of _native.INTERPOLATION_CHOICES, alternating, `--rounds` times each
(median seconds of bake_volume_to_uv, in process). Detail is read against
the same texels taken from their nearest voxel (what the solid holds, with
voxel blocks): the mean absolute difference of neighbouring texels' luminance
("gradient", grey levels) and the luminance's standard deviation, each as a
fraction of the nearest voxels' ("kept").

usage: bench_bake.py --build BUILD_DIR [--size 128] [--texels 1024] [--texels-per-voxel 3.7] [--rounds 3]
"""
import argparse
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXEMPLAR = os.path.join(ROOT, "assets", "textures", "crackedground.png")


def oblique_square(size, voxel_size, edge_voxels):
    """Two triangles of a square `edge_voxels` wide, tilted against every
    axis, and their UVs over [0, 1]^2; also the map from UV to position."""
    a = np.array([0.8, 0.5, 0.33])
    a /= np.linalg.norm(a)
    b = np.cross(a, [0.2, 0.3, 0.93])
    b /= np.linalg.norm(b)
    edge = edge_voxels * voxel_size
    o = np.array([0.31, 0.4, 0.47]) * size * voxel_size

    def at(u, v):
        return o + edge * (np.multiply.outer(u, a) + np.multiply.outer(v, b))

    corners = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float32)
    pos = at(corners[:, 0], corners[:, 1]).astype(np.float32)
    tris = [[0, 1, 2], [0, 2, 3]]
    return pos[tris], corners[tris], at


def detail(img):
    lum = img[..., :3] @ np.array([0.2126, 0.7152, 0.0722])
    return np.abs(np.diff(lum, axis=1)).mean() * 255, lum.std() * 255


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", required=True)
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--texels", type=int, default=1024)
    ap.add_argument("--texels-per-voxel", type=float, default=3.7)
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args(argv)
    sys.path.insert(0, os.path.join(args.build, "addon"))
    from PIL import Image
    from exsynth import _native

    ex = np.asarray(Image.open(EXEMPLAR).convert("RGB"))
    solid = _native.synthesize_solid(ex, size=args.size, seed=1)["solid"]
    if solid.max() > 1.5:
        solid = solid / 255.0
    h = 1.0 / args.size
    origin = np.full(3, 0.5 * h)
    pos, uvs, at = oblique_square(args.size, h, args.texels / args.texels_per_voxel)
    n = args.texels
    # The nearest voxel of each texel centre (row 0 at v = 0, as the bake).
    c = (np.arange(n) + 0.5) / n
    p = at(*np.meshgrid(c, c))
    idx = np.floor((p - origin) / h + 0.5).astype(int) % args.size
    nearest = solid[idx[..., 2], idx[..., 1], idx[..., 0]]
    g0, s0 = detail(nearest)

    print(f"machine: {os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}; {args.size}^3 solid from "
          f"{os.path.relpath(EXEMPLAR, ROOT)} baked at {n}^2 onto an oblique square "
          f"({args.texels_per_voxel:g} texels per voxel); median of {args.rounds} rounds, in process")
    header = f"{'interpolation':<14} {'bake s':>7} {'gradient':>9} {'kept':>6} {'std':>7} {'kept':>6}"
    print(header)
    print("-" * len(header))
    print(f"{'nearest voxel':<14} {'-':>7} {g0:>9.2f} {1.0:>6.2f} {s0:>7.2f} {1.0:>6.2f}")
    times = {m: [] for m in _native.INTERPOLATION_CHOICES}
    images = {}
    for _ in range(args.rounds):
        for m in _native.INTERPOLATION_CHOICES:
            t = time.perf_counter()
            img, mask = _native.bake_volume_to_uv(solid, origin, h, pos, uvs, n, n, margin=0, interpolation=m)
            times[m].append(time.perf_counter() - t)
            images[m] = img
    for m in _native.INTERPOLATION_CHOICES:
        g, s = detail(images[m])
        print(f"{m:<14} {np.median(times[m]):>7.3f} {g:>9.2f} {g / g0:>6.2f} {s:>7.2f} {s / s0:>6.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
