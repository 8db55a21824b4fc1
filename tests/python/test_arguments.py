"""Every argument of every function of exsynth._native is checked before the engine runs.

A wrong type or an out-of-range number must raise InvalidInputError (a ValueError) naming the
argument and its valid range -- never pybind11's TypeError with a signature dump (which also
prints every array passed), an OverflowError or "Unable to cast".
"""
import math

import numpy as np
import pytest

from exsynth import _native

from conftest import box

VERTS, FACES = box()
SDF = np.linspace(-1, 1, 6 * 6 * 6, dtype=np.float32).reshape(6, 6, 6)
VOL = np.ones((4, 4, 4), np.float32)
POS = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]], np.float32)
UVS = np.array([[[0.25, 0.25], [0.5, 0.25], [0.25, 0.5]]], np.float32)
IMG = np.random.default_rng(0).random((16, 16, 3)).astype(np.float32)
PTS = np.array([[0, 0, 0], [1, 1, 1]], np.float32)
DIRS = np.array([[1, 0, 0], [1, 0, 0]], np.float32)
GIVEN = np.zeros_like(VERTS)
GIVEN[1] = [1, 0, 0]
# One quad (a control mesh for the surface functions) and a flat height field.
QUAD_V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
QUAD_SIZES = np.array([4], np.int32)
QUAD_FV = np.array([0, 1, 2, 3], np.int32)
HEIGHTS = np.zeros((20, 20), np.float32)


def call(name, *args, **kwargs):
    return lambda **over: getattr(_native, name)(*args, **{**kwargs, **over})


