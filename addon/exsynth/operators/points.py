# SPDX-License-Identifier: GPL-3.0-or-later
"""Point Texture: grow a geometry texture (an oriented point set over a
reference plane) into a larger one over a plane or over a target mesh, by
the engine's patch-based synthesis on point-set surfaces.

The exemplar is built-in (bumps, chainmail, weave, flowers), a mesh object
or its selected faces (sampled evenly by the engine), or a point file. The
result is a point cloud object (vertices + `exsynth_normal`, shown as discs
by a geometry-nodes modifier) and, on request, a surface mesh made from the
points (OpenVDB). make_job() (main thread) copies everything into plain
arrays; run() (worker thread) calls the engine only.
"""

import dataclasses
import os

import bpy
import numpy as np

from .. import _native
from ..io import mesh as mesh_io
from ..io import point_cloud
from ..io import point_files
from ..io.selection import select_only
from ..jobs import InputError, Job, JobOperator
from . import field as field_ops

PRESETS = _native.POINT_BUILTINS  # bumps, chainmail, weave, flowers
USER_PADDING = 0.15  # a user exemplar's box: its points' bounds minus this fraction on every side
MAX_POINTS = 20_000_000  # refuse outputs beyond this many points (estimated before running)


@dataclasses.dataclass
class Exemplar:
    """What the texture is grown from: a built-in, a mesh to sample, or points."""

    name: str
    preset: str = None          # built-in
    density: float = _native.POINTS_DEFAULT_DENSITY  # built-ins and meshes: points per unit area
    vertices: np.ndarray = None  # a mesh to sample (V by 3) ...
    triangles: np.ndarray = None  # ... and its faces (F by 3)
    positions: np.ndarray = None  # given points (N by 3) ...
    normals: np.ndarray = None    # ... and their normals
    box: tuple = None             # given points: (box_min, box_max); None: their bounds less USER_PADDING

    def build(self, seed, memory_budget, ctx):
        """(positions, normals, box_min, box_max) in exemplar units (worker thread)."""
        if self.preset is not None:
            ex = _native.make_point_exemplar(self.preset, density=self.density, seed=seed, ctx=ctx)
            return ex["positions"], ex["normals"], ex["box_min"], ex["box_max"]
        if self.vertices is not None:
            pos, nrm = _native.sample_mesh_points(self.vertices, self.triangles, density=self.density, seed=seed,
                                                  memory_budget=memory_budget, ctx=ctx)
        else:
            pos, nrm = self.positions, self.normals
        return (pos, nrm, *(self.box or user_box(pos)))

    def box_density(self):
        """Exemplar points per unit of its box, before it is built (for the estimate)."""
        if self.preset is not None:
            return self.density * _native.point_exemplar_surface_ratio(self.preset)
        if self.vertices is not None:  # sampled evenly: its area over its footprint
            extent = np.ptp(self.vertices[:, :2], axis=0)
            return self.density * surface_area(self.vertices, self.triangles) / max(float(np.prod(extent)), 1e-300)
        lo, hi = self.box or user_box(self.positions)
        p = self.positions
        inside = np.all((p[:, :2] >= lo) & (p[:, :2] <= hi), axis=1).sum()
        return float(inside) / max(float(np.prod(np.subtract(hi, lo))), 1e-300)


def surface_area(vertices, triangles):
    v = np.asarray(vertices, np.float64)
    t = np.asarray(triangles, np.int64)
    return 0.5 * float(np.linalg.norm(np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]]), axis=1).sum())


def default_scale(exemplar, target):
    """The engine's default scale for this exemplar over this target."""
    return _native.default_points_scale(exemplar.box_density(), area=surface_area(target.vertices, target.triangles))


def estimate(exemplar, target, scale, options):
    """The engine's estimate: {'patches', 'points', 'bytes', 'seconds'}."""
    return _native.estimate_points_on_mesh(exemplar.box_density(), area=surface_area(target.vertices,
                                           target.triangles), scale=scale, options=options)


def estimate_text(e):
    """'about 860 patches, 250000 points, ~30 s' (the seconds as measured on a 2-core machine)."""
    seconds = e["seconds"]
    when = f"~{seconds:.0f} s" if seconds < 120 else f"~{seconds / 60:.0f} min"
    return f"about {e['patches']:.3g} patches, {e['points']:.3g} points, {when} on a 2-core machine"


def user_box(positions):
    """The exemplar box of a user point set: its x, y bounds less USER_PADDING on each side."""
    p = np.asarray(positions, np.float64)
    lo, hi = p[:, :2].min(axis=0), p[:, :2].max(axis=0)
    inset = USER_PADDING * (hi - lo)
    return tuple(lo + inset), tuple(hi - inset)


