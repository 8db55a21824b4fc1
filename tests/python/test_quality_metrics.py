"""exsynth.quality's elongation and speckle measures: the autocorrelation against a
brute-force sum and a direct median, and both on inputs whose answer is known."""
import itertools

import numpy as np
import pytest

from exsynth import quality


def brute_autocorrelation(a, lag):
    """sum_x a(x) a(x + lag) / sum_x a(x)^2 over the overlap (a zero outside)."""
    a = np.asarray(a, np.float64) - np.mean(a)
    src = tuple(slice(max(0, -d), n - max(0, d)) for n, d in zip(a.shape, lag))
    dst = tuple(slice(max(0, d), n - max(0, -d)) for n, d in zip(a.shape, lag))
    return float((a[src] * a[dst]).sum() / (a * a).sum())


@pytest.mark.parametrize("shape", [(7, 9), (5, 6, 4)])
def test_autocorrelation_matches_the_brute_force_sum(shape):
    a = np.random.default_rng(3).random(shape)
    ac = quality.autocorrelation(a)
    centre = np.array([n for n in shape])  # lag 0 sits at n // 2 of the 2n-long padded axes
    assert ac.shape == tuple(2 * n for n in shape)
    for lag in itertools.product(*[range(-n + 1, n) for n in shape]):
        assert ac[tuple(centre + lag)] == pytest.approx(brute_autocorrelation(a, lag), abs=1e-9), lag


def blobs(shape, sigma, seed=5):
    """Smooth isotropic noise: white noise low-passed by a Gaussian in Fourier space (periodic)."""
    rng = np.random.default_rng(seed)
    F = np.fft.fftn(rng.standard_normal(shape))
    k2 = sum(np.meshgrid(*[np.fft.fftfreq(n) ** 2 for n in shape], indexing="ij"))
    return np.real(np.fft.ifftn(F * np.exp(-2 * np.pi ** 2 * sigma ** 2 * k2)))


def test_isotropic_blobs_are_not_stretched_and_stretched_ones_are():
    iso = blobs((96, 96), 2.0)
    assert quality.lobe_stretch(iso) < 1.2
    # The same noise stretched 3x along the rows' axis: features 3x longer one way.
    rows = np.repeat(blobs((96, 32), 2.0), 3, axis=1)
    assert 2.4 < quality.lobe_stretch(rows) < 3.6
    # A rotation by 90 degrees changes no length, so not the stretch.
    assert quality.lobe_stretch(rows.T) == pytest.approx(quality.lobe_stretch(rows), rel=1e-9)


@pytest.mark.parametrize("shape", [(64, 64), (24, 24, 24)])
def test_white_noise_is_isotropic_not_undefined(shape):
    # No correlation at a lag of one pixel (as on slate's fine grain): the
    # lobe must still span more than lag 0.
    noise = np.random.default_rng(1).random(shape)
    assert 1.0 <= quality.lobe_stretch(noise) < 1.3


def test_a_solid_of_tubes_is_elongated_in_3d_beyond_what_its_slices_show():
    # Isotropic blobs smeared along the (1, 1, 1) diagonal: tubes. An axis
    # slice cuts them at 55 degrees, so it shows ellipses at most sqrt(3)
    # long; the 3D measure sees the tubes' full length.
    n = 40
    g = blobs((n, n, n), 1.5)
    tubes = sum(np.roll(g, (k, k, k), axis=(0, 1, 2)) for k in range(n)) / n
    iso = g
    assert quality.lobe_stretch(iso) < 1.3
    assert quality.lobe_stretch(tubes) > 5.0
    slices = [quality.lobe_stretch(tubes[n // 2]), quality.lobe_stretch(tubes[:, n // 2]),
              quality.lobe_stretch(tubes[:, :, n // 2])]
    assert max(slices) < 2.5, slices
    E = quality.Exemplar(np.repeat(blobs((48, 48), 1.5)[..., None], 3, -1) * 40 + 128)
    m_tubes = quality.volume_metrics(E, np.repeat(tubes[..., None], 3, -1) * 120 + 128, slices=2)["mean"]
    m_iso = quality.volume_metrics(E, np.repeat(iso[..., None], 3, -1) * 40 + 128, slices=2)["mean"]
    assert m_tubes["elongation"] > 3.0 * m_iso["elongation"], (m_tubes, m_iso)


def test_the_exemplar_itself_has_elongation_one():
    ex = (np.repeat(np.repeat(blobs((64, 32), 2.0), 2, axis=1)[..., None], 3, -1) * 50 + 128).clip(0, 255)
    E = quality.Exemplar(ex)
    assert quality.image_metrics(E, ex)["elongation"] == pytest.approx(1.0, abs=1e-12)


def test_median_residual_matches_a_direct_3x3_median():
    a = np.random.default_rng(3).random((6, 7)) * 255
    want = np.empty_like(a)
    for i, j in itertools.product(range(6), range(7)):
        rows = [min(max(i + d, 0), 5) for d in (-1, 0, 1)]
        cols = [min(max(j + d, 0), 6) for d in (-1, 0, 1)]
        want[i, j] = np.median([a[r, c] for r in rows for c in cols])
    assert quality.median_residual(a) == pytest.approx(float(np.sqrt(np.mean((a - want) ** 2))), rel=1e-12)


def test_speckle_sees_lone_pixels_that_sharpness_counts_as_detail():
    ex = (np.repeat(np.repeat(blobs((64, 32), 2.0), 2, axis=1)[..., None], 3, -1) * 50 + 128).clip(0, 255)
    E = quality.Exemplar(ex)
    assert quality.image_metrics(E, ex)["speckle"] == pytest.approx(1.0, abs=1e-12)
    # Every 7th pixel swapped with a random pixel of the image: the same
    # histogram, lone pixels everywhere.
    rng = np.random.default_rng(4)
    flat = ex.reshape(-1, 3).copy()
    lone = np.arange(0, len(flat), 7)
    flat[lone] = flat[rng.integers(0, len(flat), len(lone))]
    m = quality.image_metrics(E, flat.reshape(ex.shape))
    assert m["sharpness"] > 1.1 and m["speckle"] > 1.5
    # A blur has fewer lone pixels than the exemplar, and less sharpness.
    blurred = np.stack([quality.gaussian_blur(ex[..., c], 1.0) for c in range(3)], -1)
    m = quality.image_metrics(E, blurred)
    assert m["speckle"] < 0.8 and m["sharpness"] < 0.9
