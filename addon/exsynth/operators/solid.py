# SPDX-License-Identifier: GPL-3.0-or-later
"""Solid Texture (Kopf et al. 2007): a solid synthesized from 2D exemplars,
kept as a Volume object and baked onto the selected meshes; Re-bake bakes
more meshes from an existing solid, e.g. one cut open with a Boolean.

Space: a solid is a tile of `size`³ voxels of edge `scale / size` that
repeats in every direction. It lives in its Volume object's local space: the
voxel centres are at `(i + 0.5) * voxel_size`, so one tile spans
[0, scale]³ (the .vdb says so too). Blender < 4.5 shows a .vdb half a voxel
off (io/volume.py::blender_cell_offset); the object's location compensates,
and world → grid accounts for it, so moving, rotating or scaling the Volume
object moves the texture of every later Re-bake with it.
"""

import dataclasses
import os

import bpy
import numpy as np

from .. import _native
from ..io import bake as bake_io
from ..io import image as image_io
from ..io import materials
from ..io import volume as volume_io
from ..jobs import InputError, Job, JobOperator

SUFFIX = "_solid"
METADATA = "exsynth_solid"  # custom property on the Volume datablock
IMAGE_EXTENSIONS = (".png", ".jpg", ".jpeg", ".tif", ".tiff", ".exr", ".hdr", ".tga", ".bmp", ".webp")


