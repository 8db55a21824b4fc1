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

usage: bench_solid_axes.py --build BUILD [--size 64] [--exemplars a,b] [--options "method='coordinates'"]
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_quality import EXEMPLARS, exemplar  # noqa: E402

KEYS = ("nn_rel", "sharpness", "contrast", "hist_emd")
TARGETS = {"nn_rel": (0.35, -1), "sharpness": (0.85, 1), "contrast": (0.85, 1), "hist_emd": (4.0, -1)}


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


def met(m):
    return sum(1 for k, (t, s) in TARGETS.items() if (m[k] - t) * s >= 0)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", required=True)
    ap.add_argument("--size", type=int, default=64)
    ap.add_argument("--slices", type=int, default=8)
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--exemplars", default=",".join(EXEMPLARS))
    ap.add_argument("--options", default="", help="engine options, e.g. \"method='coordinates'\"")
    args = ap.parse_args(argv)
    sys.path.insert(0, os.path.join(args.build, "addon"))
    from exsynth import _native, quality

    opts = eval(f"dict({args.options})", {})  # noqa: S307 - a developer's command line
    print(f"{args.size}^3, seed {args.seed}, method {opts.get('method', _native.SOLID_DEFAULT_METHOD)}, "
          f"options: {args.options or 'default'}; load average at start {os.getloadavg()[0]:.1f}")
    print(f"{'exemplar':<14}{'axis':<5}" + "".join(f"{k:>10}" for k in KEYS) + f"{'equal':>8}{'eq@4':>8}{'CPU s':>8}")
    total_met, cpu_sum = 0, 0.0
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
        sys.stdout.flush()
    print(f"targets met by the means: {total_met} of {4 * len(args.exemplars.split(','))}; "
          f"CPU {cpu_sum:.1f} s; load average at end {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