# function -> (a call with valid arguments taking overrides, {argument: kind})
# kinds: ("int", lo, hi), "seed", "budget", ("real", lo, hi) with None = unbounded,
# "bool", "ctx", "str".
FUNCTIONS = {
    "voxelize": (call("voxelize", VERTS, FACES), {
        "resolution": ("int", 1, 16384), "padding": ("int", 0, 1024), "supersample": ("int", 1, 8),
        "voxel_size": ("real", 0, None), "compute_sdf": "bool", "memory_budget": "budget", "seed": "seed",
        "ctx": "ctx"}),
    "model_thickness": (call("model_thickness", VERTS, FACES, resolution=16), {
        "resolution": ("int", 16, 1024), "percentile": ("real", 0, 100),
        "pattern_per_thickness": ("real", 0, 100), "memory_budget": "budget", "seed": "seed",
        "ctx": "ctx"}),
    "volume_frames": (call("volume_frames", SDF, [0, 0, 0], 1.0, PTS, DIRS), {
        "band": ("real", 0, None), "smoothing_steps": ("int", 0, 1000), "ctx": "ctx"}),
    "synthesize_analogy": (call("synthesize_analogy", SDF, SDF, SDF), {
        "voxel_size": ("real", 0, None), "levels": ("int", 1, 6), "fine_size": ("int", 3, 9),
        "coarse_size": ("int", 1, 7), "sweeps": ("int", 1, 8), "pca_variance": ("real", 0, 1),
        "max_pca_dims": ("int", 1, 4096), "ann_eps": ("real", 0, None), "coherence": ("real", 0, None),
        "coherence_slack": ("real", 0, None), "cull_distance": ("real", None, None), "remove_debris": "bool",
        "memory_budget": "budget", "seed": "seed", "ctx": "ctx"}),
    "sample_volume": (call("sample_volume", VOL, [0, 0, 0], 1.0, PTS), {"wrap": "bool", "interpolation": "str",
                                                                         "ctx": "ctx"}),
    "bake_volume_to_uv": (call("bake_volume_to_uv", VOL, [0, 0, 0], 1.0, POS, UVS, width=8, height=8), {
        "width": ("int", 1, 16384), "height": ("int", 1, 16384), "margin": ("int", 0, 64), "wrap": "bool",
        "interpolation": "str", "ctx": "ctx"}),
    "isosurface": (call("isosurface", SDF, [0, 0, 0], voxel_size=1.0), {
        "voxel_size": ("real", 0, None), "isovalue": ("real", None, None), "adaptivity": ("real", 0, 1),
        "invert": "bool", "ctx": "ctx"}),
    "gaussian_pyramid": (call("gaussian_pyramid", VOL), {"levels": ("int", 1, 32), "wrap": "bool", "ctx": "ctx"}),
    "synthesize_solid": (call("synthesize_solid", IMG, size=8, levels=1, iterations=1), {
        "size": ("int", 1, 2048), "views": "str", "levels": ("int", 1, 8), "neighborhood": ("int", 3, 32),
        "iterations": ("int", 1, 100), "finest_iterations": ("int", -1, 100), "r": ("real", 0, 2), "pca_variance": ("real", 0, 1),
        "max_pca_dims": ("int", 1, 4096), "search": "str", "coherence_k": ("int", 0, 64),
        "random_candidates": ("int", 0, 64), "ann_eps": ("real", 0, 1e6), "histogram_matching": "bool",
        "histogram_bins": ("int", 2, 256), "histogram_strength": ("real", 0, 16), "mean_shift": "bool",
        "feature_weight": ("real", 0, 100),
        "feature_threshold": ("real", 0, 10), "feature_scale": ("int", 0, 64), "rotate_exemplar": "str",
        "exemplar_values": "bool", "histogram_values": ("real", 0, 100), "histogram_value_rounds": ("int", 1, 64),
        "histogram_value_window": ("real", 0, 1), "structure_sigma": ("real", 0, 8),
        "tileable": "bool", "memory_budget": "budget", "seed": "seed", "ctx": "ctx",
        "method": "str", "coordinate_coherence_k": ("int", 0, 16)}),
    "synthesize_image": (call("synthesize_image", IMG, width=8, height=8, levels=1, iterations=1), {
        "width": ("int", 1, 16384), "height": ("int", 1, 16384), "levels": ("int", 1, 8), "r": ("real", 0, 2),
        "exemplar_values": "bool", "memory_budget": "budget", "seed": "seed", "tileable": "bool", "ctx": "ctx",
        "method": "str", "jitter": ("real", 0, 4), "jitter_from": ("int", 1, 1024), "corrections": ("int", 0, 16),
        "candidates_k": ("int", 1, 16), "coherence": ("real", 0, 100), "wide_below": ("int", 0, 1024),
        "appearance_window": ("int", 1, 15), "appearance_dims": ("int", 1, 64),
        "coarsest_spacing": ("int", 0, 1024), "exhaustive": "bool", "refine_passes": ("int", 0, 16),
        "refine_patch": ("int", 2, 32), "refine_stride": ("int", 1, 32), "refine_random": ("int", 0, 16),
        "refine_medoid": "bool", "cut_passes": ("int", 0, 16), "cut_window": ("int", 4, 256),
        "cut_labels": ("int", 1, 256), "cut_leave": ("real", 0, 1e6), "cut_reach": ("int", 0, 256),
        "cut_radius": ("int", 0, 4), "cut_matches": "bool"}),
    "diffuse_direction_field": (call("diffuse_direction_field", VERTS, FACES, GIVEN), {
        "weights": "str", "seed": "seed", "ctx": "ctx"}),
    "preset_direction_field": (call("preset_direction_field", VERTS, FACES), {"preset": "str", "ctx": "ctx"}),
    "make_exemplar_pair": (call("make_exemplar_pair", preset="dilate", resolution=8), {
        "preset": "str", "resolution": ("int", 8, 512), "thickness": ("real", 0, None),
        "spacing": ("real", 0, None), "jitter": ("real", 0, 0.25), "dilation": ("real", 0, None),
        "groove_direction": "str", "memory_budget": "budget", "seed": "seed", "ctx": "ctx"}),
    "check_exemplar_pair": (call("check_exemplar_pair", preset="dilate", resolution=8), {
        "preset": "str", "resolution": ("int", 8, 512), "thickness": ("real", 0, None),
        "spacing": ("real", 0, None), "jitter": ("real", 0, 0.25), "dilation": ("real", 0, None),
        "groove_direction": "str", "memory_budget": "budget"}),
    "exemplar_feature_stretch": (call("exemplar_feature_stretch", IMG), {}),
    "min_texture_size": (call("min_texture_size"), {"levels": ("int", 1, 8), "neighborhood": ("int", 3, 32)}),
    "voxel_grid": (call("voxel_grid", (0, 0, 0), (1, 2, 3)), {
        "resolution": ("int", 1, 2 ** 14), "voxel_size": ("real", 0, None), "padding": ("int", 0, 1024)}),
    "analogy_padding": (call("analogy_padding"), {"fine_size": ("int", 3, 9), "coarse_size": ("int", 1, 7)}),
    "resolution_for_pattern": (call("resolution_for_pattern", resolution=128, pattern_scale=0.3), {
        "resolution": ("int", 1, 2 ** 15), "pattern_scale": ("real", 0, None)}),
    "validate_mesh": (call("validate_mesh", VERTS, FACES), {"name": "str"}),
    "point_texture_preset": (call("point_texture_preset"), {"name": "str"}),
    "make_point_exemplar": (lambda **over: _native.make_point_exemplar(**{"name": "bumps", "density": 200.0, **over}), {
        "name": "str", "density": ("real", 0, None), "padding": ("real", 0, 2), "seed": "seed", "ctx": "ctx"}),
    "height_field_exemplar": (call("height_field_exemplar", HEIGHTS, padding=2), {
        "pixel_size": ("real", 0, None), "density": ("real", 0, None), "padding": ("int", 0, 2 ** 20),
        "seed": "seed", "ctx": "ctx"}),
    "sample_mesh_points": (call("sample_mesh_points", VERTS, FACES, density=10.0), {
        "density": ("real", 0, None), "seed": "seed", "memory_budget": "budget", "ctx": "ctx"}),
    "synthesize_points": (call("synthesize_points", PTS, DIRS), {
        "memory_budget": "budget", "seed": "seed", "ctx": "ctx"}),
    "synthesize_points_on_mesh": (call("synthesize_points_on_mesh", PTS, DIRS, VERTS, FACES,
                                       field=np.ones_like(VERTS)), {
        "scale": ("real", 0, None), "memory_budget": "budget", "seed": "seed", "ctx": "ctx"}),
    "estimate_points_on_mesh": (call("estimate_points_on_mesh", density=1000.0, area=2.0, scale=0.5), {
        "density": ("real", 0, None), "area": ("real", 0, None), "scale": ("real", 0, None)}),
    "default_points_scale": (call("default_points_scale", density=1000.0, area=2.0), {
        "density": ("real", 0, None), "area": ("real", 0, None)}),
    "point_exemplar_surface_ratio": (
        lambda **over: _native.point_exemplar_surface_ratio(**{"name": "chainmail", **over}), {"name": "str"}),
    "points_to_mesh": (call("points_to_mesh", PTS, DIRS), {
        "spacing": ("real", None, None), "radius": ("real", 0, None), "voxel": ("real", 0, None),
        "smoothing": ("int", 0, 64), "memory_budget": "budget", "ctx": "ctx"}),
    "texture_surface": (call("texture_surface", QUAD_V, QUAD_SIZES, QUAD_FV, IMG, face_resolution=4), {
        "method": "str", "texels_per_unit": ("real", 0, None), "face_resolution": ("int", 1, 16384),
        "min_face_resolution": ("int", 1, 16384), "max_face_resolution": ("int", 1, 16384),
        "exemplar_scale": ("real", 0, None), "coherent_radius": ("int", 1, 5), "coherent_passes": ("int", 1, 8),
        "levels": ("int", 0, 6), "fine_neighborhood": ("int", 3, 11), "coarse_neighborhood": ("int", 1, 11),
        "knn": ("int", 1, 64), "knn_tolerance": ("real", 0, None), "coherence": ("real", 0, None), "pca_variance": ("real", 0, 1),
        "max_pca_dims": ("int", 1, 4096), "tileable_exemplar": "bool", "vertex_charts": "bool",
        "memory_budget": "budget", "seed": "seed", "gutter": ("int", 0, 16), "segments": ("int", 1, 64), "displacement_channel": ("int", -1, 15),
        "displacement_scale": ("real", None, None), "displacement_midlevel": ("real", None, None), "ctx": "ctx"}),
    "surface_texel_count": (call("surface_texel_count", QUAD_V, QUAD_SIZES, QUAD_FV, face_resolution=4), {
        "method": "str", "texels_per_unit": ("real", 0, None), "face_resolution": ("int", 1, 16384),
        "levels": ("int", 0, 6), "memory_budget": "budget", "seed": "seed"}),
    "surface_limit_points": (call("surface_limit_points", QUAD_V, QUAD_SIZES, QUAD_FV, [0], [[0.5, 0.5]]), {}),
}