@dataclasses.dataclass
class Target:
    name: str
    vertices: np.ndarray  # world space
    triangles: np.ndarray
    field: np.ndarray = None  # V by 3 world tangents, or None: the preset below
    preset: str = "around_axis"
    axis: tuple = (0.0, 0.0, 1.0)
    curve: np.ndarray = None

    def vectors(self, ctx):
        if self.field is not None:
            return self.field
        return _native.preset_direction_field(self.vertices, self.triangles, self.preset, axis=self.axis,
                                              curve=self.curve, ctx=ctx)


@dataclasses.dataclass
class PointTexture:
    """What a PointTextureJob returns."""

    name: str
    positions: np.ndarray
    normals: np.ndarray
    spacing: float       # the output's point spacing (world units)
    stats: dict          # patches, pairs, fallbacks, times
    on_target: bool
    surface: tuple = None  # (vertices, triangles) or None


@dataclasses.dataclass
class PointTextureJob(Job):
    exemplar: Exemplar
    size: tuple = (2.0, 2.0)   # over a plane, exemplar units
    target: Target = None      # or over this mesh
    scale: float = 1.0         # target units per exemplar unit
    options: dict = dataclasses.field(default_factory=dict)
    make_mesh: bool = False
    memory_budget: int = 0
    seed: int = 0

    label = "point texture"

    def preview(self):
        """The estimate shown before the work starts (over a target), or None."""
        if self.target is None:
            return None
        return estimate_text(estimate(self.exemplar, self.target, self.scale, self.options))

    def run(self, ctx):
        self.share(ctx, 0.0, 0.1)
        pos, nrm, box_min, box_max = self.exemplar.build(self.seed, self.memory_budget, ctx)
        self.share(ctx, 0.1, 0.85 if self.make_mesh else 1.0)
        common = dict(box_min=box_min, box_max=box_max, options=self.options, memory_budget=self.memory_budget,
                      seed=self.seed, ctx=ctx)
        if self.target is None:
            res = _native.synthesize_points(pos, nrm, size=self.size, **common)
            scale = 1.0
        else:
            field = self.target.vectors(ctx)
            res = _native.synthesize_points_on_mesh(pos, nrm, self.target.vertices, self.target.triangles,
                                                    field=field, scale=self.scale, **common)
            scale = self.scale
        if len(res["positions"]) == 0:
            raise ValueError("the synthesis produced no points; raise the output size or the exemplar's density")
        name = self.exemplar.name if self.target is None else f"{self.target.name}_{self.exemplar.name}"
        spacing = float(res["spacing"]) * scale
        surface = None
        if self.make_mesh:
            self.share(ctx, 0.85, 1.0)
            surface = _native.points_to_mesh(res["positions"], res["normals"], spacing=spacing,
                                             memory_budget=self.memory_budget, ctx=ctx)
        stats = {k: res[k] for k in ("patches", "pairs", "fallbacks")}
        stats["times"] = dict(res["times"])
        return PointTexture(name=f"{name}_points", positions=res["positions"], normals=res["normals"],
                            spacing=spacing, stats=stats, on_target=self.target is not None, surface=surface)


# ---- reading the scene (main thread) ----------------------------------------------
def options_from(settings, preset):
    """The engine options: the preset's (the built-in's, or 'default'), with the panel's
    patch size; with Custom Weights, the panel's weights too."""
    opts = _native.point_texture_preset(preset if preset in PRESETS else "default")
    opts["patch_size"] = settings.pts_patch_size
    if settings.pts_custom_weights:
        for key in ("extra", "epsilon", "w_p", "w_n", "w_v", "w_l", "w_d"):
            opts[key] = getattr(settings, f"pts_{key}")
    return opts


def object_exemplar(context, obj, selected_only, density):
    if obj is None or obj.type != 'MESH':
        raise InputError("pick a mesh object as the exemplar (Exemplar > Object), or choose a built-in")
    if selected_only:
        faces = mesh_io.selected_world_triangles(obj)
        if faces is None:
            raise InputError(f"no faces of '{obj.name}' are selected. Select the faces to learn from (Tab into "
                             "Edit Mode, face select, Tab back), or choose Exemplar: Object")
        verts, tris = faces
    else:
        verts, tris = mesh_io.world_triangles([obj], context.evaluated_depsgraph_get())
    if len(tris) == 0:
        raise InputError(f"the exemplar '{obj.name}' has no faces to sample points from; give it faces")
    # Exemplar units: world units, relative to the object's origin.
    verts = verts - np.array(obj.matrix_world.translation, np.float64)
    return Exemplar(name=obj.name, vertices=verts, triangles=tris, density=density)


