#!/usr/bin/env python3
"""Geometric texture on real closed meshes, as a user runs it: `./exsynth run
analogy --b MESH --preset P --resolution R --axis 0 1 0` with the defaults
(the pattern size fitted to the model), one process per run. Per mesh,
preset and resolution: the area and volume of B' over the input mesh's,
the same ratios for the input voxelized and meshed with no texture at the
resolution the job used (the calibration: what the grid alone does to the
model), the resolution used (a built-in pair raises it for its detail), the
fitted pattern size, wall time and peak memory. With --render DIR, also a
picture per mesh (bench/figure_geometry.py).

usage: bench_geometry.py [--meshes bunny cow armadillo] [--presets spikes grooves]
                         [--resolutions 128 256] [--out DIR] [--render DIR]
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MESHES = {name: os.path.join(ROOT, "assets", "meshes", f"{name}.obj") for name in ("bunny", "cow", "armadillo")}
# The targets of the analogy guide, per preset: (least area gain, volume band).
TARGETS = {"spikes": (0.25, None), "grooves": (0.05, 0.10)}


def read_obj(path):
    verts, tris = [], []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                verts.append([float(x) for x in line.split()[1:4]])
            elif line.startswith("f "):
                ids = [int(x.split("/")[0]) - 1 for x in line.split()[1:]]
                tris += [(ids[0], ids[k], ids[k + 1]) for k in range(1, len(ids) - 1)]
    return np.asarray(verts, np.float64), np.asarray(tris, np.int64)


def area_volume(path):
    v, t = read_obj(path)
    a, b, c = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum()
    volume = abs(np.einsum("ij,ij->i", a, np.cross(b, c)).sum()) / 6.0
    return area, volume


def run(args):
    """`./exsynth run ARGS`: (its output, wall seconds, peak RSS in MiB)."""
    t0 = time.perf_counter()
    proc = subprocess.Popen([os.path.join(ROOT, "exsynth"), "run", *args], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)
    text = proc.stdout.read()
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"./exsynth run {' '.join(args)} failed:\n{text[-2000:]}")
    return text, wall, usage.ru_maxrss / 1024.0


def pair_calibration(resolution=64):
    """What the built-in pairs do on their own (A -> A'), the ceiling for B': spikes' area gain over
    the slab's top face, grooves' area gain over the cylinder's side and their volume ratio."""
    sys.path.insert(0, os.path.join(ROOT, "build", "addon"))
    from exsynth import _native

    def area(mesh):
        v, t = np.asarray(mesh[0], np.float64), np.asarray(mesh[1])
        return 0.5 * np.linalg.norm(np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]]), axis=1).sum()

    h, out = 2.0 / resolution, {}
    for preset, covered in (("spikes", 4.0), ("grooves", 2 * np.pi * 0.6 * 2.0)):  # the top 2 x 2, the side
        pair = _native.make_exemplar_pair(preset, resolution=resolution)
        meshes = [_native.isosurface(pair[k], (-1.0 + h / 2,) * 3, h) for k in ("a", "a_prime")]
        out[preset] = ((area(meshes[1]) - area(meshes[0])) / covered,
                       float((pair["a_prime"] < 0).sum()) / float((pair["a"] < 0).sum()))
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--meshes", nargs="+", default=list(MESHES), choices=list(MESHES))
    ap.add_argument("--presets", nargs="+", default=list(TARGETS))
    ap.add_argument("--resolutions", nargs="+", type=int, default=[128, 256])
    ap.add_argument("--out", help="keep the outputs here (default: a temporary folder)")
    ap.add_argument("--render", help="render one picture per mesh into this folder")
    args = ap.parse_args(argv)
    out_dir = args.out or tempfile.mkdtemp(prefix="exsynth_geometry_")
    os.makedirs(out_dir, exist_ok=True)
    cal = pair_calibration()
    print(f"the pairs themselves at 64 voxels (the ceiling): spikes add {100 * cal['spikes'][0]:.0f} % of the "
          f"area they cover; grooves add {100 * cal['grooves'][0]:.0f} % and keep {cal['grooves'][1]:.2f} of the "
          "volume of their cylinder")
    print(f"{'mesh':<10} {'preset':<8} {'res':>4} {'used':>4} {'pattern':>8} {'area':>6} {'volume':>7} "
          f"{'grid area':>9} {'grid vol':>8} {'wall':>7} {'peak RSS':>9}  target")
    failed = 0
    for mesh in args.meshes:
        a0, v0 = area_volume(MESHES[mesh])
        for res in args.resolutions:
            for preset in args.presets:
                path = os.path.join(out_dir, f"{mesh}_{preset}_{res}.obj")
                text, wall, rss = run(["analogy", "--b", MESHES[mesh], "--preset", preset, "--resolution", str(res),
                                       "--axis", "0", "1", "0", "--out", path])
                m = re.search(r"pattern size ([\d.]+)", text)
                raised = re.search(r"resolution (\d+) \(--resolution", text)
                grid = int(raised.group(1)) if raised else res
                plain = os.path.join(out_dir, f"{mesh}_plain_{grid}.obj")
                if not os.path.exists(plain):
                    run(["voxelize", "--mesh", MESHES[mesh], "--resolution", str(grid), "--out",
                         os.path.join(out_dir, f"{mesh}_{grid}.npy"), "--mesh-out", plain])
                ga, gv = area_volume(plain)
                pa, pv = area_volume(path)
                gain, band = TARGETS.get(preset, (None, None))
                ok = (gain is None or pa / a0 >= 1 + gain) and (band is None or abs(pv / v0 - 1) <= band)
                failed += not ok
                want = "" if gain is None else f"area >= {1 + gain:.2f}" + (f", volume 1 ± {band:.2f}" if band else "")
                print(f"{mesh:<10} {preset:<8} {res:>4} {grid:>4} {m.group(1) if m else '?':>8} {pa / a0:>6.2f} "
                      f"{pv / v0:>7.2f} {ga / a0:>9.2f} {gv / v0:>8.2f} {wall:>6.1f}s {rss:>6.0f}MiB  {want}: "
                      f"{'met' if ok else 'NOT met'}", flush=True)
    if args.render:
        subprocess.run(["blender", "-b", "--factory-startup", "--python-exit-code", "1", "--python",
                        os.path.join(ROOT, "bench", "figure_geometry.py"), "--", out_dir, args.render,
                        *args.meshes], check=True, stdout=subprocess.DEVNULL)
        print(f"renders: {args.render}/geometry_<mesh>.png")
    print(f"outputs: {out_dir}; {failed} of the runs miss their target")
    return 0


if __name__ == "__main__":
    sys.exit(main())
