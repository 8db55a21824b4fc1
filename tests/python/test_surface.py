"""Texture synthesis on subdivision surfaces through the binding: limit
points, quality on a flat plane against the 2D synthesis, seamless face
borders, stripes following a field on a cylinder, determinism, cancel and
bad inputs."""
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from exsynth import _native

TEXTURES = Path(__file__).resolve().parents[2] / "assets" / "textures"


def grid(n, size=1.0):
    """n x n quads in the z = 0 plane, face (i, j) = index j * n + i, u along x."""
    xs = np.arange(n + 1) * size
    v = np.array([(x, y, 0.0) for y in xs for x in xs])
    faces = [(j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1, (j + 1) * (n + 1) + i)
             for j in range(n) for i in range(n)]
    return v, np.full(len(faces), 4, np.int32), np.array(faces, np.int32).ravel()


def tube(around=16, along=8, radius=1.0, length=3.0):
    a = 2 * np.pi * np.arange(around) / around
    v = np.array([(radius * np.cos(t), radius * np.sin(t), length * j / along) for j in range(along + 1) for t in a])
    faces = []
    for j in range(along):
        for i in range(around):
            p, q = j * around + i, j * around + (i + 1) % around
            faces.append((p, q, q + around, p + around))
    return v, np.full(len(faces), 4, np.int32), np.array(faces, np.int32).ravel()


def exemplar(size=48):
    img = Image.open(TEXTURES / "crackedground.png").convert("RGB")
    return np.asarray(img.resize((size, size), Image.LANCZOS))


def assemble(res, n, r):
    """The face maps of an n x n flat grid (r texels a face) as one image seen
    from +z (row 0 = the largest y), as the exemplar maps onto it (its x along
    the field, its rows down against v2 = n x v1)."""
    t = res["texels"]
    c = t.shape[1]
    out = np.zeros((n * r, n * r, c), np.float32)
    for f in range(n * n):
        i, j = f % n, f // n
        o = res["face_offset"][f]
        out[j * r:(j + 1) * r, i * r:(i + 1) * r] = t[o:o + r * r].reshape(r, r, c)
    return out[::-1]


def windows(img, n=8):
    h, w, _ = img.shape
    return np.stack([img[y:y + n, x:x + n].ravel() for y in range(h - n + 1) for x in range(w - n + 1)])


def nn_distance(img, ex, samples=80, seed=0):
    """Mean distance of random 8x8 windows to their nearest exemplar window
    (the solid tests' measure; no wrap: windows inside the image)."""
    rng = np.random.default_rng(seed)
    ref = windows(ex)
    h, w, _ = img.shape
    total = 0.0
    for _ in range(samples):
        y, x = rng.integers(0, h - 8), rng.integers(0, w - 8)
        total += np.sqrt(((ref - img[y:y + 8, x:x + 8].ravel()) ** 2).sum(1).min())
    return total / samples


