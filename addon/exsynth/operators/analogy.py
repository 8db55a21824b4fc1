# SPDX-License-Identifier: GPL-3.0-or-later
"""Geometric Texture: the volume analogy B' : B :: A' : A (Bhat, Ingram &
Turk 2004) on the active mesh B, field-aligned.

The pair A -> A' is a built-in one (spikes, pits, holes, grooves, dilate:
`_native.make_exemplar_pair`, with its own direction field) or two mesh
objects the user picked, voxelized with B's voxel size (their features are
copied at their world size); A' is read in A's frame, so a copy of A moved
beside it and then changed is a pair. The pattern follows a direction field on B: the
mesh's `exsynth_field` point attribute when it has one (the Direction Field
operator makes it), otherwise a preset (around or along a world axis, along
a curve) chosen in the panel. A user pair's A gets its field the same way.

make_job() (main thread) reads everything from bpy into a
GeometricTextureJob of world-space arrays; run() (worker thread) voxelizes,
builds the volume frames, synthesizes and extracts the isosurface without
touching bpy.
"""

import dataclasses
import math

import bpy
import numpy as np

from .. import _native
from ..io import mesh as mesh_io
from ..io import volume as volume_io
from ..io.selection import select_only
from ..jobs import InputError, Job, JobOperator
from . import field as field_ops

PRESETS = _native.PAIR_PRESETS  # spikes, pits, holes, grooves, dilate
FIELD_PRESETS = tuple(field_ops.PRESETS.values())  # around_axis, along_axis, along_curve
PAIR_MIN, PAIR_MAX = _native.PAIR_MIN_RESOLUTION, _native.PAIR_MAX_RESOLUTION  # make_exemplar_pair's range
PATTERN_SCALE_MIN, PATTERN_SCALE_MAX = 0.05, 4.0  # the panel's Pattern Size range
MAX_GRID_SIDE = 2048  # voxels along one side of a user pair's grid

# How far A' reaches beyond A in the pair's own units (the pair spans
# [-1, 1]^3): the grid around B needs that much room to grow into.
_PAIR_GROWTH = {"spikes": "feature_height", "dilate": "dilation"}
DEFAULT_GROWTH = {key: _native.PAIR_DEFAULTS[key] for key in _PAIR_GROWTH.values()}  # the engine's


def pair_resolution(resolution, pattern_scale):
    """Voxels along the built-in pair's cube so that its voxels are B's voxels.

    B is voxelized with `resolution` voxels along its longest side L, so
    its voxel is h = L / resolution. The pair's cube [-1, 1]^3 is to cover
    `pattern_scale` * L of B, i.e. pattern_scale * resolution of B's voxels:
    that is the pair's resolution. Depends only on the two settings, so it
    is known (and checked) before anything runs."""
    return int(round(pattern_scale * resolution))


def grid_resolution(resolution, pattern_scale, fitted):
    """B's voxels along its longest side for a built-in pair: with the
    pattern fitted to the model, the Resolution raised (the engine's rule,
    _native.resolution_for_pattern) until the pair has the voxels its
    features need, so a small pattern on a coarse grid makes spikes, not
    lumps; a pattern size set by hand keeps the Resolution as given."""
    return _native.resolution_for_pattern(resolution, pattern_scale) if fitted else resolution


def fitted_pattern_scale(vertices, triangles, resolution):
    """Pattern Size fitted to B: the engine's pattern size for B's thickness
    (_native.model_thickness: twice the median diameter of the balls that
    fit inside B at its surface) as a fraction of B's longest side, kept in
    the range a built-in pair allows at `resolution`. Returns (scale, the
    measure's dict); an InputError when B cannot be measured."""
    try:
        measure = _native.model_thickness(vertices, triangles)
    except _native.InvalidInputError as exc:
        raise InputError(f"cannot fit the pattern size to the mesh: {exc}. Set the pattern size by hand") from None
    v = np.asarray(vertices, np.float64)
    longest = float((v.max(axis=0) - v.min(axis=0)).max())
    lo = max(PATTERN_SCALE_MIN, PAIR_MIN / resolution)
    hi = min(PATTERN_SCALE_MAX, PAIR_MAX / resolution)
    return float(min(max(measure["pattern_size"] / longest, lo), hi)), measure