# ---- the engine side: plain data in, plain data out ------------------------------------
@dataclasses.dataclass
class BakeOptions:
    resolution: int = 1024  # width and height of baked images
    interpolation: str = _native.DEFAULT_INTERPOLATION  # how texels and corners read the solid (INTERPOLATION_CHOICES)

    @property
    def margin(self):
        # Texels filled around UV islands, so mip-mapping and filtering do
        # not pull in the background: ~0.8 % of the image, at least 4.
        return max(4, self.resolution // 128)


def bake_options(settings):
    """The scene's bake settings as BakeOptions."""
    return BakeOptions(settings.solid_bake_resolution, settings.solid_bake_interpolation.lower())


@dataclasses.dataclass
class Baked:
    target: bake_io.BakeTarget
    pixels: np.ndarray = None   # IMAGE: (H, W, C), row 0 at v = 0 (Blender's order)
    covered: float = 0.0        # IMAGE: fraction of texels inside a triangle
    colors: np.ndarray = None   # ATTRIBUTE: (L, C), one per face corner


def bake_targets(volume, origin, voxel_size, targets, options, ctx, span=(0.0, 1.0)):
    """Bake a tiling volume onto each target (worker thread: no bpy),
    reporting progress within `span` of the job's bar."""
    baked = []
    lo, hi = span
    for k, target in enumerate(targets):
        Job.share(ctx, lo + (hi - lo) * k / len(targets), lo + (hi - lo) * (k + 1) / len(targets))
        if ctx is not None and ctx.cancelled:
            raise _native.CancelledError("cancelled")
        if target.mode == bake_io.IMAGE:
            pixels, mask = _native.bake_volume_to_uv(
                volume, origin, voxel_size, target.positions, target.uvs,
                options.resolution, options.resolution, wrap=True, margin=options.margin,
                interpolation=options.interpolation, ctx=ctx,
            )
            baked.append(Baked(target, pixels=pixels, covered=float(np.mean(mask == 1))))
        else:
            colors = _native.sample_volume(volume, origin, voxel_size, target.positions, wrap=True,
                                           interpolation=options.interpolation, ctx=ctx)
            baked.append(Baked(target, colors=colors))
    return baked


@dataclasses.dataclass
class Solid:
    """A synthesized tile: values (Z, Y, X, C) float32, voxel centre (i, j, k)
    at origin + voxel_size * (i, j, k) in the solid's space."""

    values: np.ndarray
    voxel_size: float
    energy: list = dataclasses.field(default_factory=list)
    turned: tuple = (False, False, False)  # per view (x, y, z): its exemplar used in its quarter turns

    def turned_note(self):
        """What the report says of the exemplar's quarter turns (rotate_exemplar)."""
        if not any(self.turned):
            return ""
        views = "" if all(self.turned) else " for the " + ", ".join(v for v, t in zip("xyz", self.turned) if t) + " view"
        return f", exemplar also matched in its quarter turns{views}"

    @property
    def size(self):
        return self.values.shape[0]

    @property
    def origin(self):
        return np.full(3, 0.5 * self.voxel_size)


def solid_grids(values, density=False):
    """Volume grids of a solid: "color" (the first three channels), then
    "alpha" (a 4th) or "channel_<i>" (any further) as float grids; with
    `density` also "density", 1 over the tile, so that a render shows the
    tile as a block (a constant density would also fill the empty margin
    Blender puts around a volume's voxels)."""
    grids = {"color": np.ascontiguousarray(values[..., :3])}
    if density:
        grids["density"] = np.ones(values.shape[:3], np.float32)
    channels = values.shape[3]
    for c in range(3, channels):
        grids["alpha" if channels == 4 else f"channel_{c}"] = np.ascontiguousarray(values[..., c])
    return grids


def tile_from_vdb(data, size):
    """(values (Z, Y, X, C), origin, voxel_size) of a solid read with
    _native.read_vdb, back in its full tile of `size`³ voxels: the file leaves
    zero voxels out, so its box can be smaller than the tile (size 0: take
    the file's box as the tile)."""
    grids = data["grids"]
    channels = [grids["color"]]
    extra = sorted((n for n in grids if n.startswith("channel_")), key=lambda n: int(n.split("_")[1]))
    for name in (["alpha"] if "alpha" in grids else []) + extra:
        channels.append(grids[name][..., None])
    values = np.concatenate(channels, axis=3) if len(channels) > 1 else channels[0]
    voxel_size = float(data["voxel_size"])
    origin = np.asarray(data["origin"], np.float64)
    if size and values.shape[:3] != (size, size, size):
        start = np.rint(origin / voxel_size - 0.5).astype(int)  # (x, y, z) of the box's first voxel
        end = start + values.shape[2::-1]
        if np.any(start < 0) or np.any(end > size):
            raise ValueError(f"the solid's file holds voxels outside its {size}³ tile; it was not made "
                             "by Solid Texture or was changed since")
        full = np.zeros((size, size, size, values.shape[3]), np.float32)
        full[start[2]:end[2], start[1]:end[1], start[0]:end[0]] = values
        values, origin = full, origin - start * voxel_size
    return np.ascontiguousarray(values, np.float32), origin, voxel_size


@dataclasses.dataclass
class SolidResult:
    name: str
    solid: Solid
    baked: list
    anchor: np.ndarray  # world position of the tile's corner (0, 0, 0)
    encoding: str


@dataclasses.dataclass
class SolidJob(Job):
    name: str
    exemplar: np.ndarray            # (H, W, C) float32, row 0 at the top
    exemplar_y: np.ndarray = None
    exemplar_z: np.ndarray = None
    size: int = _native.SOLID_DEFAULT_SIZE
    levels: int = _native.DEFAULT_LEVELS
    iterations: int = _native.DEFAULT_ITERATIONS
    method: str = None              # one of _native.SOLID_METHODS; None = the engine's default
    feature_weight: float = _native.SOLID_DEFAULT_FEATURE_WEIGHT  # the optimiser's; 0 = off
    feature_threshold: float = _native.SOLID_DEFAULT_FEATURE_THRESHOLD  # which dark pixels are features
    feature_scale: int = _native.SOLID_DEFAULT_FEATURE_SCALE  # exemplar pixels; 0 = the neighbourhood's
    rotate_exemplar: str = _native.SOLID_DEFAULT_ROTATE_EXEMPLAR  # its quarter turns: off, on, auto
    histogram_values: float = _native.SOLID_DEFAULT_HISTOGRAM_VALUES  # the optimiser's; 0 = off
    structure_sigma: float = _native.SOLID_DEFAULT_STRUCTURE_SIGMA  # the optimiser's, in voxels; 0 = off
    scale: float = 1.0              # edge length of one tile
    seed: int = 0
    memory_budget: int = 0          # bytes; 0 = the engine's default
    encoding: str = image_io.SRGB
    anchor: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros(3))
    targets: list = dataclasses.field(default_factory=list)
    bake: BakeOptions = dataclasses.field(default_factory=BakeOptions)

    label = "solid texture"

    def run(self, ctx):
        self.share(ctx, 0.0, 0.9 if self.targets else 1.0)
        res = _native.synthesize_solid(
            self.exemplar, exemplar_y=self.exemplar_y, exemplar_z=self.exemplar_z, size=self.size,
            levels=self.levels, iterations=self.iterations, seed=self.seed,
            memory_budget=self.memory_budget, ctx=ctx, method=self.method or _native.SOLID_DEFAULT_METHOD,
            feature_weight=self.feature_weight, feature_threshold=self.feature_threshold,
            feature_scale=self.feature_scale, rotate_exemplar=self.rotate_exemplar, histogram_values=self.histogram_values,
            structure_sigma=self.structure_sigma,
        )
        solid = Solid(res["solid"], self.scale / self.size, list(res["energy"]), tuple(res["rotated_exemplar"]))
        baked = bake_targets(solid.values, solid.origin, solid.voxel_size, self.targets, self.bake, ctx,
                             span=(0.9, 1.0))
        return SolidResult(self.name, solid, baked, np.asarray(self.anchor, np.float64), self.encoding)


