"""Quality numbers for exemplar-based texture synthesis (numpy only, no bpy).

Used by the quality benchmark (bench/bench_quality.py) and the Python-tier
floors. Values are in 0..255 grey-level units (float inputs with max <= 1
are scaled by 255), RGB throughout (grey images get three equal channels).
For a volume (Z, Y, X[, C]) every slice orientation (x, y, z; up to
`slices` evenly spaced slices each) is compared with the exemplar and the
numbers are averaged per axis, then over the axes.

  nn_rms     mean over the output's k x k patches (stride `stride`) of the RMS
             per-pixel-channel L2 distance to the nearest exemplar patch (every
             exemplar position). Search: PCA to `dims` dimensions, the
             `candidates` nearest there, re-ranked exactly.
  nn_rel     nn_rms / the exemplar's RMS contrast (sqrt of the mean
             per-channel variance): comparable across exemplars; ~1 or more
             means no better than unstructured.
  hist_emd   per-channel 1-D earth mover's distance between 32-bin histograms
             over 0..256, in grey levels, channel mean.
  sharpness  mean gradient magnitude (central differences, channel mean) of the
             output / the exemplar's: 1 = as crisp; a blur scores below 1.
  contrast   output RMS contrast / exemplar RMS contrast.
  copy_rate  fraction of output patches that match an exemplar patch (RMS <
             `copy_eps`) and belong to a 4-connected group of >= `min_cells`
             such patches with the same exemplar offset: verbatim copies.
  max_copy_frac  pixel area of the largest such copied region / exemplar area.
  speckle    single-pixel noise: the RMS of the luminance minus its 3 x 3
             median (edges replicated), output / exemplar's. Above 1 the
             output has more lone pixels than the exemplar, which raises
             sharpness without any detail: solids of exemplar values scored
             sharpness 1.10 with speckle 1.72 on granite1, whose slices look
             like salt and pepper (issue 10, sixteenth pass). Not in the
             shared tool (texmetrics.py): a project-side diagnostic.
  elongation the output's stretch / the exemplar's (1 = as isotropic as the
             exemplar). Stretch = sqrt(largest / smallest eigenvalue) of the
             second moments of the central lobe of the luminance's
             autocorrelation (zero-padded, lag 0 = 1; the lobe is the
             connected region > `lobe_level` around lag 0), i.e. the ratio
             of the typical feature's longest to shortest extent. For a
             volume it is computed in 3D (on at most a 64^3 middle block),
             so it sees what no slice measure does: a solid of parallel
             sheets whose every slice shows the exemplar's features, only
             all stretched one way (found on cells and cracks, issue 10).
"""
import numpy as np

__all__ = ["load", "image_metrics", "volume_metrics", "Exemplar"]


def as_255(a):
    a = np.asarray(a)
    scale = 255.0 if a.dtype.kind == "f" and a.size and a.max() <= 1.0 else 1.0
    return a.astype(np.float64) * scale


def rgb(img):
    img = np.asarray(img, np.float64)
    if img.ndim == 2:
        img = img[..., None]
    if img.shape[-1] == 1:
        img = np.repeat(img, 3, -1)
    elif img.shape[-1] != 3:
        img = np.repeat(img.mean(-1, keepdims=True), 3, -1)
    return img


def load(path):
    """An image file or a .npy array, in 0..255."""
    if str(path).endswith(".npy"):
        return as_255(np.load(path))
    from PIL import Image
    return as_255(np.asarray(Image.open(path).convert("RGB")))


def patches(img, k, stride):
    v = np.lib.stride_tricks.sliding_window_view(img, (k, k), axis=(0, 1))[::stride, ::stride]
    gh, gw = v.shape[:2]
    return v.reshape(gh * gw, -1), gh, gw


class Exemplar:
    """An exemplar's patches and their PCA, built once for many outputs."""

    def __init__(self, img, k=8, dims=24):
        self.img = rgb(as_255(img))
        self.k = k
        self.P, self.gh, self.gw = patches(self.img, k, 1)
        self.mean = self.P.mean(0)
        X = self.P - self.mean
        _, V = np.linalg.eigh(X.T @ X)
        self.basis = V[:, ::-1][:, :min(dims, V.shape[1])]
        self.Y = X @ self.basis
        self.Yn = (self.Y ** 2).sum(1)
        self.contrast = float(np.sqrt(self.img.reshape(-1, 3).var(0).mean()))
        self.grad = grad_energy(self.img)
        self.stretch = lobe_stretch(luminance(self.img))
        self.speckle = median_residual(luminance(self.img))

    def nearest(self, Q, candidates=8, chunk=2048):
        """(squared distance, index) of each row of Q's nearest exemplar patch."""
        d2 = np.empty(len(Q))
        idx = np.empty(len(Q), np.int64)
        c = min(candidates, len(self.P))
        for s in range(0, len(Q), chunk):
            q = Q[s:s + chunk]
            y = (q - self.mean) @ self.basis
            approx = (y ** 2).sum(1)[:, None] + self.Yn[None, :] - 2.0 * y @ self.Y.T
            cand = np.argpartition(approx, c - 1, axis=1)[:, :c]
            exact = ((self.P[cand] - q[:, None, :]) ** 2).sum(-1)
            j = exact.argmin(1)
            d2[s:s + chunk] = exact[np.arange(len(q)), j]
            idx[s:s + chunk] = cand[np.arange(len(q)), j]
        return d2, idx


