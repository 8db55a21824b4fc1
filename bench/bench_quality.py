#!/usr/bin/env python3
"""Quality benchmark of solid and 2D synthesis on real exemplars, with peers.

For each exemplar (128^2, resampled with Lanczos from the source listed
below): a 64^3 solid (and with --full a 128^3 one), a 256^2 image, and the
peer G'MIC `syntexturize_matchpatch 256,256` on the same exemplar, all with
default options and seed 7. The numbers are exsynth.quality's (see its
docstring: nn_rel, sharpness, contrast, hist_emd, copy_rate, max_copy_frac,
speckle, elongation; speckle above 1 = lone-pixel noise the sharpness counts as
detail); solids are the mean over x, y and z slices, but their
elongation is measured in 3D (1 = features as long for their width as the
exemplar's; above 1 stretched one way, as parallel sheets or tubes; below 1
the exemplar's long features, veins or courses, lost). Then which of issue
10's targets each kind of output meets (the peer's rows against the image
targets, for comparison). Then speed: whole-process time
for 128^2 -> 256^2 (the Python module vs the gmic command, alternating in
the same run, median of 3) and a 128^3 RGB solid.

Exemplar sources: assets/textures (bundled), the Debian packages gimp-data
(/usr/share/gimp/2.0/patterns) and assimp-testmodels (/usr/share/assimp).

Then a calibration of nn_rel ("the texture itself"): each exemplar's right
half scored against its left half, beside syntheses from that left half (a
128^2 image, G'MIC's, a 64^3 solid): an unseen piece of the same texture is
the score a synthesis that does not copy can hope for.

usage: bench_quality.py --build BUILD_DIR [--full] [--exemplars a,b] [--no-peers] [--no-calibration]
                       [--options 'k=v, ...'] [--image-options 'k=v, ...']
"""
import argparse
import os
import resource
import shutil
import struct
import subprocess
import sys
import tempfile
import time

import numpy as np
from PIL import Image

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TEX = os.path.join(ROOT, "assets", "textures")
GIMP = "/usr/share/gimp/2.0/patterns"
ASSIMP = "/usr/share/assimp/models"
EXEMPLARS = {  # name: source
    "crackedground": os.path.join(TEX, "crackedground.png"),
    "drkwood2": os.path.join(TEX, "drkwood2.png"),
    "marble1": os.path.join(TEX, "marble1.png"),
    "granite1": os.path.join(TEX, "granite1.png"),
    "stone33": os.path.join(GIMP, "Stone", "stone33.pat"),
    "brick": os.path.join(GIMP, "Stone", "brick.pat"),
    "slate": os.path.join(GIMP, "Stone", "slate.pat"),
    "brownground": os.path.join(ASSIMP, "IRRMesh", "brownground_1-1.jpg"),
}
SOLID_ONLY = ("method", "coordinate_coherence_k")  # options synthesize_image does not take
KEYS = ("nn_rel", "sharpness", "contrast", "hist_emd", "copy_rate", "max_copy_frac", "speckle", "elongation")
# Issue 10's targets, per kind of output: (key, "min" | "max", bound).
TARGETS = {
    "solid": (("sharpness", "min", 0.85), ("contrast", "min", 0.85), ("hist_emd", "max", 4.0), ("nn_rel", "max", 0.35)),
    "image": (("sharpness", "min", 0.9), ("nn_rel", "max", 0.20), ("copy_rate", "max", 0.35),
              ("max_copy_frac", "max", 0.25)),
}
WORST = {"nn_rel": max, "speckle": max, "hist_emd": max, "copy_rate": max, "max_copy_frac": max, "sharpness": min, "contrast": min,
         "elongation": lambda v: max(v, key=lambda e: abs(np.log(e)))}  # farthest from 1 either way


def read_pat(path):
    """A GIMP .pat pattern (header, then raw 8-bit pixels) as (H, W, 3) uint8."""
    data = open(path, "rb").read()
    header, _, w, h, bpp = struct.unpack(">5I", data[:20])
    a = np.frombuffer(data[header:header + w * h * bpp], np.uint8).reshape(h, w, bpp)
    return np.ascontiguousarray(np.repeat(a[..., :1], 3, -1) if bpp < 3 else a[..., :3])


def exemplar(name, size=128):
    path = EXEMPLARS[name]
    img = Image.fromarray(read_pat(path)) if path.endswith(".pat") else Image.open(path).convert("RGB")
    return np.asarray(img.resize((size, size), Image.LANCZOS))


