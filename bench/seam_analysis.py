#!/usr/bin/env python3
"""Where the 2D nn error sits: per output 8x8 patch (stride 2, as exsynth.quality).

Classes of patches: `copied` (exact, in a copied group of >= 16 cells: what
copy_rate counts), `exact_small` (exact, RMS < copy_eps, but in a smaller
group: a coherent region too small to count as copying), `seam` (not exact:
the patch crosses a seam between sources, since a patch inside one coherent
region is an exemplar patch). nn_rel = share(seam) * mean rel error of seam
patches (+ the tiny error of exact ones). Per exemplar of bench_quality.py,
ours (synthesize_image defaults, seed 7, plus --options) and G'MIC's.

usage: seam_analysis.py --build BUILD [--exemplars a,b] [--options "jitter=0.2"] [--no-peers] [--png DIR]
"""
import argparse, os, sys, tempfile
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_quality as bq  # noqa: E402


def classes(E, out, quality, stride=2, copy_eps=1.0, min_cells=16):
    out = quality.rgb(quality.as_255(out))
    Q, gh, gw = quality.patches(out, E.k, stride)
    d2, idx = E.nearest(Q)
    rms = np.sqrt(d2 / Q.shape[1]).reshape(gh, gw) / E.contrast
    sy, sx = np.divmod(idx.reshape(gh, gw), E.gw)
    oy, ox = np.mgrid[0:gh, 0:gw] * stride
    offset = (sy - oy) * 100003 + (sx - ox)
    exact = rms * E.contrast < copy_eps
    copied, best = quality.copied_regions(exact, offset, stride, E.k, out.shape, min_cells)
    seam = ~exact
    e = rms[seam]
    return dict(nn_rel=float(rms.mean()), sharp=quality.grad_energy(out) / max(E.grad, 1e-9), copied=float(copied.mean()),
                max_copy=best / float(E.img.shape[0] * E.img.shape[1]), exact_small=float((exact & ~copied).mean()),
                seam=float(seam.mean()), seam_err=float(e.mean()) if e.size else 0.0,
                seam_p50=float(np.median(e)) if e.size else 0.0, seam_p90=float(np.percentile(e, 90)) if e.size else 0.0)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True)
    ap.add_argument("--exemplars", default=",".join(bq.EXEMPLARS))
    ap.add_argument("--options", default="")
    ap.add_argument("--no-peers", action="store_true")
    ap.add_argument("--png", default="", help="write exemplar | G'MIC | ours side by side here")
    a = ap.parse_args()
    sys.path.insert(0, os.path.join(a.build, "addon"))
    from exsynth import _native, quality
    from PIL import Image
    opts = eval(f"dict({a.options})", {})  # noqa: S307 - a developer's command line
    tmp = tempfile.mkdtemp()
    keys = ("nn_rel", "sharp", "copied", "max_copy", "exact_small", "seam", "seam_err", "seam_p50", "seam_p90")
    print(f"{'':28}" + " ".join(f"{k:>11}" for k in keys), f"  options: {a.options or 'defaults'}; load {os.getloadavg()[0]:.1f}")
    tot = {}
    for name in a.exemplars.split(","):
        ex = bq.exemplar(name)
        E = quality.Exemplar(ex)
        ours = _native.synthesize_image(ex, width=256, height=256, seed=7, **opts)["image"]
        runs = [("ours", ours)]
        if not a.no_peers:
            p = os.path.join(tmp, name + ".png")
            Image.fromarray(ex).save(p)
            g = bq.gmic_image(p, os.path.join(tmp, name + "_g.png"))
            runs.append(("gmic", g))
        for label, img in runs:
            m = classes(E, img, quality)
            tot.setdefault(label, []).append(m)
            print(f"{name + ' ' + label:28}" + " ".join(f"{m[k]:11.3f}" for k in keys), flush=True)
        if a.png:
            os.makedirs(a.png, exist_ok=True)
            u8 = lambda x: np.clip(np.asarray(x, np.float64) * (255 if np.asarray(x).dtype.kind == "f" else 1), 0, 255).astype(np.uint8)
            pad = np.zeros((256, 256, 3), np.uint8)
            pad[:128, :128] = ex
            row = [pad] + [u8(img) for _, img in runs]
            Image.fromarray(np.concatenate(row, 1)).save(os.path.join(a.png, name + ".png"))
    for label, ms in tot.items():
        print(f"{'mean ' + label:28}" + " ".join(f"{np.mean([m[k] for m in ms]):11.3f}" for k in keys))
        print(f"{'worst ' + label:28}" + " ".join(f"{(min if k in ('exact_small', 'sharp') else max)(m[k] for m in ms):11.3f}" for k in keys))


if __name__ == "__main__":
    main()