def fmt(x):
    return f"{x:.10g}"


def bad_values(kind):
    """(value, words the message must contain) for an argument of this kind."""
    if kind == "seed":
        rng = "between 0 and 2**64 - 1"
        return [(-1, [rng, "-1"]), (2 ** 64, [rng]), (1.5, [rng, "float"]), ("7", [rng, "str"]), (None, [rng])]
    if kind == "budget":
        return [(-1, ["between 0 and", "bytes"]), (2 ** 63, ["between 0 and"]), (1e30, ["integer", "float"]),
                (math.inf, ["integer"]), ("8G", ["integer", "str"])]
    if kind == "bool":
        return [("yes", ["True or False"]), (2, ["True or False"]), (None, ["True or False"])]
    if kind == "ctx":
        return [(5, ["ExecContext or None"]), ("ctx", ["ExecContext or None"])]
    if kind == "str":
        return [(5, ["a string"]), (None, ["a string"])]
    if kind[0] == "int":
        _, lo, hi = kind
        rng = f"an integer between {lo} and {hi}"
        return [(lo - 1, [rng]), (hi + 1, [rng]), (2 ** 31, [rng]), (-2 ** 64, [rng]), (2.5, [rng, "float"]),
                ("8", [rng, "str"]), (None, [rng])]
    _, lo, hi = kind
    rng = "a number in" if lo is not None and hi is not None else "a finite number"
    out = [(math.nan, [rng]), (math.inf, [rng]), ("1", [rng, "str"]), (None, [rng, "None"]), (10 ** 400, [rng])]
    if lo is not None:
        out.append((lo - 1, [fmt(lo)]))
    if hi is not None:
        out.append((hi + 1, [fmt(hi)]))
    return out


