"""exsynth._native point-set geometry texture synthesis through the binding:
layout and dtypes, options, determinism, coverage, a height-field exemplar
against a 2D synthesis of the same image, cancel, and bad input."""
import threading

import numpy as np
import pytest

from exsynth import _native

PRESETS = ["bumps", "chainmail", "weave", "flowers"]
SMALL = {"patch_size": 0.4, "grid_resolution": 8}


@pytest.fixture(scope="module")
def bumps():
    return _native.make_point_exemplar("bumps", density=2500, seed=1)


@pytest.mark.parametrize("name", PRESETS)
def test_exemplar_layout(name):
    ex = _native.make_point_exemplar(name, density=1500, padding=0.3)
    p, n = ex["positions"], ex["normals"]
    assert p.dtype == np.float32 and p.shape[1] == 3 and p.shape == n.shape and len(p) > 300
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-3)
    assert ex["box_min"] == (0.0, 0.0) and ex["box_max"] == (1.0, 1.0)
    assert p[:, 0].min() < -0.2 and p[:, 0].max() > 1.2  # padding around the box
    assert set(_native.point_texture_preset(name)) == set(_native.point_texture_preset())


def test_synthesis_layout_coverage_and_determinism(bumps):
    r = _native.synthesize_points(bumps["positions"], bumps["normals"], size=(1.5, 1.0), options=SMALL, seed=3)
    assert set(r) >= {"positions", "normals", "patches", "pairs", "spacing", "density", "times"}
    assert set(r["times"]) == {"search", "warp", "blend", "other"}
    p = r["positions"]
    assert p.dtype == np.float32 and p.shape == r["normals"].shape
    assert p[:, 0].min() >= 0 and p[:, 0].max() <= 1.5 + 1e-3 and p[:, 1].max() <= 1.0 + 1e-3
    # Every 0.25 cell holds about the exemplar's count per cell.
    inside = bumps["positions"]
    inside = inside[(inside[:, 0] >= 0) & (inside[:, 0] < 1) & (inside[:, 1] >= 0) & (inside[:, 1] < 1)]
    per_cell = len(inside) / 16
    h, _, _ = np.histogram2d(p[:, 0], p[:, 1], bins=[6, 4], range=[[0, 1.5], [0, 1.0]])
    assert h.min() > 0.6 * per_cell and h.max() < 1.4 * per_cell, (h, per_cell)
    again = _native.synthesize_points(bumps["positions"], bumps["normals"], size=(1.5, 1.0), options=SMALL, seed=3)
    np.testing.assert_array_equal(again["positions"], p)
    other = _native.synthesize_points(bumps["positions"], bumps["normals"], size=(1.5, 1.0), options=SMALL, seed=4)
    assert other["positions"].shape != p.shape or not np.array_equal(other["positions"], p)


def test_options_round_trip_and_unknown_keys(bumps):
    opts = _native.point_texture_preset("chainmail")
    assert opts["patch_size"] > 0 and opts["grid_resolution"] >= 4
    with pytest.raises(_native.InvalidInputError, match="unknown point texture option 'patchsize'"):
        _native.synthesize_points(bumps["positions"], bumps["normals"], options={"patchsize": 0.3})
    with pytest.raises(_native.InvalidInputError, match="unknown point-texture preset"):
        _native.point_texture_preset("moss")


TABLE1 = {"heightfield": (3, 30, 9, 7), "chainmail": (1, 10, 8, 6), "weave": (2, 15, 6, 5), "flowers": (2, 2, 6, 6)}


@pytest.mark.parametrize("name", sorted(TABLE1))
def test_presets_carry_table1_weights_through_the_binding(name):
    opts = _native.point_texture_preset(name)
    assert (opts["w_p"], opts["w_n"], opts["w_v"], opts["w_l"], opts["w_d"]) == (1, *TABLE1[name])


def test_bumps_is_the_height_field_preset_and_the_weights_change_the_output(bumps):
    assert _native.point_texture_preset("bumps") == _native.point_texture_preset("heightfield")
    with pytest.raises(_native.InvalidInputError, match="choose default, heightfield, bumps"):
        _native.point_texture_preset("height")
    runs = [_native.synthesize_points(bumps["positions"], bumps["normals"], size=(1.0, 1.0), seed=3,
                                      options={**_native.point_texture_preset(name), **SMALL})["positions"]
            for name in ("default", "heightfield")]
    assert runs[0].shape != runs[1].shape or not np.array_equal(*runs)


def _patch_score(img, ref, k=5):
    """Mean squared distance of each k x k window of img to its nearest window of ref (brute force)."""
    def windows(a):
        s = np.lib.stride_tricks.sliding_window_view(a, (k, k))
        return s.reshape(-1, k * k)
    a, b = windows(img)[::3], windows(ref)
    d = (a * a).sum(1)[:, None] - 2 * a @ b.T + (b * b).sum(1)[None, :]
    return float(np.maximum(d.min(1), 0).mean())