def test_limit_points_of_a_flat_grid_are_the_affine_plane():
    v, fs, fv = grid(5)
    faces = np.array([6, 7, 12, 18])
    uv = np.array([[0.25, 0.5], [0.0, 1.0], [0.9, 0.1], [0.5, 0.5]])
    res = _native.surface_limit_points(v, fs, fv, faces, uv)
    want = np.stack([faces % 5 + uv[:, 0], faces // 5 + uv[:, 1], np.zeros(4)], 1)
    np.testing.assert_allclose(res["position"], want, atol=1e-9)
    np.testing.assert_allclose(res["du"], np.tile([1.0, 0, 0], (4, 1)), atol=1e-9)


def test_cube_corner_limit_is_the_closed_form():
    # Catmull-Clark limit of a cube corner (valence 3): (9 v + 4 sum e + sum d) / 24 = v / 2.
    v = np.array([[x, y, z] for z in (-1, 1) for y in (-1, 1) for x in (-1, 1)], float)
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    res = _native.surface_limit_points(v, np.full(6, 4), np.array(quads).ravel(), np.array([0]), np.zeros((1, 2)))
    np.testing.assert_allclose(res["position"][0], v[0] / 2, atol=1e-6)


@pytest.fixture(scope="module")
def flat():
    n, r = 4, 16
    v, fs, fv = grid(n)
    ex = exemplar()
    field = np.tile([1.0, 0.0, 0.0], (len(v), 1))
    res = _native.texture_surface(v, fs, fv, ex, field=field, face_resolution=r, seed=4)
    return n, r, ex.astype(np.float32) / 255.0, res


def test_result_arrays(flat):
    n, r, ex, res = flat
    assert res["texels"].shape == (n * n * r * r, 3)
    assert res["face_resolution"].tolist() == [r] * (n * n)
    h, w, c = res["atlas"].shape
    assert c == 3 and h * w >= n * n * (r + 4) ** 2
    assert res["quads"].shape[1] == 4 and res["corner_uvs"].shape == (4 * len(res["quads"]), 2)
    assert res["corner_uvs"].min() >= 0 and res["corner_uvs"].max() <= 1
    assert ex.min() - 1e-5 <= res["texels"].min() and res["texels"].max() <= ex.max() + 1e-5


def test_flat_plane_scores_like_the_2d_synthesis_and_borders_are_invisible(flat):
    n, r, ex, res = flat
    img = assemble(res, n, r)
    flat_2d = _native.synthesize_image((ex * 255).astype(np.uint8), width=n * r, height=n * r, seed=4)["image"]
    got, ref = nn_distance(img, ex), nn_distance(flat_2d, ex)
    shuffled = nn_distance(np.random.default_rng(2).permutation(img.reshape(-1, 3)).reshape(img.shape), ex)
    # Measured (seed 4): coherent 0.33, the 2D texture optimisation 0.26,
    # the same texels shuffled 0.9: within 1.3x of the 2D method, which
    # optimises exactly this distance.
    assert got < 1.6 * ref, f"surface {got:.3f} vs 2D {ref:.3f}"
    assert got < 0.6 * shuffled, f"surface {got:.3f} vs shuffled {shuffled:.3f}"
    # Across face borders texels differ no more than inside faces (columns and rows).
    dx = ((img[:, 1:] - img[:, :-1]) ** 2).sum(-1)
    dy = ((img[1:] - img[:-1]) ** 2).sum(-1)
    border = np.zeros(n * r - 1, bool)
    border[r - 1::r] = True  # pairs (r-1, r), (2r-1, 2r), ...: across a face edge
    inside = np.concatenate([dx[:, ~border].ravel(), dy[~border].ravel()]).mean()
    across = np.concatenate([dx[:, border].ravel(), dy[border].ravel()]).mean()
    assert across <= 1.3 * inside, f"across borders {across:.4f} vs inside {inside:.4f}"


def test_stripes_follow_the_field_on_a_cylinder():
    # Horizontal stripes (constant along exemplar x = the field's v1): with
    # the field along the axis they run along the cylinder, varying around it.
    y = np.arange(32)
    stripes = np.repeat((0.5 + 0.5 * np.sin(2 * np.pi * y / 8))[:, None], 32, 1).astype(np.float32)
    v, fs, fv = tube()
    field = np.tile([0.0, 0.0, 1.0], (len(v), 1))
    res = _native.texture_surface(v, fs, fv, stripes, field=field, texels_per_unit=12, segments=4, seed=1)
    # Value at each limit-mesh vertex: the atlas at its UV (nearest texel).
    atlas = res["atlas"][..., 0]
    h, w = atlas.shape
    uv = res["corner_uvs"]
    px = np.clip((uv[:, 0] * w).astype(int), 0, w - 1)
    py = np.clip(((1 - uv[:, 1]) * h).astype(int), 0, h - 1)
    value = np.zeros(len(res["vertices"]))
    value[res["quads"].ravel()] = atlas[py, px]
    p = res["vertices"]
    # Neighbouring vertices along the axis vs around it, away from the open ends.
    q = res["quads"]
    a, b = q.ravel(), np.roll(q, -1, axis=1).ravel()
    d = p[b] - p[a]
    keep = (p[a, 2] > 0.5) & (p[a, 2] < 2.5)
    along = keep & (np.abs(d[:, 2]) > 3 * np.hypot(d[:, 0], d[:, 1]))
    around = keep & (np.hypot(d[:, 0], d[:, 1]) > 3 * np.abs(d[:, 2]))
    step_along = np.abs(value[b] - value[a])[along] / np.linalg.norm(d[along], axis=1)
    step_around = np.abs(value[b] - value[a])[around] / np.linalg.norm(d[around], axis=1)
    assert along.sum() > 100 and around.sum() > 100
    # Measured: the value changes ~10x faster around the cylinder than along it.
    assert step_around.mean() > 4 * step_along.mean(), (step_around.mean(), step_along.mean())


def test_same_seed_same_result_other_seed_other_result():
    v, fs, fv = grid(2)
    ex = exemplar(32)
    a = _native.texture_surface(v, fs, fv, ex, face_resolution=8, seed=3)
    b = _native.texture_surface(v, fs, fv, ex, face_resolution=8, seed=3)
    c = _native.texture_surface(v, fs, fv, ex, face_resolution=8, seed=4)
    np.testing.assert_array_equal(a["atlas"], b["atlas"])
    assert not np.array_equal(a["atlas"], c["atlas"])


def test_multiscale_on_a_flat_plane_scores_near_the_2d_synthesis_and_coherence_helps(flat):
    n, r, ex, _ = flat
    v, fs, fv = grid(n)
    field = np.tile([1.0, 0.0, 0.0], (len(v), 1))
    ex8 = (ex * 255).astype(np.uint8)
    got = {c: np.mean([nn_distance(assemble(_native.texture_surface(
        v, fs, fv, ex8, field=field, face_resolution=r, seed=seed, method="multiscale", coherence=c), n, r), ex)
        for seed in (4, 5, 6, 7, 8)]) for c in (0.0, 1.0)}
    # The 2D reference is the texture optimisation by name (the default 2D
    # method changed to coordinate synthesis, 0.43 at seed 4 in this measure).
    ref = nn_distance(_native.synthesize_image(ex8, width=n * r, height=n * r, seed=4,
                                               method="optimization")["image"], ex)
    # Measured (mean of seeds 4-8, 80 windows): 0.365 with coherence (the
    # default), 0.446 without (Wei-Levoy's search alone); the 2D optimisation
    # 0.309 at seed 4 (0.353 over seeds 4-8, 0.341 over 4-23): 1.18x the
    # seed-4 figure, 1.03x the same seeds'. Before the coarsest level took
    # coherent candidates: 0.387 (1.25x); before the finer levels started
    # from the coarser level's sources upsampled: 0.451 (1.46x). (One seed
    # alone is too noisy to show the coherence gap.) The absolute bound
    # keeps the test about the surface method when the 2D synthesis changes.
    assert got[1.0] < 0.38, f"multiscale {got[1.0]:.3f}"
    assert got[1.0] < 1.25 * ref, f"multiscale {got[1.0]:.3f} vs 2D {ref:.3f}"
    assert got[1.0] < 0.98 * got[0.0], f"with coherence {got[1.0]:.3f} vs without {got[0.0]:.3f}"


def test_multiscale_and_channels():
    v, fs, fv = grid(2)
    rgb = exemplar(32).astype(np.float32) / 255
    height = rgb.mean(-1, keepdims=True)
    ex = np.concatenate([rgb, height], -1)  # colour + height, synthesized together
    res = _native.texture_surface(v, fs, fv, ex, method="multiscale", face_resolution=8, seed=2,
                                  displacement_channel=3, displacement_scale=0.1)
    t = res["texels"]
    assert t.shape[1] == 4
    # The height channel stays the mean of the colour it came with (same source pixel).
    np.testing.assert_allclose(t[:, 3], t[:, :3].mean(1), atol=1e-5)
    assert np.ptp(res["vertices"][:, 2]) > 0.01  # displaced out of the plane


def test_cancel_and_progress():
    v, fs, fv = grid(2)
    ctx = _native.ExecContext()
    ctx.cancel()
    with pytest.raises(_native.CancelledError):
        _native.texture_surface(v, fs, fv, exemplar(16), face_resolution=8, ctx=ctx)
    ctx = _native.ExecContext()
    _native.texture_surface(v, fs, fv, exemplar(16), face_resolution=8, ctx=ctx)
    assert ctx.progress == pytest.approx(1.0)


@pytest.mark.parametrize("mesh, words", [
    ("nonmanifold", "non-manifold"),
    ("zero_area", "zero area"),
    ("no_faces", "no faces"),
    ("flipped", "inconsistently oriented"),
])
def test_bad_meshes(mesh, words):
    v, fs, fv = grid(2)
    if mesh == "nonmanifold":
        v = np.vstack([v, [[0, 0, -1], [1, 0, -1]]])
        fs = np.append(fs, [4, 4])
        fv = np.append(fv, [1, 0, 9, 10, 0, 1, 10, 9])
    elif mesh == "zero_area":
        v = np.vstack([v, [[5, 0, 0], [6, 0, 0], [7, 0, 0]]])
        fs = np.append(fs, 3)
        fv = np.append(fv, [9, 10, 11])
    elif mesh == "no_faces":
        fs, fv = np.zeros(0, np.int32), np.zeros(0, np.int32)
    else:
        fv = fv.copy()
        fv[[1, 3]] = fv[[3, 1]]
    with pytest.raises(_native.InvalidInputError, match=words):
        _native.texture_surface(v, fs, fv, exemplar(16), face_resolution=4)


def test_bad_options_and_arrays():
    v, fs, fv = grid(2)
    with pytest.raises(_native.InvalidInputError, match="smaller than the 5x5 neighbourhood"):
        _native.texture_surface(v, fs, fv, exemplar(4))
    with pytest.raises(_native.InvalidInputError, match="smaller than the 9x9"):
        _native.texture_surface(v, fs, fv, exemplar(8), method="multiscale")
    with pytest.raises(_native.OverBudgetError):
        _native.texture_surface(v, fs, fv, exemplar(16), face_resolution=512, memory_budget=1 << 20)
    with pytest.raises(_native.InvalidInputError, match="unknown option 'colour'"):
        _native.texture_surface(v, fs, fv, exemplar(16), colour=1)
    with pytest.raises(_native.InvalidInputError, match="17 channels; at most 16"):
        _native.texture_surface(v, fs, fv, np.zeros((16, 16, 17), np.float32))
    with pytest.raises(_native.InvalidInputError, match="non-finite"):
        _native.texture_surface(v, fs, fv, np.full((16, 16, 3), np.nan, np.float32))
    with pytest.raises(_native.InvalidInputError, match="'exemplar' must have dtype"):
        _native.texture_surface(v, fs, fv, np.zeros((16, 16, 3), np.int8))
    with pytest.raises(_native.InvalidInputError, match="method"):
        _native.texture_surface(v, fs, fv, exemplar(16), method="fast")
    with pytest.raises(_native.InvalidInputError, match="field"):
        _native.texture_surface(v, fs, fv, exemplar(16), field=np.zeros((3, 3)))
    with pytest.raises(_native.InvalidInputError, match="vertices"):
        _native.texture_surface(v[:, :2], fs, fv, exemplar(16))
    with pytest.raises(_native.InvalidInputError, match="face_vertices"):
        _native.texture_surface(v, fs, fv.astype(np.float32), exemplar(16))
    with pytest.raises(_native.InvalidInputError, match="out of range"):
        _native.texture_surface(v, fs, np.where(fv == 8, 99, fv), exemplar(16))
    with pytest.raises(_native.InvalidInputError, match="ptex face"):
        _native.surface_limit_points(v, fs, fv, np.array([7]), np.zeros((1, 2)))
    assert _native.surface_texel_count(v, fs, fv, face_resolution=8) == 4 * 64


def test_vertex_charts_sample_the_flat_grid_exactly_as_walks_do(flat):
    # On a flat grid away from its corners the charts are exactly linear: the
    # same texture as walking every sample (vertex_charts=False), most samples
    # placed through the charts; both methods.
    n, r, ex, res = flat
    v, fs, fv = grid(n)
    field = np.tile([1.0, 0.0, 0.0], (len(v), 1))
    ex8 = (ex * 255).astype(np.uint8)
    for method in ("coherent", "multiscale"):
        a = _native.texture_surface(v, fs, fv, ex8, field=field, face_resolution=r, seed=5, method=method)
        b = _native.texture_surface(v, fs, fv, ex8, field=field, face_resolution=r, seed=5, method=method,
                                    vertex_charts=False)
        np.testing.assert_array_equal(a["texels"], b["texels"])
        assert b["chart_samples"] == 0 and b["walked_samples"] > 0
        # (4 x 4 faces: the stars next to the corners walk; measured 42-43 % in charts)
        assert a["chart_samples"] > 0.3 * (a["chart_samples"] + a["walked_samples"]), method


def triangulated_grid(n):
    """n x n unit squares in the z = 0 plane, each split into two triangles
    (the cow's structure: valence-3 face centres, valence-4 edge midpoints,
    valence-6 vertices)."""
    xs = np.arange(n + 1, dtype=float)
    v = np.array([(x, y, 0.0) for y in xs for x in xs])
    faces = []
    for j in range(n):
        for i in range(n):
            a, b, c, d = j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1, (j + 1) * (n + 1) + i
            faces += [(a, b, c), (a, c, d)]
    return v, np.full(len(faces), 3, np.int32), np.array(faces, np.int32).ravel()


@pytest.mark.parametrize("method", ["coherent", "multiscale"])
def test_patches_on_a_triangulated_plane_copy_the_exemplar_exactly(method):
    # Coherent synthesis copies patches: neighbouring texels of one patch
    # have sources that differ by exactly their offset on the surface (the
    # kites' square texel grids are sheared, so the offsets are fractional).
    # Neighbour offsets taken from the landing points (within the walk's or
    # chart's tolerance of the asked offset) drifted the sources of a patch
    # apart: median 0.10 px, 90th percentile 0.36 px, so a patch's texels
    # rounded to other pixels than a copy would. Now 0 / 0 (99th: 0.15).
    n = 6
    v, fs, fv = triangulated_grid(n)
    ex = exemplar()
    field = np.tile([1.0, 0.0, 0.0], (len(v), 1))
    res = _native.texture_surface(v, fs, fv, ex, field=field, texels_per_unit=12, seed=4, method=method)
    r, off = res["face_resolution"], res["face_offset"]
    faces = np.repeat(np.arange(len(r)), r * r)
    k = np.arange(len(faces)) - off[faces]
    uv = np.stack([(k % r[faces] + 0.5) / r[faces], (k // r[faces] + 0.5) / r[faces]], 1)
    pos = _native.surface_limit_points(v, fs, fv, faces, uv)["position"]
    h = res["sample_spacing"]
    drift = res["source"] - np.stack([pos[:, 0], -pos[:, 1]], 1) / h  # constant over a patch
    # Texel pairs within 1.5 spacings (brute force), same patch = sources within a pixel of the offset.
    d2 = ((pos[:, None, :2] - pos[None, :, :2]) ** 2).sum(-1)
    i, j = np.nonzero(np.triu(d2 < (1.5 * h) ** 2, 1))
    mismatch = np.linalg.norm(drift[i] - drift[j], axis=1)
    same = mismatch < 1.0
    if method == "coherent":
        assert same.mean() > 0.85, same.mean()  # measured 0.93: large patches
        assert np.percentile(mismatch[same], 90) < 0.05, np.percentile(mismatch[same], 90)
    else:
        # Multiscale: float sources and chord offsets as the coherent method
        # (whole-pixel sources: median 0.45 px); its patches are smaller
        # (measured: 0.66 of the pairs in one patch, 90th percentile 0.68 px).
        assert same.mean() > 0.5, same.mean()
        assert np.median(mismatch[same]) < 0.02, np.median(mismatch[same])


def test_multiscale_seeds_give_different_textures(flat):
    # The coarsest level's causal pass followed from its first texel's random
    # pixel alone: seeds 8 / 17, 9 / 18, 10 / 19 and 11 / 16 gave the same
    # texture on the 4 x 4 plane (and 8 / 17 shared half its texels before
    # the coarsest level took coherent candidates). Now the texels of the
    # first row keep random pixels there: no pair of seeds 4-23 shares more
    # than a fifth of its texels (measured: none shares 20 %).
    n, r, ex, _ = flat
    v, fs, fv = grid(n)
    field = np.tile([1.0, 0.0, 0.0], (len(v), 1))
    ex8 = (ex * 255).astype(np.uint8)
    seeds = (8, 9, 10, 11, 16, 17, 18, 19)
    runs = [_native.texture_surface(v, fs, fv, ex8, field=field, face_resolution=r, seed=s, method="multiscale")["texels"]
            for s in seeds]
    for i in range(len(runs)):
        for j in range(i + 1, len(runs)):
            shared = (np.abs(runs[i] - runs[j]).max(1) < 1e-6).mean()
            assert shared < 0.2, (seeds[i], seeds[j], shared)


@pytest.mark.parametrize("size, seeds", [(32, (9, 19)), (24, (4, 12))])
def test_multiscale_seeds_differ_on_a_small_exemplar(size, seeds):
    # With the exact nearest at the coarsest level, these pairs grew the same
    # texture from a small exemplar at 8 texels a face (shared 0.995 / 0.959
    # of their texels, the worst of seeds 4-23); the coarsest level now picks
    # among its near-best matches (0.425 / 0.221 measured).
    n, r = 4, 8
    v, fs, fv = grid(n)
    field = np.tile([1.0, 0.0, 0.0], (len(v), 1))
    a, b = (_native.texture_surface(v, fs, fv, exemplar(size), field=field, face_resolution=r, seed=s,
                                    method="multiscale")["texels"] for s in seeds)
    shared = (np.abs(a - b).max(1) < 1e-6).mean()
    assert shared < 0.6, shared
