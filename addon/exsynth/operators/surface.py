# SPDX-License-Identifier: GPL-3.0-or-later
"""Surface Texture: texture synthesis directly on the subdivision surface of
the active mesh (Ying, Hertzmann, Biermann & Zorin 2001).

The active mesh (its own polygons, no modifiers) is the control mesh of a
Catmull-Clark surface. The engine synthesizes one texture map per ptex face
from an exemplar image (optionally with a height image as an extra channel),
following the mesh's `exsynth_field` or a preset, packs the maps into one
atlas with gutters and tessellates the limit surface. The result is a new
mesh object `<mesh>_surface` (the limit mesh, UVs into the atlas; with a
height image, displaced along the limit normal: real geometry, so Cycles,
EEVEE and OBJ/glTF exports all show the same relief) with a material whose
Base Color (and Alpha) read the atlas image. The original stays as it is.

make_job() copies the scene into a SurfaceJob of world-space arrays; run()
(worker thread) calls _native.texture_surface; finish() builds bpy data.
"""

import dataclasses

import bpy
import numpy as np

from .. import _native, compat
from ..io import image as image_io
from ..io.selection import select_only
from ..jobs import InputError, Job, JobOperator
from . import field as field_ops

METHODS = ("coherent", "multiscale")
FIELD_MODES = {'SMOOTH': "smooth", 'AROUND_AXIS': "around_axis", 'ALONG_AXIS': "along_axis"}


@dataclasses.dataclass
class ControlMesh:
    name: str
    vertices: np.ndarray  # V by 3, world space
    face_sizes: np.ndarray  # F
    face_vertices: np.ndarray  # sum of face_sizes

    def triangles(self):
        """A fan triangulation (for the field presets, which work on triangles)."""
        tris, at = [], 0
        for n in self.face_sizes:
            for k in range(1, n - 1):
                tris.append((self.face_vertices[at], self.face_vertices[at + k], self.face_vertices[at + k + 1]))
            at += n
        return np.asarray(tris, np.int32).reshape(-1, 3)


@dataclasses.dataclass
class SurfaceResult:
    name: str
    atlas: np.ndarray  # (H, W, C) float32, row 0 at the top
    vertices: np.ndarray
    quads: np.ndarray
    corner_uvs: np.ndarray
    texels: int
    faces: int
    colour_channels: int  # 3 or 4 (alpha)
    has_height: bool
    encoding: str
    method: str
    field: str


@dataclasses.dataclass
class SurfaceJob(Job):
    mesh: ControlMesh
    exemplar: np.ndarray  # (H, W, C) float32, row 0 at the top: colour (+ alpha) (+ height)
    colour_channels: int = 3
    has_height: bool = False
    encoding: str = image_io.SRGB
    method: str = "coherent"
    texels_per_unit: float = 0.0
    face_resolution: int = 16
    exemplar_scale: float = 1.0
    field_mode: str = "smooth"
    axis: tuple = (0.0, 0.0, 1.0)
    field: np.ndarray = None  # V by 3 world vectors from the mesh's attribute, or None
    height_scale: float = 0.0  # displacement along the normal per unit of height
    segments: int = 2
    memory_budget: int = 0
    seed: int = 0

    label = "surface texture"

    def run(self, ctx):
        m = self.mesh
        field, how = self.field, "'exsynth_field'"
        if field is None and self.field_mode != "smooth":
            self.share(ctx, 0.0, 0.02)
            field = _native.preset_direction_field(m.vertices, m.triangles(), self.field_mode, axis=self.axis, ctx=ctx)
        if self.field is None:
            how = self.field_mode.replace("_", " ")
        self.share(ctx, 0.02, 1.0)
        options = dict(method=self.method, face_resolution=self.face_resolution,
                       texels_per_unit=self.texels_per_unit, exemplar_scale=self.exemplar_scale,
                       field_axis=self.axis, segments=self.segments, memory_budget=self.memory_budget,
                       seed=self.seed)
        if self.has_height:
            options.update(displacement_channel=self.exemplar.shape[2] - 1,
                           displacement_scale=self.height_scale, displacement_midlevel=0.5)
        res = _native.texture_surface(m.vertices, m.face_sizes, m.face_vertices, self.exemplar,
                                      field=field, ctx=ctx, **options)
        return SurfaceResult(
            name=m.name, atlas=res["atlas"], vertices=res["vertices"], quads=res["quads"],
            corner_uvs=res["corner_uvs"], texels=len(res["texels"]), faces=len(res["face_resolution"]),
            colour_channels=self.colour_channels, has_height=self.has_height, encoding=self.encoding,
            method=self.method, field=how,
        )