def voxel_size_for(vertices, resolution):
    """B's voxel, as the voxelizer computes it from its bounding box."""
    v = np.asarray(vertices, np.float32)
    return _native.voxel_grid(v.min(axis=0), v.max(axis=0), resolution=resolution, padding=0)["voxel_size"]


def _voxelize(role, vertices, triangles, fix="lower the resolution", **options):
    """_native.voxelize at B's voxel size; over budget, the message says what
    the user can change (`fix`: the resolution by default, as the voxel size is derived from it)."""
    try:
        return _native.voxelize(vertices, triangles, **options)
    except _native.OverBudgetError as exc:
        need = str(exc).split(";")[0]
        raise _native.OverBudgetError(f"{role}: {need}; {fix} or raise the memory budget") from None


# ---- plain data handed to the worker -------------------------------------------
@dataclasses.dataclass
class FieldSpec:
    """A direction field for one mesh in world space: given vectors at
    points (from its `exsynth_field` attribute), or a preset rule evaluated
    on the mesh's triangles in run()."""

    preset: str = "around_axis"
    axis: tuple = (0.0, 0.0, 1.0)
    curve: np.ndarray = None  # N by 3 polyline, world space (along_curve)
    points: np.ndarray = None  # P by 3 world positions of given vectors ...
    vectors: np.ndarray = None  # ... and the P by 3 world vectors (None: the preset)
    source: str = None  # where given vectors came from, for reports (default: the attribute)

    @property
    def description(self):
        if self.vectors is not None:
            return self.source or f"'{field_ops.FIELD_ATTRIBUTE}'"
        if self.preset == "along_curve":
            return "along curve"
        axis = {(1.0, 0.0, 0.0): "X", (0.0, 1.0, 0.0): "Y", (0.0, 0.0, 1.0): "Z"}.get(
            tuple(float(a) for a in self.axis), "({:g}, {:g}, {:g})".format(*self.axis))
        return f"{self.preset.replace('_', ' ')} {axis}"

    def frames_t(self, mesh, grid, ctx, span=(0.0, 1.0)):
        """The (Z, Y, X, 3) field T on `grid` (a voxelize result of `mesh`),
        reporting progress within `span` of the job's bar."""
        lo, hi = span
        if self.vectors is not None:
            points, vectors = self.points, self.vectors
        else:
            Job.share(ctx, lo, 0.5 * (lo + hi))
            points = mesh.vertices
            vectors = _native.preset_direction_field(
                mesh.vertices, mesh.triangles, self.preset, axis=self.axis, curve=self.curve, ctx=ctx)
        Job.share(ctx, 0.5 * (lo + hi), hi)
        return _native.volume_frames(grid["sdf"], grid["origin"], float(grid["voxel_size"]),
                                     points, vectors, ctx=ctx)["t"]


@dataclasses.dataclass
class MeshInput:
    name: str
    vertices: np.ndarray  # V by 3, world space
    triangles: np.ndarray  # F by 3
    field: FieldSpec = None  # B and a user pair's A; None for A'
    region: tuple = None  # a user pair's A: (vertices, triangles) of the faces to learn from, or None


@dataclasses.dataclass
class Textured:
    """What a GeometricTextureJob returns; arrays are indexed [z, y, x]."""

    name: str  # B's name
    pair: str  # the built-in preset or A''s name
    b_prime: np.ndarray  # B' signed distance, world units, positive outside
    origin: np.ndarray
    voxel_size: float
    pair_dims: tuple  # A's grid (x, y, z)
    field: str  # where B's field came from
    stats: dict  # searched, coherent, culled, debris
    surface: tuple  # (vertices V by 3, triangles F by 3), world space

    @property
    def dims_xyz(self):
        return tuple(reversed(self.b_prime.shape))

    def grids(self):
        """The grids of B' as written to .vdb: `sdf`, and a `density` for display."""
        return {"sdf": self.b_prime, "density": volume_io.sdf_density(self.b_prime, self.voxel_size)}