def gmic_image(ex_png, out_png):
    subprocess.run(["gmic", "-v", "-1", ex_png, "syntexturize_matchpatch", "256,256", "-o", out_png],
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return np.asarray(Image.open(out_png).convert("RGB"))


EXSYNTH_CHILD = ("import sys, numpy as np; from PIL import Image; from exsynth import _native; "
                 "ex = np.asarray(Image.open(sys.argv[1]).convert('RGB')); "
                 "img = _native.synthesize_image(ex, width=256, height=256, seed=7)['image']; "
                 "Image.fromarray((np.clip(img, 0, 1) * 255 + 0.5).astype(np.uint8)).save(sys.argv[2])")


def whole_process(cmd, env=None):
    """(wall seconds, CPU seconds user + sys) of one child process."""
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    subprocess.run(cmd, check=True, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall = time.perf_counter() - t
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)


CALIBRATION_WIDTHS = (9, 9, 7, 9, 9, 7)  # held-out, exsynth (copy), solid, gmic (copy)


def calibration(names, quality, native, opts, image_opts, peers, tmp):
    """nn_rel of an unseen piece of each texture, beside syntheses from the rest.

    The exemplar's left half (128 x 64) is the exemplar here; its right half,
    never seen by anyone, scores what the texture itself scores; exsynth and
    G'MIC make 128^2 from the left half, and exsynth a 64^3 solid (its
    slices, as in the main table). A synthesis far below the held-out score
    is closer to a copy than the texture is to itself.
    """
    print()
    print("calibration of nn_rel: left half (128 x 64) as exemplar; its right half (the texture itself, unseen) "
          "against syntheses from the left half: images 128^2, a solid 64^3 (mean of x/y/z slices)")
    head = (f"{'exemplar':<16} {'held-out':>9} {'exsynth':>9} {'(copy)':>7} {'solid':>9}" +
            (f" {'gmic':>9} {'(copy)':>7}" if peers else ""))
    print(head)
    print("-" * len(head))
    sums = []
    for name in names:
        ex = exemplar(name)
        left, right = np.ascontiguousarray(ex[:, :64]), np.ascontiguousarray(ex[:, 64:])
        E = quality.Exemplar(left)
        held = quality.image_metrics(E, right)
        ours = quality.image_metrics(E, native.synthesize_image(left, width=128, height=128, seed=7, **image_opts)["image"])
        solid = native.synthesize_solid(left, size=64, seed=7, **opts)["solid"]
        vals = [held["nn_rel"], ours["nn_rel"], ours["copy_rate"],
                quality.volume_metrics(E, solid, slices=8)["mean"]["nn_rel"]]
        if peers:
            png = os.path.join(tmp, name + "_left.png")
            Image.fromarray(left).save(png)
            subprocess.run(["gmic", "-v", "-1", png, "syntexturize_matchpatch", "128,128", "-o", png + ".out.png"],
                           check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            theirs = quality.image_metrics(E, np.asarray(Image.open(png + ".out.png").convert("RGB")))
            vals += [theirs["nn_rel"], theirs["copy_rate"]]
        sums.append(vals)
        print(f"{name:<16} " + " ".join(f"{v:>{w}.2f}" for v, w in zip(vals, CALIBRATION_WIDTHS)), flush=True)
    mean = np.mean(sums, axis=0)
    print("-" * len(head))
    print(f"{'mean':<16} " + " ".join(f"{v:>{w}.2f}" for v, w in zip(mean, CALIBRATION_WIDTHS)))


def target_kind(label):
    return "solid" if label.startswith("solid") else "image" if "256^2" in label else None


def missed(kind, m):
    """The targets output m misses: [(key, value, bound)]."""
    return [(k, m[k], b) for k, side, b in TARGETS[kind] if (m[k] < b if side == "min" else m[k] > b)]


def print_targets(totals):
    """Per kind of output, how many exemplars meet each of issue 10's targets, and the misses."""
    print()
    print("issue 10's targets: " + "; ".join(
        f"{kind}s " + ", ".join(f"{k} {'>=' if side == 'min' else '<='} {b:g}" for k, side, b in TARGETS[kind])
        for kind in TARGETS))
    for label, named in totals.items():
        kind = target_kind(label)
        if kind is None:
            continue
        misses = {name: missed(kind, m) for name, m in named}
        met = sum(len(TARGETS[kind]) - len(v) for v in misses.values())
        per_key = ", ".join(f"{k} {sum(all(mk != k for mk, _, _ in v) for v in misses.values())}/{len(named)}"
                            for k, _, _ in TARGETS[kind])
        print(f"  {label}: {met} of {len(named) * len(TARGETS[kind])} met ({per_key}); every target on "
              f"{sum(not v for v in misses.values())} of {len(named)} exemplars")
        for name, v in misses.items():
            if v:
                print(f"    {name} misses " + ", ".join(f"{k} {val:.2f}" for k, val, _ in v))


def row(label, m):
    return f"{label:<44} " + " ".join(f"{m[k]:>9.2f}" for k in KEYS)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", required=True)
    ap.add_argument("--full", action="store_true", help="also 128^3 solids (slower)")
    ap.add_argument("--exemplars", default=",".join(EXEMPLARS))
    ap.add_argument("--no-peers", action="store_true")
    ap.add_argument("--solids-only", action="store_true", help="only the solids (no images, peers or speed)")
    ap.add_argument("--options", default="", help="extra engine options, e.g. 'coherent_upsampling=False'")
    ap.add_argument("--image-options", default="",
                    help="extra options for synthesize_image only, e.g. 'cut_passes=2' (synthesize_solid rejects them)")
    ap.add_argument("--no-calibration", action="store_true", help="skip the held-out-half calibration of nn_rel")
    args = ap.parse_args(argv)
    sys.path.insert(0, os.path.join(args.build, "addon"))
    from exsynth import _native, quality

    opts = eval(f"dict({args.options})", {})  # noqa: S307 - a developer's command line
    peers = not args.no_peers and shutil.which("gmic") is not None
    names = args.exemplars.split(",")
    tmp = tempfile.mkdtemp(prefix="exsynth_bench_")
    method = opts.get("method", _native.SOLID_DEFAULT_METHOD)
    image_opts = {k: v for k, v in opts.items() if k not in SOLID_ONLY}
    image_opts.update(eval(f"dict({args.image_options})", {}))  # noqa: S307 - a developer's command line
    print(f"machine: {os.cpu_count()} cores; 128^2 exemplars, {args.options or 'default options'}"
          f"{'; images also ' + args.image_options if args.image_options else ''}, seed 7; "
          f"solids: mean of x/y/z slices, method {method}")
    print(f"image method: {opts.get('method', _native.IMAGE_DEFAULT_METHOD)} (synthesize_image's default: {_native.IMAGE_DEFAULT_METHOD}); "
          f"load average at start {os.getloadavg()[0]:.1f}")
    header = f"{'output':<44} " + " ".join(f"{k:>9}" for k in KEYS)
    print(header)
    print("-" * len(header))
    totals = {}
    for name in names:
        ex = exemplar(name)
        ex_png = os.path.join(tmp, name + ".png")
        Image.fromarray(ex).save(ex_png)
        E = quality.Exemplar(ex)
        cases = [("solid 64^3", lambda: quality.volume_metrics(
            E, _native.synthesize_solid(ex, size=64, seed=7, **opts)["solid"], slices=8)["mean"])]
        if args.full:
            cases.append(("solid 128^3", lambda: quality.volume_metrics(
                E, _native.synthesize_solid(ex, size=128, seed=7, **opts)["solid"], slices=4)["mean"]))
        if not args.solids_only:
            cases.append(("image 256^2", lambda: quality.image_metrics(
                E, _native.synthesize_image(ex, width=256, height=256, seed=7, **image_opts)["image"])))
        if peers and not args.solids_only:
            cases.append(("G'MIC matchpatch 256^2 (peer)", lambda: quality.image_metrics(
                E, gmic_image(ex_png, os.path.join(tmp, name + "_gmic.png")))))
        for label, run in cases:
            m = run()
            totals.setdefault(label, []).append((name, m))
            print(row(f"{name}: {label}", m), flush=True)
    print("-" * len(header))
    for label, named in totals.items():
        ms = [m for _, m in named]
        print(row(f"mean over {len(ms)} exemplars: {label}", {k: float(np.mean([m[k] for m in ms])) for k in KEYS}))
        print(row(f"worst of {len(ms)} exemplars: {label}",
                  {k: WORST[k]([m[k] for m in ms]) for k in KEYS}))
    print_targets(totals)

    if args.solids_only:
        return 0
    if not args.no_calibration:
        calibration(names, quality, _native, opts, image_opts, peers, tmp)
    print()
    print("speed (whole process, same run, alternating; median of 3)")
    env = dict(os.environ, PYTHONPATH=os.path.join(args.build, "addon"))
    ex_png = os.path.join(tmp, "crackedground.png")
    Image.fromarray(exemplar("crackedground")).save(ex_png)
    ours, theirs = [], []
    for _ in range(3):
        ours.append(whole_process(["/usr/bin/python3", "-c", EXSYNTH_CHILD, ex_png, os.path.join(tmp, "o.png")], env))
        if peers:
            theirs.append(whole_process(["gmic", "-v", "-1", ex_png, "syntexturize_matchpatch", "256,256",
                                         "-o", os.path.join(tmp, "g.png")]))
    ow, oc = np.median([w for w, _ in ours]), np.median([c for _, c in ours])
    print(f"  image 128^2 -> 256^2, exsynth (python module)   {ow:6.2f} s wall, {oc:5.2f} s CPU")
    if peers:
        tw, tc = np.median([w for w, _ in theirs]), np.median([c for _, c in theirs])
        print(f"  image 128^2 -> 256^2, gmic syntexturize_matchpatch {tw:6.2f} s wall, {tc:5.2f} s CPU"
              f"   (exsynth / gmic: wall {ow / tw:.2f}, CPU {oc / tc:.2f}; load {os.getloadavg()[0]:.1f})")
    ex = exemplar("crackedground")
    t = time.perf_counter()
    solid_opts = {"method": method}
    _native.synthesize_solid(ex, size=128, seed=7, **solid_opts)
    print(f"  solid 128^3 RGB, method {method} (in process)   {time.perf_counter() - t:6.2f} s")
    shutil.rmtree(tmp, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