def autocorrelation(a):
    """Autocorrelation of a (any dimension) with its mean removed, zero
    padded (no wrap-around), lag 0 at the array's centre, normalised to 1
    there: A(d) = sum_x a(x) a(x + d) / sum_x a(x)^2."""
    a = np.asarray(a, np.float64)
    a = a - a.mean()
    shape = [2 * n for n in a.shape]
    axes = list(range(a.ndim))  # NumPy 2 wants them named beside the shape
    F = np.fft.rfftn(a, shape, axes)
    ac = np.fft.irfftn(F * np.conj(F), shape, axes)
    return np.fft.fftshift(ac / max(ac.flat[0], 1e-30))


def gaussian_blur(a, sigma):
    """a low-passed by a Gaussian of `sigma` pixels (periodic, in Fourier space)."""
    F = np.fft.fftn(np.asarray(a, np.float64))
    for ax, n in enumerate(F.shape):
        g = np.exp(-2.0 * (np.pi * sigma * np.fft.fftfreq(n)) ** 2)
        F *= g.reshape([n if i == ax else 1 for i in range(F.ndim)])
    return np.fft.ifftn(F).real


def lobe_stretch(a, lobe_level=0.3, sigma=1.0):
    """sqrt(largest / smallest eigenvalue) of the second moments (weighted by
    the autocorrelation) of the autocorrelation's central lobe: the
    connected region above lobe_level around lag 0, grown face-neighbour by
    face-neighbour. 1 = isotropic.

    `a` is blurred by a Gaussian of `sigma` pixels first, so that the lobe
    holds at least the face neighbours of lag 0 on any grain: slate's
    correlation at a lag of 1 pixel is 0.21, and unblurred its lobe (and a
    64^3 marble1 solid's) was the lag-0 point alone, the stretch undefined."""
    ac = autocorrelation(gaussian_blur(a, sigma) if sigma > 0 else a)
    centre = tuple(n // 2 for n in ac.shape)
    above = ac > lobe_level
    lobe = np.zeros_like(above)
    lobe[centre] = True
    while True:  # grow into face neighbours above the level; the lobe is small
        grown = lobe.copy()
        for ax in range(ac.ndim):
            grown |= np.roll(lobe, 1, ax) | np.roll(lobe, -1, ax)
        grown &= above
        if (grown == lobe).all():
            break
        lobe = grown
    d = np.argwhere(lobe) - np.array(centre)
    w = ac[lobe]
    T = (d * w[:, None]).T @ d / w.sum()
    ev = np.linalg.eigvalsh(T)
    return float(np.sqrt(ev[-1] / max(ev[0], 1e-12)))


def luminance(a, dims=2):
    """Channel mean of a `dims`-dimensional image or volume (a grey one as is)."""
    a = np.asarray(a, np.float64)
    return a.mean(-1) if a.ndim == dims + 1 else a


def grad_energy(img):
    gy = 0.5 * (img[2:, 1:-1] - img[:-2, 1:-1])
    gx = 0.5 * (img[1:-1, 2:] - img[1:-1, :-2])
    return float(np.sqrt(gx ** 2 + gy ** 2).mean())


def median_residual(lum):
    """RMS of a 2D luminance minus its 3 x 3 median (edges replicated)."""
    h, w = lum.shape
    p = np.pad(lum, 1, mode="edge")
    med = np.median(np.stack([p[dy:dy + h, dx:dx + w] for dy in range(3) for dx in range(3)]), axis=0)
    return float(np.sqrt(np.mean((lum - med) ** 2)))


def hist_emd(ex, out, bins=32):
    emd = []
    for c in range(ex.shape[-1]):
        p = np.histogram(ex[..., c], bins, (0, 256))[0].astype(float)
        q = np.histogram(out[..., c], bins, (0, 256))[0].astype(float)
        p /= p.sum()
        q /= q.sum()
        emd.append(np.abs(np.cumsum(p - q)).sum() * 256.0 / bins)
    return float(np.mean(emd))


def label4(mask):
    """4-connected component labels of a boolean grid (0 = background)."""
    lab = np.zeros(mask.shape, np.int64)
    n = 0
    h, w = mask.shape
    for i, j in zip(*np.nonzero(mask)):
        if lab[i, j]:
            continue
        n += 1
        stack = [(i, j)]
        lab[i, j] = n
        while stack:
            a, b = stack.pop()
            for u, v in ((a + 1, b), (a - 1, b), (a, b + 1), (a, b - 1)):
                if 0 <= u < h and 0 <= v < w and mask[u, v] and not lab[u, v]:
                    lab[u, v] = n
                    stack.append((u, v))
    return lab, n


def copied_regions(exact, offset, stride, k, shape, min_cells=16):
    """Verbatim copying from the patch grid: `exact` patches (RMS < copy_eps)
    in 4-connected groups of >= min_cells sharing one exemplar `offset`.
    Returns (copied: bool per patch, pixel area of the largest group's
    footprint in an output of `shape`)."""
    copied = np.zeros_like(exact)
    best = 0
    for t in np.unique(offset[exact]):
        lab, n = label4(exact & (offset == t))
        sizes = np.bincount(lab.ravel())[1:]
        for c in np.nonzero(sizes >= min_cells)[0] + 1:
            cells = lab == c
            copied |= cells
            foot = np.zeros(shape[:2], bool)
            for i, j in np.argwhere(cells):
                foot[i * stride:i * stride + k, j * stride:j * stride + k] = True
            best = max(best, int(foot.sum()))
    return copied, best


def image_metrics(E, out, stride=2, copy_eps=1.0, min_cells=16):
    """The numbers above for one 2D output against Exemplar E."""
    out = rgb(as_255(out))
    k = E.k
    Q, gh, gw = patches(out, k, stride)
    d2, idx = E.nearest(Q)
    rms = np.sqrt(d2 / Q.shape[1]).reshape(gh, gw)
    sy, sx = np.divmod(idx.reshape(gh, gw), E.gw)
    oy, ox = np.mgrid[0:gh, 0:gw] * stride
    offset = (sy - oy) * 100003 + (sx - ox)
    exact = rms < copy_eps
    copied, best = copied_regions(exact, offset, stride, k, out.shape, min_cells)
    out_contrast = float(np.sqrt(out.reshape(-1, 3).var(0).mean()))
    return dict(nn_rms=float(rms.mean()), nn_rel=float(rms.mean() / max(E.contrast, 1e-9)),
                hist_emd=hist_emd(E.img, out), sharpness=grad_energy(out) / max(E.grad, 1e-9),
                contrast=out_contrast / max(E.contrast, 1e-9), copy_rate=float(copied.mean()),
                max_copy_frac=best / float(E.img.shape[0] * E.img.shape[1]),
                speckle=median_residual(luminance(out)) / max(E.speckle, 1e-9),
                elongation=lobe_stretch(luminance(out)) / E.stretch)


def volume_metrics(E, vol, slices=16, block=64, **kw):
    """Per axis ('x', 'y', 'z') and 'mean' of image_metrics over slices of a
    (Z, Y, X[, C]) volume; 'mean' has the elongation in 3D (of the middle
    block^3, see the module's docstring) instead of the slices' mean."""
    vol = np.asarray(vol)
    if vol.ndim == 3:
        vol = vol[..., None]
    res = {}
    for name, ax in (("x", 2), ("y", 1), ("z", 0)):
        ids = np.unique(np.linspace(0, vol.shape[ax] - 1, min(slices, vol.shape[ax])).astype(int))
        ms = [image_metrics(E, np.take(vol, i, axis=ax), **kw) for i in ids]
        res[name] = {key: float(np.mean([m[key] for m in ms])) for key in ms[0]}
        res[name]["max_copy_frac"] = max(m["max_copy_frac"] for m in ms)
    res["mean"] = {key: float(np.mean([res[n][key] for n in "xyz"])) for key in res["x"]}
    res["mean"]["max_copy_frac"] = max(res[n]["max_copy_frac"] for n in "xyz")
    res["mean"]["elongation"] = volume_elongation(E, vol, block)
    return res


def volume_elongation(E, vol, block=64):
    """The elongation of a (Z, Y, X[, C]) volume in 3D, on its middle block^3
    (at most), against exemplar E (see the module's docstring)."""
    vol = np.asarray(vol)
    mid = tuple(slice(max(0, (n - block) // 2), max(0, (n - block) // 2) + block) for n in vol.shape[:3])
    return lobe_stretch(luminance(as_255(vol[mid]), 3)) / E.stretch
