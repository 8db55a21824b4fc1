"""exsynth._native.make_exemplar_pair through the binding: layout, dtypes,
the change A -> A', options, progress and cancel, and bad input."""
import numpy as np
import pytest

from exsynth import _native

PRESETS = ["spikes", "pits", "holes", "grooves", "dilate"]


@pytest.mark.parametrize("preset", PRESETS)
def test_pair_layout_and_dtypes(preset):
    r = _native.make_exemplar_pair(preset, resolution=24)
    assert set(r) == {"a", "a_prime", "field", "origin", "voxel_size"}
    for key in ("a", "a_prime"):
        v = r[key]
        assert v.dtype == np.float32 and v.shape == (24, 24, 24) and v.flags["C_CONTIGUOUS"]
        assert np.all(np.isfinite(v))
    f = r["field"]
    assert f.dtype == np.float32 and f.shape == (24, 24, 24, 3)
    np.testing.assert_allclose(np.linalg.norm(f, axis=-1), 1.0, atol=1e-5)
    assert r["voxel_size"] == pytest.approx(2 / 24)
    np.testing.assert_allclose(r["origin"], [-1 + 1 / 24] * 3)
    # Centre inside, top corner outside, in both.
    for key in ("a", "a_prime"):
        assert r[key][12, 12, 12] < 0 and r[key][-1, -1, -1] > 0


def test_the_pairs_change_volume_the_expected_way():
    def volume(v):
        return int((v < 0).sum())

    spikes = _native.make_exemplar_pair("spikes", resolution=48)
    assert volume(spikes["a_prime"]) > volume(spikes["a"])
    for name in ("pits", "holes", "grooves"):
        r = _native.make_exemplar_pair(name, resolution=48)
        assert volume(r["a_prime"]) < volume(r["a"]), name
    d = _native.make_exemplar_pair("dilate", resolution=64, sphere_radius=0.4, dilation=0.2)
    assert volume(d["a_prime"]) / volume(d["a"]) == pytest.approx((0.6 / 0.4) ** 3, rel=0.05)


def test_axis_order_is_z_y_x():
    # The slab is horizontal: A varies with z (axis 0) only.
    a = _native.make_exemplar_pair("holes", resolution=16)["a"]
    assert np.all(a == a[:, :1, :1])
    z = -1 + 1 / 16 + 2 / 16 * np.arange(16)
    np.testing.assert_allclose(a[:, 0, 0], np.abs(z) - 0.2, atol=1e-6)


def test_options_reach_the_engine():
    base = _native.make_exemplar_pair("grooves", resolution=32)
    along = _native.make_exemplar_pair("grooves", resolution=32, groove_direction="along")
    np.testing.assert_array_equal(along["field"][..., 2], 1.0)
    assert not np.array_equal(base["a_prime"], along["a_prime"])
    j1 = _native.make_exemplar_pair("spikes", resolution=32, jitter=0.2, seed=5)
    j2 = _native.make_exemplar_pair("spikes", resolution=32, jitter=0.2, seed=5)
    j3 = _native.make_exemplar_pair("spikes", resolution=32, jitter=0.2, seed=6)
    np.testing.assert_array_equal(j1["a_prime"], j2["a_prime"])
    assert not np.array_equal(j1["a_prime"], j3["a_prime"])


def test_progress_and_cancel():
    ctx = _native.ExecContext()
    _native.make_exemplar_pair("dilate", resolution=16, ctx=ctx)
    assert ctx.progress == pytest.approx(1.0)
    ctx = _native.ExecContext()
    ctx.cancel()
    with pytest.raises(_native.CancelledError):
        _native.make_exemplar_pair("dilate", resolution=16, ctx=ctx)


@pytest.mark.parametrize("kwargs, exc, words", [
    ({"preset": "bumps"}, _native.InvalidInputError, ["preset", "bumps", "spikes"]),
    ({"resolution": 4}, _native.InvalidInputError, ["resolution", "between 8 and 512"]),
    ({"feature_radius": -1.0}, _native.InvalidInputError, ["feature_radius"]),
    ({"jitter": 0.9}, _native.InvalidInputError, ["jitter"]),
    ({"spacing": "wide"}, _native.InvalidInputError, ["spacing", "number"]),
    ({"groove_direction": "diagonal"}, _native.InvalidInputError, ["groove_direction", "around"]),
    ({"wibble": 1}, _native.InvalidInputError, ["wibble", "feature_radius"]),
    ({"resolution": 512, "memory_budget": 1 << 20}, _native.OverBudgetError, ["memory budget", "resolution"]),
])
def test_bad_input_is_rejected_with_a_message_naming_it(kwargs, exc, words):
    kwargs = dict(kwargs)
    preset = kwargs.pop("preset", "spikes")
    with pytest.raises(exc) as info:
        _native.make_exemplar_pair(preset, **kwargs)
    for w in words:
        assert w in str(info.value)


@pytest.mark.parametrize("preset, options, message", [
    ("dilate", {"dilation": -5.0}, r"'dilation' must be a finite number > 0 \(world units\), got -5"),
    ("spikes", {"feature_height": 5.0}, r"feature_height \(5\) plus half the thickness"),
    ("pits", {"feature_radius": 0.45}, "feature_radius"),
])
def test_check_exemplar_pair_refuses_what_make_would(preset, options, message):
    with pytest.raises(_native.InvalidInputError, match=message):
        _native.check_exemplar_pair(preset, **options)
    with pytest.raises(_native.InvalidInputError, match=message):
        _native.make_exemplar_pair(preset, resolution=16, **options)


def test_check_exemplar_pair_accepts_the_defaults():
    for preset in ("spikes", "pits", "holes", "grooves", "dilate"):
        assert _native.check_exemplar_pair(preset) is None


def test_resolution_for_pattern_gives_the_pair_its_detail():
    detail = _native.PAIR_DETAIL_RESOLUTION
    assert _native.PAIR_MIN_RESOLUTION <= detail <= _native.PAIR_MAX_RESOLUTION
    for resolution, scale in ((128, 0.276), (48, 0.5), (128, 0.223), (16, 1.0)):
        r = _native.resolution_for_pattern(resolution, scale)
        assert r > resolution and round(scale * r) >= detail > round(scale * (r - 1))  # the least such r
    assert _native.resolution_for_pattern(128, 0.575) == 128  # already 74 voxels across
    assert _native.resolution_for_pattern(128, 0.01) == _native.MAX_PATTERN_RESOLUTION  # capped
    with pytest.raises(_native.InvalidInputError, match="pattern_scale"):
        _native.resolution_for_pattern(128, 0.0)
    with pytest.raises(_native.InvalidInputError, match="resolution"):
        _native.resolution_for_pattern(0, 0.5)
    with pytest.raises(_native.InvalidInputError, match="unknown"):
        _native.resolution_for_pattern(128, 0.5, scale=2)


@pytest.mark.parametrize("preset", PRESETS)
def test_the_exported_defaults_are_the_ones_the_pair_uses(preset):
    plain = _native.make_exemplar_pair(preset, resolution=24)
    given = _native.make_exemplar_pair(preset, resolution=24, **_native.PAIR_DEFAULTS)
    np.testing.assert_array_equal(plain["a_prime"], given["a_prime"])
    changed = _native.make_exemplar_pair(preset, resolution=24, **{**_native.PAIR_DEFAULTS,
                                                                    "feature_radius": 0.1, "dilation": 0.2})
    assert not np.array_equal(plain["a_prime"], changed["a_prime"])