def _bump_image(n=48, seed=2):
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:n, 0:n].astype(np.float64)
    img = np.zeros((n, n))
    for _ in range(26):
        cx, cy, r = rng.uniform(0, n), rng.uniform(0, n), rng.uniform(3, 5)
        d2 = ((x - cx) ** 2 + (y - cy) ** 2) / r ** 2
        img = np.maximum(img, np.sqrt(np.clip(1 - d2, 0, 1)))
    return img


def test_height_field_output_scores_like_a_2d_synthesis():
    img = _bump_image()
    scale = 3.0  # grey 1 = 3 pixels high
    ex = _native.height_field_exemplar((img * scale).astype(np.float32), pixel_size=1.0, density=3.0, padding=6)
    w = 40
    r = _native.synthesize_points(ex["positions"], ex["normals"], box_min=ex["box_min"], box_max=ex["box_max"],
                                  size=(w, w), options={"patch_size": 16.0, "grid_resolution": 8}, seed=1)
    def raster(pts, x0, y0, n):
        """Mean height per pixel of the points over [x0, x0 + n) x [y0, y0 + n)."""
        ix = np.floor(pts[:, 0] - x0).astype(int)
        iy = np.floor(pts[:, 1] - y0).astype(int)
        ok = (ix >= 0) & (iy >= 0) & (ix < n) & (iy < n)
        s, c = np.zeros((n, n)), np.zeros((n, n))
        np.add.at(s, (iy[ok], ix[ok]), pts[ok, 2])
        np.add.at(c, (iy[ok], ix[ok]), 1)
        return np.where(c > 0, s / np.maximum(c, 1), 0) / scale, c

    out, count = raster(r["positions"], 0, 0, w)
    assert (count > 0).mean() > 0.95, "holes in the output"
    # The exemplar's own points rastered the same way: the reference carries
    # the same sampling noise as the output.
    ref, _ = raster(ex["positions"], 0, 0, img.shape[0])
    two_d = _native.synthesize_image(img[:, :, None].astype(np.float32), width=w, height=w, seed=1)["image"][:, :, 0]
    shuffled = np.random.default_rng(0).permutation(img.ravel())[: w * w].reshape(w, w)
    s3, s2 = _patch_score(out, ref), _patch_score(two_d, img)
    noise, bad = _patch_score(ref[8:-8, 8:-8], img), _patch_score(shuffled, img)
    assert s3 < 0.25 * bad, (s3, s2, noise, bad)
    assert s3 < 3.0 * s2 + 2.0 * noise, (s3, s2, noise, bad)


def _uv_sphere(radius, nu=48, nv=24):
    verts = [[0, 0, -radius], [0, 0, radius]]
    for j in range(1, nv):
        t = np.pi * j / nv - np.pi / 2
        for i in range(nu):
            a = 2 * np.pi * i / nu
            verts.append([radius * np.cos(t) * np.cos(a), radius * np.cos(t) * np.sin(a), radius * np.sin(t)])
    ring = lambda j, i: 2 + (j - 1) * nu + i % nu  # noqa: E731
    faces = [[0, ring(1, i + 1), ring(1, i)] for i in range(nu)]
    faces += [[1, ring(nv - 1, i), ring(nv - 1, i + 1)] for i in range(nu)]
    for j in range(1, nv - 1):
        for i in range(nu):
            faces += [[ring(j, i), ring(j, i + 1), ring(j + 1, i + 1)], [ring(j, i), ring(j + 1, i + 1), ring(j + 1, i)]]
    return np.array(verts, np.float64), np.array(faces, np.int32)


def test_on_mesh_follows_the_target():
    verts, faces = _uv_sphere(2.0)
    ex = _native.make_point_exemplar("bumps", density=300)
    field = np.cross([0.0, 0.0, 1.0], verts)  # around z
    r = _native.synthesize_points_on_mesh(ex["positions"], ex["normals"], verts, faces, field=field, scale=1.0,
                                          options={"patch_size": 0.5, "grid_resolution": 8})
    p = r["positions"]
    assert len(p) > 1000
    # Every point within the bumps' height (< 0.1) of the sphere, normals outward.
    d = np.linalg.norm(p, axis=1) - 2.0
    assert np.all(np.abs(d) < 0.15), np.abs(d).max()
    assert np.mean(np.einsum("ij,ij->i", r["normals"], p / np.linalg.norm(p, axis=1)[:, None]) > 0.5) > 0.9