@dataclasses.dataclass
class GeometricTextureJob(Job):
    b: MeshInput
    preset: str = "spikes"  # the built-in pair, unless a and a_prime are given
    a: MeshInput = None
    a_prime: MeshInput = None
    resolution: int = 64  # the user's; see grid_resolution
    pattern_scale: float = 0.5  # built-in pairs only
    fit_pattern: bool = False  # pattern_scale was fitted to B: the grid follows it (grid_resolution)
    pair_options: dict = dataclasses.field(default_factory=dict)
    memory_budget: int = 0  # bytes; 0 = the engine's default

    label = "geometric texture"

    @property
    def user_pair(self):
        return self.a is not None

    @property
    def grid_resolution(self):
        """B's voxels along its longest side: the Resolution, raised for a fitted built-in pattern."""
        return grid_resolution(self.resolution, self.pattern_scale, self.fit_pattern and not self.user_pair)

    @property
    def pair_resolution(self):
        return pair_resolution(self.grid_resolution, self.pattern_scale)

    @property
    def pair_name(self):
        return self.a_prime.name if self.user_pair else self.preset

    def padding(self):
        """Empty voxels around B for a built-in pair: room for A' to grow
        into, plus the neighbourhoods."""
        key = _PAIR_GROWTH.get(self.preset)
        growth = self.pair_options.get(key, DEFAULT_GROWTH.get(key, 0.0)) if key else 0.0
        return int(math.ceil(growth * self.pair_resolution / 2.0)) + _native.analogy_padding()

    def run(self, ctx):
        h = voxel_size_for(self.b.vertices, self.grid_resolution)
        common = dict(supersample=2, compute_sdf=True, memory_budget=self.memory_budget, ctx=ctx)
        if self.user_pair:
            a, a_prime, field_a, growth, region = self._user_pair(h, common, ctx)
            padding = int(math.ceil(growth / h)) + _native.analogy_padding()
            scale, h_a = 1.0, h
        else:
            padding = self.padding()
            region = None
        self.share(ctx, 0.15, 0.22)
        raised = self.grid_resolution > self.resolution
        fix = {"fix": f"set a larger Pattern Size by hand (the fitted one raised the resolution from "
                      f"{self.resolution} to {self.grid_resolution} for its detail)"} if raised else {}
        grid = _voxelize("B", self.b.vertices, self.b.triangles, voxel_size=h, padding=padding, **fix, **common)
        b, origin = grid["sdf"], grid["origin"]
        field_b = self.b.field.frames_t(self.b, grid, ctx, span=(0.22, 0.27))
        if not self.user_pair:
            self.share(ctx, 0.27, 0.3)
            pair = _native.make_exemplar_pair(
                self.preset, resolution=self.pair_resolution, ctx=ctx,
                memory_budget=self.memory_budget, **self.pair_options,
            )
            a, a_prime, field_a = pair["a"], pair["a_prime"], pair["field"]
            # The analogy matches A's and B's neighbourhoods voxel for voxel,
            # so both must use the same voxel size. Rather than generating the
            # pair at 2 / h voxels (B's world units are arbitrary: a 0.15 m
            # bunny would ask for a 13000^3 pair), the pair stays in its own
            # units and B is rescaled uniformly into them: one pair unit is
            # k = h / h_a of B's world units, so B's distances divided by k are
            # in pair units on a grid of voxel h_a, exactly like A's. B' comes
            # back times k. The field is a direction: no rescaling.
            h_a = float(pair["voxel_size"])  # 2 / pair resolution
            scale = h / h_a
        self.share(ctx, 0.3, 0.97)
        res = _native.synthesize_analogy(
            a, a_prime, np.ascontiguousarray(b / scale, np.float32), field_a=field_a, field_b=field_b,
            voxel_size=h_a, a_region=region, memory_budget=self.memory_budget, ctx=ctx,
        )
        b_prime = np.ascontiguousarray(res["b_prime"] * scale, np.float32)
        self.share(ctx, 0.97, 1.0)
        surface = _native.isosurface(b_prime, origin, h, isovalue=0.0, ctx=ctx)
        if len(surface[1]) == 0:
            fix = ("Pick an A′ that is A with a local change (bumps, grooves) at the size of the features "
                   "you want on B" if self.user_pair else
                   "Raise the resolution or the pattern size, or try another pair")
            raise ValueError(
                f"the analogy with the pair '{self.pair_name}' left no surface (B′ is all inside or all "
                f"outside). {fix}"
            )
        return Textured(
            name=self.b.name, pair=self.pair_name, b_prime=b_prime, origin=origin, voxel_size=h,
            pair_dims=tuple(reversed(a.shape)), field=self.b.field.description,
            stats={k: int(res[k]) for k in ("searched", "coherent", "culled", "debris")},
            surface=surface,
        )

    def _user_pair(self, h, common, ctx):
        """A and A' voxelized on one grid (the union of their bounds) with
        B's voxel size, A's field on it, and how far A' reaches out of A.

        The voxelizer centres its grid on the mesh's bounding box; giving
        both meshes the union's two corners as extra, unreferenced vertices
        gives them the same box, hence the same grid (no resampling)."""
        corners = np.array([np.minimum(self.a.vertices.min(0), self.a_prime.vertices.min(0)),
                            np.maximum(self.a.vertices.max(0), self.a_prime.vertices.max(0))])
        grids = []
        for k, mesh in enumerate((self.a, self.a_prime)):
            self.share(ctx, 0.04 * k, 0.04 * (k + 1))
            verts = np.concatenate([np.asarray(mesh.vertices, np.float64), corners])
            grids.append(_voxelize("A′" if k else "A", verts, mesh.triangles, voxel_size=h,
                                   padding=_native.analogy_padding() + 1, **common))
        a, a_prime = grids[0]["sdf"], grids[1]["sdf"]
        if float(np.abs(a - a_prime).max()) < 0.1 * h:
            raise ValueError(
                f"A' '{self.a_prime.name}' does not differ from A '{self.a.name}' at this resolution "
                f"(voxel {h:.4g}): the analogy needs a pair whose A' changes A. Pick another A', "
                "model the change on a copy of A, or raise the resolution"
            )
        outside = a_prime < 0
        growth = max(0.0, float(a[outside].max())) if outside.any() else 0.0
        field_a = self.a.field.frames_t(self.a, grids[0], ctx, span=(0.08, 0.12))
        region = None
        if self.a.region is not None:
            # Distance to the selected faces on the same grid (an open
            # surface: the voxelizer's distance is unsigned there); A' may
            # reach as far as its growth from them.
            verts, tris = self.a.region
            self.share(ctx, 0.12, 0.15)
            near = _voxelize("the selected faces of A", np.concatenate([np.asarray(verts, np.float64), corners]),
                             tris, voxel_size=h, padding=_native.analogy_padding() + 1, **common)["sdf"]
            if near.shape != a.shape:
                raise RuntimeError(f"the selected faces' grid {near.shape} is not A's {a.shape}")
            region = (np.abs(near) <= growth + _native.analogy_padding() * h).astype(np.float32)
        return a, a_prime, field_a, growth, region