# ---- reading the scene (main thread) ----------------------------------------------
def control_mesh(obj):
    """The object's own polygons (no modifiers) in world space, or an InputError."""
    if obj is None or obj.type != 'MESH':
        raise InputError("no active mesh. Select the mesh to texture (click it) and run Surface Texture again")
    mesh = obj.data
    if len(mesh.polygons) == 0:
        raise InputError(f"the mesh '{obj.name}' has no faces; Surface Texture needs polygons")
    sizes = np.empty(len(mesh.polygons), np.int32)
    mesh.polygons.foreach_get("loop_total", sizes)
    loops = np.empty(len(mesh.loops), np.int32)
    mesh.loops.foreach_get("vertex_index", loops)
    starts = np.empty(len(mesh.polygons), np.int32)
    mesh.polygons.foreach_get("loop_start", starts)
    order = np.concatenate([np.arange(s, s + n) for s, n in zip(starts, sizes)]) if len(starts) else loops
    co = np.empty(3 * len(mesh.vertices), np.float32)
    mesh.vertices.foreach_get("co", co)
    matrix = np.array(obj.matrix_world, np.float64)
    verts = co.reshape(-1, 3).astype(np.float64) @ matrix[:3, :3].T + matrix[:3, 3]
    return ControlMesh(name=obj.name, vertices=np.ascontiguousarray(verts), face_sizes=sizes,
                       face_vertices=np.ascontiguousarray(loops[order]))


def mesh_field(obj):
    """The mesh's `exsynth_field` in world space (V by 3), or None when it has none."""
    if obj.data.attributes.get(field_ops.FIELD_ATTRIBUTE) is None:
        return None
    field_ops.check_field_slot(obj)
    vectors = field_ops.read_vectors(obj.data, field_ops.FIELD_ATTRIBUTE).astype(np.float64)
    if not np.isfinite(vectors).all():
        raise InputError(f"the direction field '{field_ops.FIELD_ATTRIBUTE}' of '{obj.name}' has NaN or "
                         "infinite vectors. Run Direction Field again or remove the attribute")
    matrix = np.array(obj.matrix_world, np.float64)
    return np.ascontiguousarray(vectors @ matrix[:3, :3].T)


def read_exemplar(colour, height=None, use_alpha=False):
    """(exemplar (H, W, C) with height stacked last, colour channels, encoding) or an InputError."""
    pixels = image_io.exemplar_pixels(colour, use_alpha=use_alpha)
    encoding = image_io.encoding_of(colour)
    if height is not None:
        h = image_io.exemplar_pixels(height, role="height")
        if h.shape[:2] != pixels.shape[:2]:
            raise InputError(f"the height image '{height.name}' is {h.shape[1]}×{h.shape[0]} px but the "
                             f"exemplar is {pixels.shape[1]}×{pixels.shape[0]}: give both the same size")
        pixels = np.concatenate([pixels, h[..., :1]], axis=2)
    return np.ascontiguousarray(pixels, np.float32), 4 if use_alpha else 3, encoding


# ---- building the result ---------------------------------------------------------------
def new_quad_mesh(name, vertices, quads, corner_uvs):
    """A smooth-shaded quad mesh with one UV map (per-corner UVs)."""
    mesh = bpy.data.meshes.new(name)
    mesh.vertices.add(len(vertices))
    mesh.vertices.foreach_set("co", np.ascontiguousarray(vertices, np.float32).ravel())
    loops = np.ascontiguousarray(quads, np.int32).ravel()
    mesh.loops.add(len(loops))
    mesh.loops.foreach_set("vertex_index", loops)
    mesh.polygons.add(len(quads))
    mesh.polygons.foreach_set("loop_start", np.arange(0, len(loops), 4, dtype=np.int32))
    if not bpy.types.MeshPolygon.bl_rna.properties["loop_total"].is_readonly:
        mesh.polygons.foreach_set("loop_total", np.full(len(quads), 4, np.int32))
    mesh.polygons.foreach_set("use_smooth", np.ones(len(quads), bool))
    uv = mesh.uv_layers.new(name="ExSynthAtlas")
    uv.data.foreach_set("uv", np.ascontiguousarray(corner_uvs, np.float32).ravel())
    mesh.update(calc_edges=True)
    return mesh