CASES = [(fn, arg, value, words)
         for fn, (_, args) in FUNCTIONS.items()
         for arg, kind in args.items()
         for value, words in bad_values(kind)]


@pytest.mark.parametrize("fn, arg, value, words", CASES,
                         ids=[f"{c[0]}-{c[1]}-{c[2]!r}"[:80] for c in CASES])
def test_bad_argument_is_an_invalid_input_error_naming_it(fn, arg, value, words):
    run, _ = FUNCTIONS[fn]
    with pytest.raises(_native.InvalidInputError) as info:
        run(**{arg: value})
    msg = str(info.value)
    assert f"'{arg}'" in msg or arg in msg, msg
    for w in words:
        assert w in msg, msg
    assert "incompatible function arguments" not in msg and "Unable to cast" not in msg
    assert len(msg) < 400, msg  # no dump of the arrays passed


@pytest.mark.parametrize("fn", sorted(FUNCTIONS))
def test_a_misspelt_keyword_is_named_with_the_options(fn):
    run, args = FUNCTIONS[fn]
    with pytest.raises(_native.InvalidInputError) as info:
        run(resolutoin=3)
    msg = str(info.value)
    # The message lists every option (synthesize_solid's ~28 names: ~440 characters), no arrays.
    assert "unknown option 'resolutoin'" in msg and "options" in msg and len(msg) < 600, msg