# ---- reading the scene (main thread) ----------------------------------------------
# The pair options the panel sets, by the names its fields show.
PANEL_NAMES = {"feature_height": "Spike Height", "dilation": "Dilation"}


def check_settings(preset, resolution, pattern_scale, options=None, names=PANEL_NAMES):
    """For a built-in pair: an InputError naming the setting to change, or
    None. pattern_scale None: fitted to the model (not checked here). `options` are the pair's shape options (pair_options()), checked by
    the engine; `names` maps their engine names to the names the user set
    them by (the panel's labels, the CLI's options)."""
    if preset not in PRESETS:
        raise InputError(f"unknown pair '{preset}'; choose one of {', '.join(PRESETS)}")
    try:
        _native.check_exemplar_pair(preset, **(options or {}))
    except _native.InvalidInputError as exc:
        message = str(exc)
        for engine_name, user_name in names.items():
            message = message.replace(engine_name, user_name)
        raise InputError(message) from None
    lowest = math.ceil(PAIR_MIN / PATTERN_SCALE_MAX)
    if resolution < lowest:
        raise InputError(f"Resolution {resolution} is too coarse for a built-in pair: even at the largest Pattern "
                         f"Size ({PATTERN_SCALE_MAX:g}) the pair would be under {PAIR_MIN} voxels across; give a "
                         f"Resolution of at least {lowest}")
    if pattern_scale is None:
        return  # fitted to the model: fitted_pattern_scale keeps it in range
    r_pair = pair_resolution(resolution, pattern_scale)
    if r_pair < PAIR_MIN:
        raise InputError(
            f"the exemplar pair would be only {r_pair} voxels across (Resolution {resolution} × "
            f"Pattern Size {pattern_scale:g}); it needs at least {PAIR_MIN}. Raise the resolution "
            "or the pattern size"
        )
    if r_pair > PAIR_MAX:
        raise InputError(
            f"the exemplar pair would be {r_pair} voxels across (Resolution {resolution} × "
            f"Pattern Size {pattern_scale:g}); at most {PAIR_MAX}. Lower the resolution or the pattern size"
        )