def test_bad_inputs_name_the_fix(bumps):
    p, n = bumps["positions"], bumps["normals"]
    with pytest.raises(_native.InvalidInputError, match="oriented point set"):
        _native.synthesize_points(p, None)
    with pytest.raises(_native.InvalidInputError, match="N by 3"):
        _native.synthesize_points(p[:, :2], n)
    bad = p.copy()
    bad[3, 1] = np.nan
    with pytest.raises(_native.InvalidInputError, match="NaN"):
        _native.synthesize_points(bad, n)
    with pytest.raises(_native.InvalidInputError, match="no points"):
        _native.synthesize_points(np.zeros((0, 3), np.float32), np.zeros((0, 3), np.float32))
    with pytest.raises(_native.InvalidInputError, match="no point lies inside the exemplar box"):
        _native.synthesize_points(p, n, box_min=(5, 5), box_max=(6, 6))
    with pytest.raises(_native.InvalidInputError, match="lower the patch size"):
        _native.synthesize_points(p, n, options={"patch_size": 1.8})
    with pytest.raises(_native.OverBudgetError):
        _native.synthesize_points(p, n, size=(40, 40), memory_budget=1 << 20)
    with pytest.raises(_native.InvalidInputError, match="density"):
        _native.make_point_exemplar("weave", density=0)


def test_cancel_from_another_thread_and_progress(bumps):
    ctx = _native.ExecContext()
    out = {}

    def work():
        try:
            out["r"] = _native.synthesize_points(bumps["positions"], bumps["normals"], size=(4, 4),
                                                 options=SMALL, ctx=ctx)
        except _native.CancelledError as exc:
            out["cancelled"] = exc

    t = threading.Thread(target=work)
    t.start()
    while t.is_alive() and ctx.progress < 0.1:  # the GIL is released: this loop runs
        t.join(0.005)
    ctx.cancel()
    t.join()
    assert "cancelled" in out
    done = _native.ExecContext()
    _native.synthesize_points(bumps["positions"], bumps["normals"], size=(0.5, 0.5), options=SMALL, ctx=done)
    assert done.progress == pytest.approx(1.0)


def test_points_to_mesh_of_a_sphere():
    v, f = _uv_sphere(1.0, 64, 32)
    p, n = _native.sample_mesh_points(v, f, density=800, seed=2)
    assert len(p) == pytest.approx(800 * 4 * np.pi, rel=0.02)
    verts, faces = _native.points_to_mesh(p, n)
    assert faces.dtype == np.int32 and faces.shape[1] == 3 and len(faces) > 500
    np.testing.assert_allclose(np.linalg.norm(verts, axis=1), 1.0, atol=0.04)
    with pytest.raises(_native.InvalidInputError, match="oriented"):
        _native.points_to_mesh(p, None)


def _area(verts, faces):
    a, b, c = (verts[faces[:, k]] for k in range(3))
    return 0.5 * float(np.linalg.norm(np.cross(b - a, c - a), axis=1).sum())


@pytest.mark.parametrize("preset", ["bumps", "chainmail"])
def test_the_estimate_before_the_work_is_near_the_result(preset):
    """The estimate the CLI and the panel show, against a real run on a sphere,
    from the built-in's surface ratio (no exemplar built), as the add-on does."""
    verts, faces = _uv_sphere(2.0, 24, 12)
    ex = _native.make_point_exemplar(preset, density=300)
    density = 300 * _native.point_exemplar_surface_ratio(preset)
    options = {"patch_size": 0.5, "grid_resolution": 8}
    e = _native.estimate_points_on_mesh(density, area=_area(verts, faces), scale=1.0, options=options)
    r = _native.synthesize_points_on_mesh(ex["positions"], ex["normals"], verts, faces,
                                          field=np.cross([0.0, 0.0, 1.0], verts), scale=1.0, options=options)
    assert 0.5 * e["points"] < len(r["positions"]) < 1.5 * e["points"], (len(r["positions"]), e)
    assert 0.6 * e["patches"] < r["patches"] < 1.4 * e["patches"], (r["patches"], e)
    assert e["seconds"] == pytest.approx(e["points"] * _native.POINTS_SECONDS_PER_POINT)
    s = _native.default_points_scale(density, area=_area(verts, faces))
    assert _native.estimate_points_on_mesh(density, area=_area(verts, faces), scale=s)["points"] == pytest.approx(
        _native.POINTS_DEFAULT_OUTPUT)


def test_values_out_of_reach_are_refused_by_name(bumps):
    verts, faces = _uv_sphere(1.0, 12, 6)
    args = (bumps["positions"], bumps["normals"], verts, faces)
    with pytest.raises(_native.InvalidInputError, match="the direction field is zero everywhere"):
        _native.synthesize_points_on_mesh(*args, field=np.zeros_like(verts), options=SMALL)
    with pytest.raises(_native.OverBudgetError, match=r"about \d\.\de\+\d+ points .*raise the scale"):
        _native.synthesize_points_on_mesh(*args, field=np.cross([0.0, 0.0, 1.0], verts), scale=1e-12, options=SMALL)
    with pytest.raises(_native.InvalidInputError, match="less than two of the exemplar's point spacings"):
        _native.synthesize_points(bumps["positions"], bumps["normals"], options={**SMALL, "patch_size": 1e-9})
    pts = np.random.default_rng(0).normal(size=(200, 3))
    pts /= np.linalg.norm(pts, axis=1)[:, None]
    with pytest.raises(_native.InvalidInputError, match="give a spacing of at least"):  # not OpenVDB's ArithmeticError
        _native.points_to_mesh(pts, pts, spacing=1e-9)
