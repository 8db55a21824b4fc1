"""2D synthesis of exemplar coordinates (the default image method): quality
floors on small images of two exemplars, a copy ceiling, tiling, options."""
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from exsynth import _native, quality

TEXTURES = Path(__file__).resolve().parents[2] / "assets" / "textures"


def exemplar(name, size=64):
    img = Image.open(TEXTURES / name).convert("RGB")
    return np.asarray(img.resize((size, size), Image.LANCZOS))  # uint8 (H, W, 3)


@pytest.fixture(scope="module", params=["crackedground.png", "drkwood2.png"])
def case(request):
    ex = exemplar(request.param)
    img = _native.synthesize_image(ex, width=96, height=96, seed=7)["image"]
    return request.param, ex, img, quality.image_metrics(quality.Exemplar(ex), img)


def test_sharpness_and_contrast_floor(case):
    # Measured (64^2 -> 96^2, seed 7, default options), sharpness / contrast /
    # nn_rel: crackedground 0.97 / 0.95 / 0.42, drkwood2 1.00 / 0.98 / 0.22
    # (with the patch refinement, an option, and jitter 0.5: 0.93 / 0.91 /
    # 0.37, 0.92 / 0.91 / 0.25; its mean-colour vote: sharpness 0.84 / 0.80);
    # before coordinates wrapped in the valid range (they were clamped, a
    # smear of one row or column) sharpness was 0.89 / 0.80.
    name, _, _, m = case
    assert m["sharpness"] >= 0.9 and m["contrast"] >= 0.8, (name, m)
    assert m["nn_rel"] <= 0.45, (name, m)  # structure, not noise (shuffled pixels score ~1)


def test_copy_ceiling(case):
    # Measured copy_rate / max_copy_frac: crackedground 0.16 / 0.16, drkwood2 0.34 / 0.24
    # (with the refinement and jitter 0.5: 0.26 / 0.27, 0.23 / 0.18).
    name, _, _, m = case
    assert m["copy_rate"] <= 0.5 and m["max_copy_frac"] <= 0.5, (name, m)


def test_every_pixel_is_an_exemplar_pixel(case):
    _, ex, img, _ = case
    palette = {tuple(p) for p in ex.reshape(-1, 3).tolist()}
    got = np.rint(img.reshape(-1, 3) * 255.0).astype(int)
    assert np.abs(img.reshape(-1, 3) * 255.0 - got).max() < 1e-3
    assert all(tuple(p) in palette for p in got.tolist())


def seam_ratios(img):
    """Mean |difference| across the wrap-around seam (last column to first,
    last row to first) over the mean between neighbouring columns / rows."""
    across = np.abs(img[:, 0] - img[:, -1]).mean() / np.abs(np.diff(img, axis=1)).mean()
    down = np.abs(img[0] - img[-1]).mean() / np.abs(np.diff(img, axis=0)).mean()
    return across, down


def test_tileable_output_continues_across_its_edges():
    # Measured (crackedground 64^2 -> 80x72, seeds 0-3): tileable 0.86-1.26,
    # not tileable 1.58-2.04 (two unrelated edges).
    ex = exemplar("crackedground.png")
    for seed in (0, 1):
        tiled = seam_ratios(_native.synthesize_image(ex, width=80, height=72, tileable=True, seed=seed)["image"])
        plain = seam_ratios(_native.synthesize_image(ex, width=80, height=72, seed=seed)["image"])
        assert max(tiled) < 1.4 and min(plain) > 1.4, (seed, tiled, plain)


def test_jitter_trades_copying_for_randomness():
    ex = exemplar("drkwood2.png")
    E = quality.Exemplar(ex)
    calm = quality.image_metrics(E, _native.synthesize_image(ex, width=96, height=96, seed=7, jitter=0)["image"])
    wild = quality.image_metrics(E, _native.synthesize_image(ex, width=96, height=96, seed=7, jitter=1.5,
                                                             jitter_from=2)["image"])
    assert wild["copy_rate"] < calm["copy_rate"], (calm, wild)