def test_invalid_input_error_is_a_value_error():
    assert issubclass(_native.InvalidInputError, ValueError)


def test_every_function_of_the_module_is_covered():
    functions = {n for n in dir(_native) if callable(getattr(_native, n)) and not isinstance(getattr(_native, n), type)}
    covered = set(FUNCTIONS) | {"write_vdb", "read_vdb", "with_threads"}  # the last two: below, test_threads.py
    assert functions == covered, functions ^ covered


@pytest.mark.parametrize("lo, hi, words", [
    (0.9, 0.1, ["'lo' must not exceed 'hi'"]),
    (math.nan, 2, ["'lo'", "[0, 1]"]),
    (0.1, 2, ["'hi'", "[0, 1]"]),
    (-0.5, 0.5, ["'lo'", "[0, 1]"]),
    ("0", 1, ["'lo'", "str"]),
    (0, None, ["'hi'"]),
])
def test_set_span_refuses_a_bad_span(lo, hi, words):
    ctx = _native.ExecContext()
    with pytest.raises(_native.InvalidInputError) as info:
        ctx.set_span(lo, hi)
    for w in words:
        assert w in str(info.value), str(info.value)
    ctx.set_span(0.2, 0.7)
    assert ctx.progress == pytest.approx(0.2)


# ---- array arguments: lists are converted by NumPy, anything else is refused by name ----------