def check_user_pair_grid(b_vertices, a_vertices, a_prime_vertices, resolution):
    """A user pair is voxelized with B's voxel: refuse one that is huge next to B."""
    lo_a, hi_a = a_vertices.min(0), a_vertices.max(0)
    lo_p, hi_p = a_prime_vertices.min(0), a_prime_vertices.max(0)
    if np.any(lo_p > hi_a) or np.any(lo_a > hi_p):
        raise InputError(
            "A′ lies away from A (their bounding boxes do not overlap), so the grid holding both would be "
            "mostly empty; A′ must be A with the change modelled on it, in the same place. Move A′ onto A"
        )
    h = voxel_size_for(b_vertices, resolution)
    both = np.concatenate([a_vertices, a_prime_vertices])
    sides = np.ceil((both.max(0) - both.min(0)) / h).astype(np.int64) + 2 * (_native.analogy_padding() + 1)
    if sides.max() > MAX_GRID_SIDE:
        raise InputError(
            f"A and A′ are {sides.max()} voxels across at B's voxel size (Resolution {resolution}); "
            f"at most {MAX_GRID_SIDE}. Scale A and A′ down to the size of B's features, or lower the resolution"
        )


def pair_options(settings):
    """The built-in pair's strength options (pair units: [-1, 1]^3). Grooves
    keep the pair's default rings: the grooves follow B's field either way
    (the pair's field runs along its grooves)."""
    preset = settings.geo_preset.lower()
    if preset == "dilate":
        return {"dilation": settings.geo_dilation}
    if preset == "spikes":
        return {"feature_height": settings.geo_spike_height}
    return {}


def source_triangles(obj, depsgraph, role, fix):
    """World-space triangles of a mesh object (modifiers applied), or an
    InputError saying what to pick."""
    if obj.type != 'MESH':
        raise InputError(
            f"{role} '{obj.name}' is a {obj.type.lower()}, not a mesh. {fix} and run Geometric Texture again"
        )
    verts, tris = mesh_io.world_triangles([obj], depsgraph)
    if len(tris) == 0:
        raise InputError(
            f"{role} '{obj.name}' has no faces (only vertices or edges), so it has no inside; the "
            f"analogy works on solids. Give it faces (Edit Mode, select, F) or {fix[0].lower()}{fix[1:]}"
        )
    try:  # as Voxelize checks it: a NaN vertex is named, not reported as "zero size"
        _native.validate_mesh(verts, tris, f"{role} '{obj.name}'")
    except _native.InvalidInputError as exc:
        raise InputError(str(exc)) from None
    return verts, tris