@dataclasses.dataclass
class RebakeResult:
    name: str
    baked: list
    encoding: str


@dataclasses.dataclass
class RebakeJob(Job):
    name: str                       # the solid's Volume object
    path: str                       # its .vdb
    size: int = 0                   # voxels per tile edge (0: unknown, the file's box)
    encoding: str = image_io.LINEAR
    targets: list = dataclasses.field(default_factory=list)
    bake: BakeOptions = dataclasses.field(default_factory=BakeOptions)

    label = "re-bake"

    def run(self, ctx):
        values, origin, voxel_size = tile_from_vdb(_native.read_vdb(self.path), self.size)
        baked = bake_targets(values, origin, voxel_size, self.targets, self.bake, ctx)
        return RebakeResult(self.name, baked, self.encoding)


@dataclasses.dataclass
class ImageJob(Job):
    """2D synthesis with the same optimiser (the `image` CLI job)."""

    exemplar: np.ndarray            # (H, W, C) float32, row 0 at the top
    width: int = 256
    height: int = 256
    tileable: bool = False
    levels: int = _native.DEFAULT_LEVELS
    iterations: int = _native.DEFAULT_ITERATIONS
    seed: int = 0
    memory_budget: int = 0
    method: str = None              # one of _native.IMAGE_METHODS; None = the engine's default
                                    # (levels and iterations apply to "optimization" only)

    label = "image"

    def run(self, ctx):
        method = self.method or _native.IMAGE_DEFAULT_METHOD
        extra = dict(levels=self.levels, iterations=self.iterations) if method == "optimization" else {}
        res = _native.synthesize_image(
            self.exemplar, width=self.width, height=self.height, tileable=self.tileable,
            seed=self.seed, method=method, memory_budget=self.memory_budget, ctx=ctx, **extra,
        )
        return res["image"]  # (height, width, C), row 0 at the top


# ---- the Blender side --------------------------------------------------------------------
def exemplar_name(image):
    stem, ext = os.path.splitext(image.name)
    return stem if ext.lower() in IMAGE_EXTENSIONS else image.name


def read_exemplars(main, image_y=None, image_z=None, use_alpha=False):
    """(exemplar, exemplar_y, exemplar_z, encoding) of Blender images; the
    per-axis ones re-encoded like the main one so that their colours compare."""
    if main is None:
        raise InputError(
            "no exemplar image chosen. Pick or open one under Exemplar (sidebar > ExSynth > "
            "Solid Texture) and run again"
        )
    encoding = image_io.encoding_of(main)
    exemplar = image_io.exemplar_pixels(main, use_alpha)
    per_axis = []
    for axis, image in (("Y", image_y), ("Z", image_z)):
        if image is None:
            per_axis.append(None)
            continue
        pixels = image_io.exemplar_pixels(image, use_alpha, role=f"exemplar {axis}")
        per_axis.append(image_io.convert(pixels, image_io.encoding_of(image), encoding))
    return exemplar, per_axis[0], per_axis[1], encoding