def atlas_images(result, created):
    """The atlas as a colour image (RGB or RGBA) and, with height, a Non-Color height image."""
    px = result.atlas[::-1]  # Blender's row 0 is the bottom
    c = result.colour_channels
    colour = image_io.new_image(f"{result.name}_surface_atlas", px[..., :c], result.encoding, created)
    height = None
    if result.has_height:
        height = image_io.new_image(f"{result.name}_surface_height", px[..., c:c + 1], image_io.DATA, created)
    return colour, height


def surface_material(name, colour, height, use_alpha, created):
    """Principled BSDF: Base Color (and Alpha) from the atlas; the height map is
    wired to a Displacement node (bump in EEVEE and Cycles' default
    'Bump Only'), on top of the real displaced geometry."""
    mat = created.add(bpy.data.materials.new(name))
    tree = compat.ensure_node_tree(mat)
    nodes, links = tree.nodes, tree.links
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    bsdf = nodes.new("ShaderNodeBsdfPrincipled")
    links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    tex = nodes.new("ShaderNodeTexImage")
    tex.image = colour
    tex.interpolation = 'Linear'
    uv = nodes.new("ShaderNodeUVMap")
    uv.uv_map = "ExSynthAtlas"
    links.new(uv.outputs["UV"], tex.inputs["Vector"])
    links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
    if use_alpha:
        links.new(tex.outputs["Alpha"], bsdf.inputs["Alpha"])
        mat.blend_method = 'HASHED'
    if height is not None:
        htex = nodes.new("ShaderNodeTexImage")
        htex.image = height
        links.new(uv.outputs["UV"], htex.inputs["Vector"])
        disp = nodes.new("ShaderNodeDisplacement")
        disp.inputs["Scale"].default_value = 0.0  # relief is in the geometry; raise for extra bump
        links.new(htex.outputs["Color"], disp.inputs["Height"])
        links.new(disp.outputs["Displacement"], out.inputs["Displacement"])
    return mat


def add_result_object(context, result, created):
    name = f"{result.name}_surface"
    mesh = created.add(new_quad_mesh(name, result.vertices, result.quads, result.corner_uvs))
    colour, height = atlas_images(result, created)
    mesh.materials.append(surface_material(name, colour, height, result.colour_channels == 4, created))
    obj = created.add(bpy.data.objects.new(name, mesh))
    context.collection.objects.link(obj)
    select_only(context.view_layer, [obj])
    return obj


def summary(result):
    h, w = result.atlas.shape[:2]
    return (f"ExSynth: '{result.name}_surface' ({result.method}, {result.texels} texels on {result.faces} "
            f"faces, atlas {w}×{h}, field {result.field}; {len(result.quads)} quads)")


class EXSYNTH_OT_surface_texture(JobOperator, bpy.types.Operator):
    """Synthesize a seamless texture from an image directly on the active mesh's subdivision surface (no UVs needed), following its direction field: adds the subdivided mesh with an atlas image and material. Settings: ExSynth tab of the sidebar"""

    bl_idname = "exsynth.surface_texture"
    bl_label = "Surface Texture"
    bl_options = {'REGISTER', 'UNDO'}

    def make_job(self, context):
        if context.mode != 'OBJECT':
            raise InputError("works in Object Mode only. Press Tab to leave Edit Mode and run it again")
        s = context.scene.exsynth
        obj = context.active_object
        mesh = control_mesh(obj)
        if s.surface_exemplar is None:
            raise InputError("no exemplar image. Pick or open one in the Surface Texture panel")
        exemplar, colour_channels, encoding = read_exemplar(s.surface_exemplar, s.surface_height, s.surface_use_alpha)
        field = mesh_field(obj)
        return SurfaceJob(
            mesh=mesh, exemplar=exemplar, colour_channels=colour_channels, has_height=s.surface_height is not None,
            encoding=encoding, method=s.surface_method.lower(),
            texels_per_unit=s.surface_density if s.surface_size_mode == 'DENSITY' else 0.0,
            face_resolution=s.surface_face_resolution, exemplar_scale=s.surface_exemplar_scale,
            field_mode=FIELD_MODES[s.surface_field], axis=field_ops.AXES[s.surface_axis], field=field,
            height_scale=s.surface_height_scale, segments=s.surface_segments,
            memory_budget=s.memory_budget_bytes, seed=s.seed,
        )

    def finish(self, context, result, created):
        add_result_object(context, result, created)
        return summary(result)


CLASSES = (EXSYNTH_OT_surface_texture,)
