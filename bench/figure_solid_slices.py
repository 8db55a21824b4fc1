#!/usr/bin/env python3
"""Middle slices of solids beside their exemplar, for docs/solid.md.

Per exemplar of bench_quality.py (128^2, seed 7 unless --seed) one row: the
exemplar's top-left size x size texels, then the z, y and x slices through
the middle of a size^3 solid synthesized with --options, each enlarged
--zoom times (nearest neighbour), into OUT.png. With --oblique, the three
oblique planes of bench_solid_axes.py (through the middle) instead of the
axis slices.

usage: figure_solid_slices.py --build BUILD --out OUT.png [--exemplars crackedground,stone33]
                              [--options "method='coordinates'"] [--size 64] [--zoom 3] [--oblique]
"""
import argparse
import os
import sys

import numpy as np
from PIL import Image

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_quality import exemplar  # noqa: E402
from bench_solid_axes import OBLIQUE, oblique_plane  # noqa: E402


def to_rgb8(a):
    a = np.asarray(a, np.float32)
    if a.max() <= 1.0 + 1e-6:
        a = a * 255.0
    return np.clip(a + 0.5, 0, 255).astype(np.uint8)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--exemplars", default="crackedground,stone33")
    ap.add_argument("--options", default="method='coordinates'")
    ap.add_argument("--size", type=int, default=64)
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--zoom", type=int, default=3)
    ap.add_argument("--oblique", action="store_true", help="oblique planes instead of the axis slices")
    args = ap.parse_args(argv)
    sys.path.insert(0, os.path.join(args.build, "addon"))
    from exsynth import _native

    opts = eval(f"dict({args.options})", {})  # noqa: S307 - a developer's command line
    n, gap = args.size, 4
    rows = []
    for name in args.exemplars.split(","):
        ex = exemplar(name)
        vol = to_rgb8(_native.synthesize_solid(ex, size=n, seed=args.seed, **opts)["solid"])  # (z, y, x, c)
        m = n // 2
        if args.oblique:
            tiles = [ex[:n, :n]] + [oblique_plane(vol, az, ax, m) for az, ax in OBLIQUE]
        else:
            tiles = [ex[:n, :n], vol[m], vol[:, m], vol[:, :, m]]  # exemplar, z-, y-, x-slice
        row = np.full((n, 4 * n + 3 * gap, 3), 255, np.uint8)
        for k, t in enumerate(tiles):
            row[:, k * (n + gap):k * (n + gap) + n] = t[..., :3]
        rows.append(row)
    sheet = np.full((len(rows) * n + (len(rows) - 1) * gap, rows[0].shape[1], 3), 255, np.uint8)
    for k, r in enumerate(rows):
        sheet[k * (n + gap):k * (n + gap) + n] = r
    img = Image.fromarray(sheet)
    img.resize((img.width * args.zoom, img.height * args.zoom), Image.NEAREST).save(args.out)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