def translation(offset):
    m = np.eye(4)
    m[:3, 3] = offset
    return m


def world_to_grid(volume_obj, voxel_size):
    """4×4 matrix from world space to the solid's grid space (where its .vdb
    puts the voxels), for a solid Volume object already in the scene."""
    local = np.linalg.inv(np.array(volume_obj.matrix_world, np.float64))
    return translation(-volume_io.blender_cell_offset(voxel_size)) @ local


def check_size(size, levels):
    """The engine's size rule, refused before any work with the panel's names."""
    smallest = _native.min_texture_size(levels)
    if size < smallest:
        raise InputError(
            f"Size {size} is too small for {levels} Levels: the coarsest level must hold one "
            f"neighbourhood, so Size must be at least {smallest}. Raise Size or use fewer Levels "
            f"(1 level allows Size {_native.min_texture_size(1)})")


def check_object_mode(context):
    if context.mode != 'OBJECT':
        raise InputError("works in Object Mode only. Press Tab to leave Edit Mode and run it again")


def apply_baked(baked, encoding, created):
    """Put one bake result on its mesh: new image (or colour attribute) and
    new material first, then the changes to the mesh, each undoable."""
    target = baked.target
    obj = bake_io.target_object(target)
    name = obj.name + SUFFIX
    if target.mode == bake_io.IMAGE:
        image = image_io.new_image(name, baked.pixels, encoding, created)
        alpha = baked.pixels.shape[2] == 4
        mat = materials.image_material(name, image, target.uv_map, created, alpha=alpha)
        bake_io.apply_uvs(obj, target, created)
    else:
        colors = image_io.convert(baked.colors, encoding, image_io.LINEAR)
        mat = materials.attribute_material(name, bake_io.ATTRIBUTE_NAME, created)
        bake_io.write_color_attribute(obj, image_io.to_rgba(colors[:, None, :])[:, 0], created)
    bake_io.replace_materials(obj, mat, created)
    return obj


def set_solid_volume(settings, obj, created):
    old = settings.solid_volume
    created.add_undo(lambda: setattr(settings, "solid_volume", old))
    settings.solid_volume = obj


def add_solid_volume(context, result, created):
    """The Volume object `<exemplar>_solid` holding the tile, placed with its
    tile corner at `result.anchor`; hidden (it would hide the meshes baked
    from it), with a material that shows its colours when unhidden."""
    solid, name = result.solid, result.name + SUFFIX
    path = volume_io.new_cache_path(name)
    volume_io.write_vdb(path, solid_grids(solid.values, density=True), solid.origin, solid.voxel_size,
                        created)
    obj = volume_io.new_volume_object(name, path, solid.voxel_size, context.collection, created)
    obj.location = result.anchor - volume_io.blender_cell_offset(solid.voxel_size)
    scale = solid.voxel_size * solid.size
    obj.data[METADATA] = {
        "size": solid.size, "scale": scale, "channels": solid.values.shape[3],
        "encoding": result.encoding, "exemplar": result.name, "turned": [int(t) for t in solid.turned],
    }
    srgb = result.encoding == image_io.SRGB
    obj.data.materials.append(materials.solid_volume_material(name, srgb, 10.0 / scale, created))
    obj.hide_render = True
    obj.hide_set(True)
    return obj


def mesh_names(baked):
    names = [f"'{b.target.name}'" for b in baked]
    return ", ".join(names[:3]) + (f" and {len(names) - 3} more" if len(names) > 3 else "")


