#!/usr/bin/env python3
"""Per-axis quality of solids: the x, y and z slices apart, and extrusion.

For each exemplar of bench_quality.py (128^2, seed 7 unless --seed): a solid
of --size^3 with the given options; prints, per axis, exsynth.quality's
nn_rel / sharpness / contrast / hist_emd (mean of --slices slices
perpendicular to that axis) and the fraction of voxels whose colour equals
their neighbour's one step along that axis (an extrusion along x shows as a
high x fraction; the optimiser's is ~0.05) and four steps along it (eq@4: the
coarsest level's repetition), then the mean over axes and the
synthesis's CPU time (user + sys of this process) with the load average.
With --oblique, also the same metrics on planes that cut the solid
obliquely (OBLIQUE: a y-plane turned about z, then about x; nearest voxel,
wrapping), as a mesh's surface does: per plane and their mean ("obl").

usage: bench_solid_axes.py --build BUILD [--size 64] [--exemplars a,b] [--options "method='coordinates'"] [--oblique]
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_quality import EXEMPLARS, TARGETS, exemplar, missed  # noqa: E402

KEYS = ("nn_rel", "sharpness", "contrast", "hist_emd")


def equal_fractions(vol, step=1):
    """Fraction of voxels equal (all channels) to their +step neighbour along x, y, z of a (Z, Y, X, C) volume."""
    vol = np.asarray(vol)
    if vol.ndim == 3:
        vol = vol[..., None]
    out = {}
    for name, ax in (("x", 2), ("y", 1), ("z", 0)):
        a = np.take(vol, range(step, vol.shape[ax]), axis=ax)
        b = np.take(vol, range(0, vol.shape[ax] - step), axis=ax)
        out[name] = float(np.mean(np.all(a == b, axis=-1)))
    return out


# Oblique planes: (turn about z, then about x, in degrees); the demo cow's cut
# box is turned by about (10, -8).
OBLIQUE = ((10, -8), (30, 20), (45, 35))


def oblique_plane(vol, about_z, about_x, offset):
    """An n x n plane through a (Z, Y, X, C) volume of edge n: the y = offset
    plane turned about z, then about x (degrees), sampled at the nearest voxel
    with wrapping (the solids tile)."""
    n = vol.shape[0]
    a, b = np.radians(about_z), np.radians(about_x)
    rz = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    rx = np.array([[1, 0, 0], [0, np.cos(b), -np.sin(b)], [0, np.sin(b), np.cos(b)]])
    r = rz @ rx
    s, t = np.meshgrid(np.arange(n), np.arange(n))
    p = np.array([0.0, offset, 0.0]) + s[..., None] * (r @ [1, 0, 0]) + t[..., None] * (r @ [0, 0, 1])
    i = np.floor(p).astype(int) % n
    return vol[i[..., 2], i[..., 1], i[..., 0]]


def oblique_metrics(quality, E, vol):
    """image_metrics per OBLIQUE plane (through the middle) and their mean."""
    vol = np.asarray(vol)
    if vol.ndim == 3:
        vol = vol[..., None]
    out = {}
    for k, (az, ax) in enumerate(OBLIQUE):
        out[f"{az},{ax}"] = quality.image_metrics(E, oblique_plane(vol, az, ax, vol.shape[0] // 2))
    out["obl"] = {key: float(np.mean([m[key] for m in out.values()])) for key in KEYS}
    return out


def met(m):
    """How many of issue 10's solid targets (bench_quality.TARGETS) m meets."""
    return len(TARGETS["solid"]) - len(missed("solid", m))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", required=True)
    ap.add_argument("--size", type=int, default=64)
    ap.add_argument("--slices", type=int, default=8)
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--exemplars", default=",".join(EXEMPLARS))
    ap.add_argument("--options", default="", help="engine options, e.g. \"method='coordinates'\"")
    ap.add_argument("--oblique", action="store_true", help="also the metrics on oblique planes")
    args = ap.parse_args(argv)
    sys.path.insert(0, os.path.join(args.build, "addon"))
    from exsynth import _native, quality

    opts = eval(f"dict({args.options})", {})  # noqa: S307 - a developer's command line
    print(f"{args.size}^3, seed {args.seed}, method {opts.get('method', _native.SOLID_DEFAULT_METHOD)}, "
          f"options: {args.options or 'default'}; load average at start {os.getloadavg()[0]:.1f}")
    print(f"{'exemplar':<14}{'axis':<5}" + "".join(f"{k:>10}" for k in KEYS) + f"{'equal':>8}{'eq@4':>8}{'CPU s':>8}")
    total_met, oblique_met, cpu_sum = 0, 0, 0.0
    for name in args.exemplars.split(","):
        ex = exemplar(name)
        t0 = os.times()
        vol = _native.synthesize_solid(ex, size=args.size, seed=args.seed, **opts)["solid"]
        t1 = os.times()
        cpu = (t1.user - t0.user) + (t1.system - t0.system)
        cpu_sum += cpu
        m = quality.volume_metrics(quality.Exemplar(ex), vol, slices=args.slices)
        eq = equal_fractions(vol)
        eq["mean"] = float(np.mean([eq[a] for a in "xyz"]))
        eq4 = equal_fractions(vol, 4)
        eq4["mean"] = float(np.mean([eq4[a] for a in "xyz"]))
        for axis in ("x", "y", "z", "mean"):
            print(f"{name if axis == 'x' else '':<14}{axis:<5}" + "".join(f"{m[axis][k]:>10.2f}" for k in KEYS) +
                  f"{eq[axis]:>8.3f}{eq4[axis]:>8.3f}" + (f"{cpu:>8.1f}" if axis == "mean" else ""))
        total_met += met(m["mean"])
        if args.oblique:
            ob = oblique_metrics(quality, quality.Exemplar(ex), vol)
            for plane, mo in ob.items():
                print(f"{'':<14}{plane:<5}", end="")
                print("".join(f"{mo[k]:>10.2f}" for k in KEYS))
            oblique_met += met(ob["obl"])
        sys.stdout.flush()
    if args.oblique:
        print(f"targets met by the oblique planes' means: {oblique_met} of {len(TARGETS['solid']) * len(args.exemplars.split(','))}")
    print(f"targets met by the means: {total_met} of {len(TARGETS['solid']) * len(args.exemplars.split(','))}; "
          f"CPU {cpu_sum:.1f} s; load average at end {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