def attribute_field(obj):
    """A FieldSpec from the mesh's `exsynth_field` attribute (world space),
    None when it has none, or an InputError when the field is unusable."""
    mesh = obj.data
    if mesh.attributes.get(field_ops.FIELD_ATTRIBUTE) is None:
        return None
    field_ops.check_field_slot(obj)
    vectors = field_ops.read_vectors(mesh, field_ops.FIELD_ATTRIBUTE).astype(np.float64)
    how_to_fix = (f"Run Direction Field on '{obj.name}' again, or remove the attribute (Properties > "
                  "Object Data > Attributes) to use the panel's field preset")
    bad = ~np.isfinite(vectors).all(axis=1)
    if bad.any():
        raise InputError(
            f"the direction field '{field_ops.FIELD_ATTRIBUTE}' of '{obj.name}' is not a number (NaN or "
            f"infinite) at {int(bad.sum())} of its {len(vectors)} vertices. {how_to_fix}"
        )
    matrix = np.array(obj.matrix_world, np.float64)
    world = vectors @ matrix[:3, :3].T  # tangents transform with the matrix
    length = np.linalg.norm(world, axis=1)
    given = length > 1e-8 * max(1.0, float(length.max(initial=0.0)))
    if not given.any():
        raise InputError(
            f"the direction field '{field_ops.FIELD_ATTRIBUTE}' of '{obj.name}' is zero everywhere, "
            f"so it gives the pattern no direction. {how_to_fix}"
        )
    co = np.empty(3 * len(mesh.vertices), np.float32)
    mesh.vertices.foreach_get("co", co)
    points = co.reshape(-1, 3).astype(np.float64) @ matrix[:3, :3].T + matrix[:3, 3]
    # Zero vectors are free (as painted ones are): the frames fill them in
    # from the nearest given ones.
    return FieldSpec(points=np.ascontiguousarray(points[given]),
                     vectors=np.ascontiguousarray(world[given] / length[given, None]))


def preset_field(context, settings, obj):
    """A FieldSpec from the panel's preset, in world space."""
    preset = field_ops.PRESETS[settings.geo_field_preset]
    spec = FieldSpec(preset=preset, axis=field_ops.AXES[settings.geo_field_axis])
    if preset == "along_curve":
        if settings.geo_field_curve is None:
            raise InputError(
                "the Along Curve field preset needs a curve. Pick a curve object in the Geometric "
                "Texture panel (Curve), or choose another field preset"
            )
        local = field_ops.curve_points(settings.geo_field_curve, obj, context.evaluated_depsgraph_get())
        matrix = np.array(obj.matrix_world, np.float64)
        spec.curve = local @ matrix[:3, :3].T + matrix[:3, 3]
    return spec


def mesh_input(context, settings, obj, role, fix, with_field=True):
    verts, tris = source_triangles(obj, context.evaluated_depsgraph_get(), role, fix)
    field = None
    if with_field:
        field = attribute_field(obj) or preset_field(context, settings, obj)
    return MeshInput(name=obj.name, vertices=verts, triangles=tris, field=field)


def selected_faces(obj):
    """World-space triangles of the faces selected on a mesh object (its
    own mesh, as last left in Edit Mode), or an InputError."""
    faces = mesh_io.selected_world_triangles(obj)
    if faces is None:
        raise InputError(
            f"no faces of A '{obj.name}' are selected. Select the faces whose change A′ shows (Tab into "
            "Edit Mode, face select, then Tab back), or untick Selected Faces of A"
        )
    return faces


def user_pair(context, settings, b):
    """(A, A') MeshInputs from the panel's A and A′ objects, or an InputError."""
    a_obj, a_prime_obj = settings.geo_a, settings.geo_a_prime
    for obj, label, what in ((a_obj, "A", "before"), (a_prime_obj, "A′", "after")):
        if obj is None:
            raise InputError(
                f"no {label} picked. Pick the mesh {label} ({what} the change) in the Geometric Texture "
                "panel, or choose Pair Source: Built-in"
            )
    if a_obj == a_prime_obj:
        raise InputError(
            f"A and A′ are the same object '{a_obj.name}', so there is no change to copy. Pick as A′ "
            "a copy of A with the change modelled on it"
        )
    a = mesh_input(context, settings, a_obj, "A", "Pick a mesh with faces as A")
    if settings.geo_a_selected_only:
        a.region = selected_faces(a_obj)
    a_prime = mesh_input(context, settings, a_prime_obj, "A′", "Pick a mesh with faces as A′", with_field=False)
    # A′ is read in A's frame (its own coordinates placed with A's transform),
    # so that a copy of A (Shift+D) moved beside it, then changed, is a pair.
    to_a = np.array(a_obj.matrix_world, np.float64) @ np.linalg.inv(np.array(a_prime_obj.matrix_world, np.float64))
    a_prime.vertices = a_prime.vertices @ to_a[:3, :3].T + to_a[:3, 3]
    check_user_pair_grid(b.vertices, a.vertices, a_prime.vertices, settings.geo_resolution)
    return a, a_prime