class EXSYNTH_OT_solid_texture(JobOperator, bpy.types.Operator):
    """Synthesize a solid texture from the exemplar image(s) and bake it onto the selected meshes (a new image and material each, or a colour attribute); the solid is kept as a hidden Volume object for Re-bake. Settings: ExSynth tab of the sidebar"""

    bl_idname = "exsynth.solid_texture"
    bl_label = "Solid Texture"
    bl_options = {'REGISTER', 'UNDO'}

    def make_job(self, context):
        check_object_mode(context)
        settings = context.scene.exsynth
        check_size(settings.solid_size, settings.solid_levels)
        exemplar, exemplar_y, exemplar_z, encoding = read_exemplars(
            settings.solid_exemplar, settings.solid_exemplar_y, settings.solid_exemplar_z,
            settings.solid_use_alpha,
        )
        objects = bake_io.mesh_objects(context, self.bl_label)
        anchor, _ = bake_io.world_bounds(objects)
        targets = bake_io.collect(context, objects, settings.solid_bake_target, translation(-anchor),
                                  new_uvs=settings.solid_new_uvs)
        return SolidJob(
            name=exemplar_name(settings.solid_exemplar), exemplar=exemplar,
            exemplar_y=exemplar_y, exemplar_z=exemplar_z, size=settings.solid_size,
            levels=settings.solid_levels, iterations=settings.solid_iterations,
            method=settings.solid_method.lower(), feature_weight=settings.solid_feature_weight,
            feature_threshold=settings.solid_feature_threshold, feature_scale=settings.solid_feature_scale,
            rotate_exemplar=settings.solid_rotate_exemplar.lower(),
            histogram_values=settings.solid_histogram_values, structure_sigma=settings.solid_structure_sigma,
            scale=settings.solid_scale, seed=settings.seed,
            memory_budget=settings.memory_budget_bytes, encoding=encoding, anchor=anchor,
            targets=targets, bake=bake_options(settings),
        )

    def finish(self, context, result, created):
        volume = add_solid_volume(context, result, created)
        for baked in result.baked:
            apply_baked(baked, result.encoding, created)
        set_solid_volume(context.scene.exsynth, volume, created)
        n = result.solid.size
        return (f"ExSynth: solid '{volume.name}' of {n}×{n}×{n} voxels{result.solid.turned_note()}, "
                f"baked onto {mesh_names(result.baked)}")


class EXSYNTH_OT_solid_rebake(JobOperator, bpy.types.Operator):
    """Bake the solid chosen under Re-bake onto the selected meshes, at their place in the solid's space (e.g. a mesh cut with a Boolean gets a matching inside). Settings: ExSynth tab of the sidebar"""

    bl_idname = "exsynth.solid_rebake"
    bl_label = "Re-bake"
    bl_options = {'REGISTER', 'UNDO'}

    def make_job(self, context):
        check_object_mode(context)
        settings = context.scene.exsynth
        volume_obj = settings.solid_volume
        if volume_obj is None:
            raise InputError(
                "no solid chosen. Pick the solid's Volume object (made by Solid Texture) under "
                "Re-bake > Solid and run again"
            )
        volume = volume_obj.data
        path = bpy.path.abspath(volume.filepath, library=volume.library)
        if not os.path.isfile(path):
            raise InputError(
                f"the file of the solid '{volume_obj.name}' is missing ({path}). Run Solid Texture "
                "again, or fix the Volume's file path"
            )
        volume.grids.load()
        if volume.grids.get("color") is None:
            raise InputError(
                f"the Volume '{volume_obj.name}' has no 'color' grid, so it is not a solid. Pick a "
                "Volume made by Solid Texture"
            )
        meta = volume.get(METADATA, {})
        size = int(meta.get("size", 0))
        if size:
            voxel_size = float(meta["scale"]) / size
        else:  # a .vdb from elsewhere: its box is the tile, its grid transform the voxel size
            grid = volume.grids["color"]
            grid.load()
            voxel_size = abs(grid.matrix_object[0][0])
        objects = bake_io.mesh_objects(context, self.bl_label)
        targets = bake_io.collect(
            context, objects, settings.solid_bake_target, world_to_grid(volume_obj, voxel_size),
            new_uvs=settings.solid_new_uvs,
        )
        return RebakeJob(
            name=volume_obj.name, path=path, size=size,
            encoding=meta.get("encoding", image_io.LINEAR), targets=targets,
            bake=bake_options(settings),
        )

    def finish(self, context, result, created):
        for baked in result.baked:
            apply_baked(baked, result.encoding, created)
        return f"ExSynth: re-baked '{result.name}' onto {mesh_names(result.baked)}"


CLASSES = (EXSYNTH_OT_solid_texture, EXSYNTH_OT_solid_rebake)