ARRAYS = {
    "voxelize": (lambda **a: _native.voxelize(a.get("vertices", VERTS), a.get("faces", FACES), resolution=8),
                 ["vertices", "faces"]),
    "model_thickness": (lambda **a: _native.model_thickness(a.get("vertices", VERTS), a.get("faces", FACES),
                                                            resolution=16), ["vertices", "faces"]),
    "volume_frames": (lambda **a: _native.volume_frames(a.get("sdf", SDF), a.get("origin", [0, 0, 0]), 1.0,
                                                        a.get("points", PTS), a.get("vectors", DIRS)),
                      ["sdf", "origin", "points", "vectors"]),
    "synthesize_analogy": (lambda **a: _native.synthesize_analogy(a.get("a", SDF), a.get("a_prime", SDF), a.get("b", SDF),
                                                                  a_region=a.get("a_region")),
                           ["a", "a_prime", "b", "a_region"]),
    "sample_volume": (lambda **a: _native.sample_volume(a.get("volume", VOL), a.get("origin", [0, 0, 0]), 1.0,
                                                        a.get("points", PTS)), ["volume", "origin", "points"]),
    "bake_volume_to_uv": (lambda **a: _native.bake_volume_to_uv(VOL, [0, 0, 0], 1.0, a.get("positions", POS),
                                                                a.get("uvs", UVS), 8, 8), ["positions", "uvs"]),
    "isosurface": (lambda **a: _native.isosurface(a.get("volume", SDF), a.get("origin", [0, 0, 0]), 1.0),
                   ["volume", "origin"]),
    "gaussian_pyramid": (lambda **a: _native.gaussian_pyramid(a.get("volume", VOL)), ["volume"]),
    "synthesize_solid": (lambda **a: _native.synthesize_solid(a.get("exemplar", IMG), size=8, levels=1,
                                                              constraint=a.get("constraint")),
                         ["exemplar", "constraint"]),
    "synthesize_image": (lambda **a: _native.synthesize_image(a.get("exemplar", IMG), width=8, height=8, levels=1),
                         ["exemplar"]),
    "diffuse_direction_field": (lambda **a: _native.diffuse_direction_field(
        a.get("vertices", VERTS), a.get("faces", FACES), a.get("given", GIVEN)), ["vertices", "faces", "given"]),
    "preset_direction_field": (lambda **a: _native.preset_direction_field(
        a.get("vertices", VERTS), a.get("faces", FACES), axis=a.get("axis", (0, 0, 1))), ["vertices", "faces", "axis"]),
    "validate_mesh": (lambda **a: _native.validate_mesh(a.get("vertices", VERTS), a.get("faces", FACES)),
                      ["vertices", "faces"]),
    "height_field_exemplar": (lambda **a: _native.height_field_exemplar(a.get("heights", HEIGHTS), padding=2),
                              ["heights"]),
    "sample_mesh_points": (lambda **a: _native.sample_mesh_points(a.get("vertices", VERTS), a.get("faces", FACES),
                                                                  density=10.0), ["vertices", "faces"]),
    "synthesize_points": (lambda **a: _native.synthesize_points(
        a.get("positions", PTS), a.get("normals", DIRS), box_min=a.get("box_min", (0, 0)),
        box_max=a.get("box_max", (1, 1)), size=a.get("size", (2, 2))),
        ["positions", "normals", "box_min", "box_max", "size"]),
    "points_to_mesh": (lambda **a: _native.points_to_mesh(a.get("positions", PTS), a.get("normals", DIRS)),
                       ["positions", "normals"]),
    "texture_surface": (lambda **a: _native.texture_surface(
        a.get("vertices", QUAD_V), a.get("face_sizes", QUAD_SIZES), a.get("face_vertices", QUAD_FV),
        a.get("exemplar", IMG), field=a.get("field"), face_resolution=4),
        ["vertices", "face_sizes", "face_vertices", "exemplar", "field"]),
    "surface_limit_points": (lambda **a: _native.surface_limit_points(
        a.get("vertices", QUAD_V), a.get("face_sizes", QUAD_SIZES), a.get("face_vertices", QUAD_FV),
        a.get("faces", [0]), a.get("uv", [[0.5, 0.5]])), ["vertices", "face_sizes", "face_vertices", "faces", "uv"]),
}
NOT_ARRAYS = [("a string", "abc"), ("a dict", {"x": 1}), ("a ragged list", [[1.0, 2.0], [3.0]]),
              ("a list of strings", [["a", "b", "c"]])]
ARRAY_CASES = [(fn, arg, label, value) for fn, (_, args) in ARRAYS.items() for arg in args
               for label, value in NOT_ARRAYS]


@pytest.mark.parametrize("fn, arg, label, value", ARRAY_CASES,
                         ids=[f"{c[0]}-{c[1]}-{c[2]}" for c in ARRAY_CASES])
def test_an_array_argument_that_is_no_array_is_refused_by_name(fn, arg, label, value):
    run, _ = ARRAYS[fn]
    with pytest.raises(_native.InvalidInputError) as info:
        run(**{arg: value})
    msg = str(info.value)
    assert f"'{arg}'" in msg, msg
    assert "incompatible function arguments" not in msg and len(msg) < 400, msg


def test_array_arguments_accept_nested_lists():
    dense = _native.voxelize(VERTS, FACES, resolution=8)
    listed = _native.voxelize(VERTS.tolist(), FACES.tolist(), resolution=8)
    np.testing.assert_array_equal(dense["density"], listed["density"])
    np.testing.assert_array_equal(
        _native.sample_volume(VOL, [0, 0, 0], 1.0, PTS), _native.sample_volume(VOL.tolist(), (0, 0, 0), 1.0, PTS.tolist()))
    v1, _ = _native.isosurface(SDF, [0, 0, 0], 1.0)
    v2, _ = _native.isosurface(SDF.tolist(), [0, 0, 0], 1.0)
    np.testing.assert_array_equal(v1, v2)
    assert [a.shape for a in _native.gaussian_pyramid(VOL.tolist(), levels=2)] == [(4, 4, 4), (2, 2, 2)]
    f1 = _native.diffuse_direction_field(VERTS, FACES, GIVEN)
    f2 = _native.diffuse_direction_field(VERTS.tolist(), FACES.tolist(), GIVEN.tolist())
    np.testing.assert_array_equal(f1, f2)