def result_name(textured):
    return f"{textured.name}_{textured.pair}"


def summary(textured):
    nx, ny, nz = textured.dims_xyz
    px, py, pz = textured.pair_dims
    s = textured.stats
    return (f"ExSynth: '{result_name(textured)}' from '{textured.name}' ({nx}×{ny}×{nz} voxels, pair "
            f"{px}×{py}×{pz}, field {textured.field}; searched {s['searched']}, coherent {s['coherent']}, "
            f"culled {s['culled']}, debris {s['debris']}; {len(textured.surface[1])} triangles)")


def add_result_objects(context, textured, make_volume, created):
    """Mesh object `<B>_<pair>` (+ Volume `<B>_<pair>_volume` with grids
    sdf = B' and density), in the active collection, selected, the mesh active."""
    collection = context.collection
    name = result_name(textured)
    mesh_obj = mesh_io.new_surface_object(name, *textured.surface, collection, created)
    new_objects = [mesh_obj]
    if make_volume:
        new_objects.append(volume_io.new_grids_object(f"{name}_volume", textured.grids(), textured.origin,
                                                      textured.voxel_size, collection, created))

    select_only(context.view_layer, new_objects, active=mesh_obj)
    return new_objects


class EXSYNTH_OT_geometric_texture(JobOperator, bpy.types.Operator):
    """Give the active mesh the geometry of an exemplar pair A → A′ (built-in spikes, pits, holes, grooves, dilation, or two meshes you model) as a new mesh: B′ is to B as A′ is to A, with the pattern following the mesh's direction field ('exsynth_field') or a field preset. Settings: ExSynth tab of the sidebar"""

    bl_idname = "exsynth.geometric_texture"
    bl_label = "Geometric Texture"
    bl_options = {'REGISTER', 'UNDO'}

    def make_job(self, context):
        if context.mode != 'OBJECT':
            raise InputError("works in Object Mode only. Press Tab to leave Edit Mode and run it again")
        settings = context.scene.exsynth
        builtin = settings.geo_pair_source == 'BUILTIN'
        fit = builtin and settings.geo_pattern_fit
        if builtin:
            check_settings(settings.geo_preset.lower(), settings.geo_resolution,
                           None if fit else settings.geo_pattern_scale, pair_options(settings))
        obj = context.active_object
        if obj is None:
            raise InputError(
                "no active object. Select the mesh to texture (click it in the viewport or the "
                "Outliner) and run Geometric Texture again"
            )
        b = mesh_input(context, settings, obj, "the active object", "Select a mesh object")
        scale = settings.geo_pattern_scale
        if fit:  # the value the panel shows (ui/pattern_preview.py measures the same mesh)
            scale, _ = fitted_pattern_scale(b.vertices, b.triangles, settings.geo_resolution)
        job = GeometricTextureJob(
            b=b, preset=settings.geo_preset.lower(), resolution=settings.geo_resolution,
            pattern_scale=scale, fit_pattern=fit, pair_options=pair_options(settings),
            memory_budget=settings.memory_budget_bytes,
        )
        if settings.geo_pair_source == 'OBJECTS':
            job.a, job.a_prime = user_pair(context, settings, b)
        return job

    def finish(self, context, textured, created):
        add_result_objects(context, textured, context.scene.exsynth.geo_make_volume, created)
        return summary(textured)


CLASSES = (EXSYNTH_OT_geometric_texture,)
