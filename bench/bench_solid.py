#!/usr/bin/env python3
"""Solid and 2D texture synthesis benchmarks on the bundled exemplars.

Each case runs in its own process (so its peak RSS is its own) and prints
one table row: wall time, peak memory and the final texture energy (mean
|s - e|^0.8 per matched 8x8 neighbourhood, lower = closer to the exemplar),
so speed and quality are read together. The coordinates rows' energy is
another unit (the last correction pass's mean crossbar cost in appearance
space); "cpu s" is the whole process's user+sys.

usage: bench_solid.py --build BUILD_DIR [--cases solid128,solid128_unturned,solid128_t0,solid128_brick,solid128_split,solid256,image256,coord64,coord128]
"""
import argparse
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXEMPLAR = os.path.join(ROOT, "assets", "textures", "crackedground.png")  # 128 x 128 RGB

CASES = {
    # name: (description, python statement producing `res` from `ex`)
    "solid128": ("solid 128^3 RGB, 3 levels", "res = _native.synthesize_solid(ex, size=128, levels=3, seed=1)"),
    # brick (gimp-data, 128^2 as in bench_quality.py): its plain values miss the histogram, so the
    # histogram-priced exemplar values run (crackedground's already match and take the plain pass)
    "solid128_brick": ("solid 128^3 RGB, brick (priced)",
                       "sys.path.insert(0, BENCH); from bench_quality import exemplar; ex = exemplar('brick'); "
                       "res = _native.synthesize_solid(ex, size=128, levels=3, seed=1)"),
    # the defaults before the fifteenth pass (docs/solid.md): feature threshold 0, the exemplar as given
    "solid128_t0": ("solid 128^3 RGB, threshold 0, unturned",
                    "res = _native.synthesize_solid(ex, size=128, levels=3, seed=1, feature_threshold=0.0, "
                    "rotate_exemplar='off')"),
    # crackedground's features are round, so the default turns it (rotate_exemplar='auto'); the
    # analysis runs on its four quarter turns, 4x the windows. Unturned, for the cost of the turns:
    "solid128_unturned": ("solid 128^3 RGB, unturned",
                          "res = _native.synthesize_solid(ex, size=128, levels=3, seed=1, rotate_exemplar='off')"),
    # structure_sigma (docs/solid.md, eighteenth pass): the finest level's mean as well, the split, the match
    "solid128_split": ("solid 128^3 RGB, structure_sigma 1.5",
                       "res = _native.synthesize_solid(ex, size=128, levels=3, seed=1, structure_sigma=1.5)"),
    # feature_scale (docs/solid.md, nineteenth pass): a wider feature channel, the same work otherwise
    "solid128_scale16": ("solid 128^3 RGB, feature_scale 16",
                         "res = _native.synthesize_solid(ex, size=128, levels=3, seed=1, feature_scale=16)"),
    "solid256": ("solid 256^3 RGB, 3 levels", "res = _native.synthesize_solid(ex, size=256, levels=3, seed=1)"),
    "image256": ("image 128^2 -> 256^2, 3 levels", "res = _native.synthesize_image(ex, width=256, height=256, seed=1)"),
    # method="coordinates" (exemplar coordinates; the solid rows above use the default method)
    "coord64": ("solid 64^3 RGB, coordinates", "res = _native.synthesize_solid(ex, size=64, seed=1, method='coordinates')"),
    "coord128": ("solid 128^3 RGB, coordinates", "res = _native.synthesize_solid(ex, size=128, seed=1, method='coordinates')"),
}
DEFAULT_CASES = "solid128,solid128_unturned,solid128_t0,solid128_brick,solid128_split,solid128_scale16,solid256,image256"


CHILD = """
import json, sys, time
BENCH = {bench!r}
import numpy as np
from PIL import Image
from exsynth import _native
ex = np.asarray(Image.open(sys.argv[1]).convert("RGB"))
t = time.perf_counter()
{stmt}
dt = time.perf_counter() - t
import resource
r = resource.getrusage(resource.RUSAGE_SELF)
print(json.dumps({{"seconds": dt, "energy": res["energy"][-1], "cpu": r.ru_utime + r.ru_stime}}))
"""


def run_case(build, stmt):
    env = dict(os.environ, PYTHONPATH=os.path.join(build, "addon"))
    proc = subprocess.Popen(["/usr/bin/python3", "-c", CHILD.format(stmt=stmt, bench=os.path.dirname(os.path.abspath(__file__))), EXEMPLAR],
                            stdout=subprocess.PIPE, env=env, text=True)
    out = proc.stdout.read()
    _, status, usage = os.wait4(proc.pid, 0)
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"benchmark case failed: {stmt}")
    return json.loads(out.strip().splitlines()[-1]), usage.ru_maxrss / 1024.0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--build", required=True)
    ap.add_argument("--cases", default=DEFAULT_CASES, help=f"comma-separated, of {', '.join(CASES)}")
    args = ap.parse_args(argv)
    sys.path.insert(0, os.path.join(args.build, "addon"))
    from exsynth import _native
    print(f"machine: {os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}; exemplar {os.path.relpath(EXEMPLAR, ROOT)}; "
          f"one process per row; solid method: {_native.SOLID_DEFAULT_METHOD} unless the row says otherwise")
    header = f"{'case':<34} {'seconds':>8} {'cpu s':>7} {'peak RSS':>10} {'energy':>8}"
    print(header)
    print("-" * len(header))
    for name in args.cases.split(","):
        desc, stmt = CASES[name]
        r, rss = run_case(args.build, stmt)
        print(f"{desc:<34} {r['seconds']:>8.2f} {r['cpu']:>7.2f} {rss:>7.0f}MiB {r['energy']:>8.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