def file_exemplar(path):
    if not path:
        raise InputError("no point file chosen (Exemplar > File: a .ply with normals, .xyz or .pwn)")
    path = bpy.path.abspath(path)
    if not os.path.isfile(path):
        raise InputError(f"the point file {path} does not exist; pick another file")
    try:
        pos, nrm = point_files.read_points(path)
    except point_files.PointFileError as exc:
        raise InputError(str(exc))
    return Exemplar(name=os.path.splitext(os.path.basename(path))[0], positions=pos, normals=nrm)


def target_input(context, settings):
    obj = settings.pts_target
    if obj is None or obj.type != 'MESH':
        raise InputError("pick a target mesh (Output > Target), or choose Output: Plane")
    verts, tris = mesh_io.world_triangles([obj], context.evaluated_depsgraph_get())
    if len(tris) == 0:
        raise InputError(f"the target '{obj.name}' has no faces; give it faces")
    target = Target(name=obj.name, vertices=verts, triangles=tris,
                    preset=field_ops.PRESETS[settings.pts_field_preset], axis=field_ops.AXES[settings.pts_field_axis])
    mesh = obj.data
    if mesh.attributes.get(field_ops.FIELD_ATTRIBUTE) is not None and len(mesh.vertices) == len(verts):
        m = np.array(obj.matrix_world, np.float64)
        target.field = field_ops.read_vectors(mesh, field_ops.FIELD_ATTRIBUTE).astype(np.float64) @ m[:3, :3].T
    elif target.preset == "along_curve":
        if settings.pts_field_curve is None:
            raise InputError("the Along Curve field needs a curve: pick one under Field, or another preset")
        local = field_ops.curve_points(settings.pts_field_curve, obj, context.evaluated_depsgraph_get())
        m = np.array(obj.matrix_world, np.float64)
        target.curve = local @ m[:3, :3].T + m[:3, 3]
    return target


def make_point_job(context, settings):
    source = settings.pts_exemplar_source
    if source == 'BUILTIN':
        preset = settings.pts_preset.lower()
        exemplar = Exemplar(name=preset, preset=preset, density=settings.pts_density)
    elif source in ('OBJECT', 'SELECTED'):
        if context.mode != 'OBJECT':
            raise InputError("works in Object Mode only. Press Tab to leave Edit Mode and run it again")
        exemplar = object_exemplar(context, settings.pts_object, source == 'SELECTED', settings.pts_density)
        preset = "default"
    else:
        exemplar = file_exemplar(settings.pts_file)
        preset = "default"
    job = PointTextureJob(exemplar=exemplar, options=options_from(settings, preset),
                          make_mesh=settings.pts_make_mesh, memory_budget=settings.memory_budget_bytes,
                          seed=settings.seed)
    if settings.pts_output == 'TARGET':
        job.target = target_input(context, settings)
        job.scale = settings.pts_scale or default_scale(exemplar, job.target)
    else:
        job.size = (settings.pts_width, settings.pts_depth)
    return job


def add_result_objects(context, result, created):
    collection = context.collection
    cloud = point_cloud.new_point_cloud_object(result.name, result.positions, result.normals,
                                               0.6 * result.spacing, collection, created)
    new = [cloud]
    if not result.on_target:  # over a plane: at the 3D cursor
        cloud.location = context.scene.cursor.location
    if result.surface is not None and len(result.surface[1]):
        surf = mesh_io.new_surface_object(result.name.replace("_points", "_surface"), *result.surface,
                                          collection, created)
        surf.location = cloud.location
        new.append(surf)
    select_only(context.view_layer, new, active=cloud)
    return new


def summary(result):
    s, t = result.stats, result.stats["times"]
    mesh = f", surface {len(result.surface[1])} triangles" if result.surface is not None else ""
    return (f"ExSynth: '{result.name}' {len(result.positions)} points from {s['patches']} patches "
            f"({s['pairs']} warp pairs; search {t['search']:.2f} s, warp {t['warp']:.2f} s, blend "
            f"{t['blend']:.2f} s){mesh}")


class EXSYNTH_OT_point_texture(JobOperator, bpy.types.Operator):
    """Grow a geometry texture (oriented points: built-in bumps, chainmail, weave, flowers, a mesh, its selected faces or a point file) over a plane or a target mesh, as a point cloud and optionally a surface mesh. Settings: ExSynth tab of the sidebar"""

    bl_idname = "exsynth.point_texture"
    bl_label = "Point Texture"
    bl_options = {'REGISTER', 'UNDO'}

    def make_job(self, context):
        return make_point_job(context, context.scene.exsynth)

    def finish(self, context, result, created):
        add_result_objects(context, result, created)
        return summary(result)


CLASSES = (EXSYNTH_OT_point_texture,)