def test_methods_and_sizes():
    ex = exemplar("crackedground.png", size=32)
    a = _native.synthesize_image(ex, width=5, height=3, seed=1)["image"]  # any size from 1
    assert a.shape == (3, 5, 3)
    b = _native.synthesize_image(ex, width=40, height=40, seed=1, method="optimization", levels=2)["image"]
    assert b.shape == (40, 40, 3)
    with pytest.raises(_native.InvalidInputError, match="method must be 'coordinates' or 'optimization', got 'x'"):
        _native.synthesize_image(ex, width=8, height=8, method="x")
    with pytest.raises(_native.InvalidInputError, match="jitter_from must be a power of two"):
        _native.synthesize_image(ex, width=8, height=8, jitter_from=3)
    with pytest.raises(_native.InvalidInputError, match="appearance_window must be odd"):
        _native.synthesize_image(ex, width=8, height=8, appearance_window=4)


def test_exhaustive_search_runs_on_a_tiny_input():
    # The C++ tests compare it with the candidate search pixel by pixel; here the binding path.
    ex = exemplar("crackedground.png", size=16)
    res = _native.synthesize_image(ex, width=12, height=12, seed=2, coarsest_spacing=2, exhaustive=True,
                                   refine_passes=1, refine_patch=6)
    assert res["image"].shape == (12, 12, 3)
    assert len(res["energy"]) == 2 * 2 + 1  # 2 levels x 2 corrections, 1 refinement round


def test_over_the_memory_budget_is_refused_before_allocating():
    ex = exemplar("crackedground.png", size=64)
    with pytest.raises(_native.OverBudgetError, match="image synthesis of 4000x4000 .*raise the memory budget"):
        _native.synthesize_image(ex, width=4000, height=4000, memory_budget=1 << 20)


def test_patch_refinement_options_are_checked_in_the_core():
    ex = exemplar("crackedground.png", size=32)
    off = _native.synthesize_image(ex, width=24, height=24, seed=3, refine_passes=0)
    on = _native.synthesize_image(ex, width=24, height=24, seed=3, refine_passes=2)
    assert len(on["energy"]) == len(off["energy"]) + 2 and not np.array_equal(on["image"], off["image"])
    with pytest.raises(_native.InvalidInputError, match=r"refine_stride must be between 1 and refine_patch \(4\)"):
        _native.synthesize_image(ex, width=8, height=8, refine_patch=4, refine_stride=5)


def test_seam_cuts_lower_their_energy_and_the_nn_error():
    # Graph-cut seams (cut_passes > 0, an option; image/seam_cut.hpp): one
    # energy per pass, never rising; the image stays made of exemplar pixels,
    # as sharp, and nearer the exemplar's patches. Measured (64^2 -> 96^2, seed 7,
    # cut_reach 4), nn_rel / sharpness / copy_rate without and with: crackedground
    # 0.418 / 0.971 / 0.16 and 0.308 / 0.974 / 0.36 (drkwood2 0.220 / 1.005 / 0.34
    # and 0.204 / 1.009 / 0.39: the nn error falls, the copying rises).
    ex = exemplar("crackedground.png")
    E = quality.Exemplar(ex)
    off = _native.synthesize_image(ex, width=96, height=96, seed=7)
    on = _native.synthesize_image(ex, width=96, height=96, seed=7, cut_passes=2)
    assert len(on["energy"]) == len(off["energy"]) + 2
    assert on["energy"][-1] <= on["energy"][-2]
    m_off, m_on = quality.image_metrics(E, off["image"]), quality.image_metrics(E, on["image"])
    assert m_on["nn_rel"] < m_off["nn_rel"] - 0.05 and m_on["sharpness"] >= 0.9, (m_off, m_on)
    palette = {tuple(p) for p in ex.reshape(-1, 3).tolist()}
    assert all(tuple(p) in palette for p in np.rint(on["image"].reshape(-1, 3) * 255.0).astype(int).tolist())
    with pytest.raises(_native.InvalidInputError, match="'cut_window' must be an integer between 4 and 256"):
        _native.synthesize_image(ex, width=8, height=8, cut_window=3)