def test_integer_like_arguments_accept_numpy_scalars():
    a = _native.voxelize(VERTS, FACES, resolution=np.int64(8), padding=np.int32(1), seed=np.uint64(2 ** 63),
                         voxel_size=np.float32(0.0), compute_sdf=np.bool_(True))
    b = _native.voxelize(VERTS, FACES, resolution=8, padding=1)
    np.testing.assert_array_equal(a["sdf"], b["sdf"])


def test_the_largest_seed_is_accepted():
    _native.make_exemplar_pair("spikes", resolution=8, jitter=0.1, seed=2 ** 64 - 1)


@pytest.mark.parametrize("weight", [2.0, -0.5, math.nan])
def test_solid_constraint_weight_outside_0_1_is_refused(weight):
    c = np.zeros((8, 8, 8, 4), np.float32)
    c[..., 3] = 0.5
    c[1, 2, 3, 3] = weight
    with pytest.raises(_native.InvalidInputError) as info:
        _native.synthesize_solid(IMG, size=8, levels=1, constraint=c)
    assert "'constraint'" in str(info.value)
    if not math.isnan(weight):
        assert "[0, 1]" in str(info.value)


# ---- files ------------------------------------------------------------------------------------

def test_vdb_arguments_are_checked(tmp_path):
    path = tmp_path / "a.vdb"
    _native.write_vdb(path, {"density": VOL.tolist()}, (0, 0, 0), 1.0)  # pathlib.Path and a list are fine
    assert set(_native.read_vdb(path, "density")["grids"]) == {"density"}
    cases = [
        (lambda: _native.write_vdb(5, {"d": VOL}, [0, 0, 0], 1.0), ["'path'", "file path"]),
        (lambda: _native.write_vdb(str(path), [VOL], [0, 0, 0], 1.0), ["'grids'", "dict"]),
        (lambda: _native.write_vdb(str(path), {1: VOL}, [0, 0, 0], 1.0), ["'grids'", "str"]),
        (lambda: _native.write_vdb(str(path), {"d": VOL}, [0, 0, 0], "1"), ["'voxel_size'", "> 0"]),
        (lambda: _native.write_vdb(str(path), {"d": VOL}, [0, 0, 0], math.nan), ["'voxel_size'", "finite"]),
        (lambda: _native.write_vdb(str(path), {"d": VOL}, "abc", 1.0), ["'origin'"]),
        (lambda: _native.read_vdb(None), ["'path'"]),
        (lambda: _native.read_vdb(str(path), 5), ["'names'", "list"]),
        (lambda: _native.read_vdb(str(path), ["density", 3]), ["'names'", "item 1"]),
        (lambda: _native.read_vdb(str(path), grid="density"), ["unknown option 'grid'", "names"]),
        (lambda: _native.write_vdb(str(path), {"d": VOL}, [0, 0, 0], 1.0, mode="w"), ["unknown option 'mode'"]),
    ]
    for run, words in cases:
        with pytest.raises(_native.InvalidInputError) as info:
            run()
        for w in words:
            assert w in str(info.value), str(info.value)


def test_solid_method_is_checked_in_the_core_and_named():
    assert _native.SOLID_METHODS == ("optimization", "coordinates")
    assert _native.SOLID_DEFAULT_METHOD in _native.SOLID_METHODS
    assert _native.IMAGE_METHODS == ("coordinates", "optimization")
    assert _native.IMAGE_DEFAULT_METHOD == "coordinates"
    with pytest.raises(_native.InvalidInputError) as info:
        _native.synthesize_solid(IMG, size=8, levels=1, method="lazy")
    assert "'optimization' or 'coordinates'" in str(info.value) and "'lazy'" in str(info.value)
