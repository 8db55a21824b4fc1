# SPDX-License-Identifier: GPL-3.0-or-later
"""Surface Texture: the engine's limit surface against Blender's Subdivision
modifier, the operator's result (mesh, UVs, atlas, material), export, field
from the mesh's attribute, errors, cancel and rollback, and `run surface`."""

import os

import bpy
import numpy as np
import pytest

from exsynth import _native, cli, jobs
from exsynth.operators import surface as surface_ops
from helpers import TEXTURES, cancel_once_running, read_obj, scene_state, write_grid_obj

EXEMPLAR = os.path.join(TEXTURES, "crackedground.png")


def settings():
    return bpy.context.scene.exsynth


def run():
    return bpy.ops.exsynth.surface_texture()


@pytest.fixture
def sphere():
    """A UV sphere: quads plus triangle fans at the poles (n-gon sub-faces,
    extraordinary vertices), moved so that world and mesh space differ."""
    bpy.ops.mesh.primitive_uv_sphere_add(segments=10, ring_count=6, radius=1.0, location=(0.5, -0.3, 0.2))
    return bpy.context.active_object


@pytest.fixture
def exemplar():
    image = bpy.data.images.load(EXEMPLAR)
    settings().surface_exemplar = image
    return image


def evaluated_vertices(obj):
    depsgraph = bpy.context.evaluated_depsgraph_get()
    ev = obj.evaluated_get(depsgraph)
    mesh = ev.to_mesh()
    co = np.empty(3 * len(mesh.vertices), np.float32)
    mesh.vertices.foreach_get("co", co)
    ev.to_mesh_clear()
    m = np.array(obj.matrix_world)
    return co.reshape(-1, 3).astype(np.float64) @ m[:3, :3].T + m[:3, 3]


def nearest_distances(a, b):
    """For each row of a, the distance to the nearest row of b (brute force)."""
    out = np.empty(len(a))
    for i in range(0, len(a), 256):
        d = ((a[i:i + 256, None, :] - b[None, :, :]) ** 2).sum(-1)
        out[i:i + 256] = np.sqrt(d.min(1))
    return out


@pytest.mark.parametrize("shape", ["sphere", "cube", "cone"])
def test_limit_points_equal_blenders_subdivision_modifier(shape):
    # Subdivision Surface modifier: Catmull-Clark, Levels 2, Quality 3,
    # UV Smooth None, Boundary Smooth All, Use Creases off, Use Limit Surface
    # on. Its level-2 vertices are the limit points at (i/4, j/4) of each
    # quad and (i/2, j/2) of each n-gon sub-face.
    if shape == "sphere":
        bpy.ops.mesh.primitive_uv_sphere_add(segments=8, ring_count=5, radius=1.2)
    elif shape == "cube":
        bpy.ops.mesh.primitive_cube_add(size=1.5)
    else:  # an open cone: a boundary, an 8-gon and triangles
        bpy.ops.mesh.primitive_cone_add(vertices=8, end_fill_type='NGON')
    obj = bpy.context.active_object
    obj.location = (0.3, 0.1, -0.2)
    bpy.context.view_layer.update()
    control = surface_ops.control_mesh(obj)
    mod = obj.modifiers.new("Subdivision", 'SUBSURF')
    mod.levels = mod.render_levels = 2
    mod.quality = 3
    mod.uv_smooth = 'NONE'
    mod.boundary_smooth = 'ALL'
    mod.use_creases = False
    mod.use_limit_surface = True
    bpy.context.view_layer.update()
    blender = evaluated_vertices(obj)

    faces, uvs = [], []
    ptex = 0
    for n in control.face_sizes:
        steps = 4 if n == 4 else 2
        grid = [(i / steps, j / steps) for j in range(steps + 1) for i in range(steps + 1)]
        for _ in range(1 if n == 4 else n):
            faces += [ptex] * len(grid)
            uvs += grid
            ptex += 1
    ours = _native.surface_limit_points(control.vertices, control.face_sizes, control.face_vertices,
                                        np.array(faces), np.array(uvs))["position"]
    assert nearest_distances(blender, ours).max() < 1e-5
    assert nearest_distances(ours, blender).max() < 1e-5


def test_surface_texture_makes_a_textured_limit_mesh(sphere, exemplar, tmp_path):
    s = settings()
    s.surface_size_mode = 'FACE'
    s.surface_face_resolution = 8
    sphere_before = len(sphere.data.vertices), [m.name for m in sphere.data.materials]
    assert run() == {'FINISHED'}
    obj = bpy.context.active_object
    assert obj.name == f"{sphere.name}_surface" and obj is not sphere
    assert (len(sphere.data.vertices), [m.name for m in sphere.data.materials]) == sphere_before
    mesh = obj.data
    assert mesh.uv_layers.active is not None and mesh.uv_layers.active.name == "ExSynthAtlas"
    assert all(len(p.vertices) == 4 for p in mesh.polygons)
    uv = np.empty(2 * len(mesh.loops), np.float32)
    mesh.uv_layers.active.data.foreach_get("uv", uv)
    assert 0.0 <= uv.min() and uv.max() <= 1.0
    # Material: the atlas image drives Base Color through the atlas UV map.
    mat = obj.active_material
    bsdf = next(n for n in mat.node_tree.nodes if n.type == 'BSDF_PRINCIPLED')
    link = bsdf.inputs["Base Color"].links[0]
    image = link.from_node.image
    assert image.name == f"{sphere.name}_surface_atlas" and image.packed_file is not None
    assert image.size[0] > 0 and image.size[1] > 0
    # The mesh lies on the sphere's limit surface (inside the control mesh, close to it).
    verts = np.array([v.co for v in mesh.vertices])
    r = np.linalg.norm(verts - np.array([0.5, -0.3, 0.2]), axis=1)
    assert 0.7 < r.min() and r.max() <= 1.0 + 1e-4
    # Survives export: OBJ (mesh + UVs + .mtl naming the image) and glTF.
    out = tmp_path / "surface.obj"
    bpy.ops.wm.obj_export(filepath=str(out), export_selected_objects=True, export_uv=True,
                          export_materials=True, path_mode='COPY')
    verts_back, _ = read_obj(str(out))
    assert len(verts_back) == len(mesh.vertices)
    assert "vt " in out.read_text()
    gltf = tmp_path / "surface.glb"
    bpy.ops.export_scene.gltf(filepath=str(gltf), use_selection=True, export_format='GLB')
    assert gltf.stat().st_size > 1000


def test_field_attribute_and_height(sphere, exemplar):
    s = settings()
    s.surface_size_mode = 'FACE'
    s.surface_face_resolution = 6
    s.surface_method = 'MULTISCALE'
    s.surface_height = bpy.data.images.load(os.path.join(TEXTURES, "granite1.png"))
    with pytest.raises(RuntimeError, match="same size"):  # 100 px height for a 128 px exemplar
        run()
    s.surface_height = exemplar  # same size: its first channel as height
    attr = sphere.data.attributes.new("exsynth_field", 'FLOAT_VECTOR', 'POINT')
    attr.data.foreach_set("vector", np.tile([0.0, 0.0, 1.0], len(sphere.data.vertices)).astype(np.float32))
    assert run() == {'FINISHED'}
    obj = bpy.context.active_object
    names = {n.image.name for n in obj.active_material.node_tree.nodes if n.type == 'TEX_IMAGE'}
    assert names == {f"{sphere.name}_surface_atlas", f"{sphere.name}_surface_height"}
    assert bpy.data.images[f"{sphere.name}_surface_height"].colorspace_settings.name == "Non-Color"


def test_errors_leave_the_scene_unchanged(sphere, exemplar):
    s = settings()
    s.surface_size_mode = 'FACE'
    s.surface_face_resolution = 512
    s.memory_budget_gib = 0.001
    before = scene_state()
    with pytest.raises(RuntimeError, match="memory budget"):
        run()
    assert scene_state() == before
    s.surface_exemplar = None
    with pytest.raises(RuntimeError, match="no exemplar"):
        run()
    assert scene_state() == before


def test_non_manifold_mesh_is_refused(exemplar):
    mesh = bpy.data.meshes.new("fin")
    mesh.from_pydata([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (0, -1, 0)], [],
                     [(0, 1, 2, 3), (1, 0, 4, 5), (0, 1, 6)])
    obj = bpy.data.objects.new("fin", mesh)
    bpy.context.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    before = scene_state()
    with pytest.raises(RuntimeError, match="non-manifold|inconsistently oriented"):
        run()
    assert scene_state() == before


def test_cancel_while_running_and_rollback(sphere, exemplar, monkeypatch):
    s = settings()
    s.surface_size_mode = 'FACE'
    s.surface_face_resolution = 48
    seen = {}
    jobs.job_started_hooks.append(cancel_once_running(seen))
    before = scene_state()
    assert run() == {'CANCELLED'}
    assert scene_state() == before
    jobs.job_started_hooks.clear()
    s.surface_face_resolution = 6

    def fail(*args):
        raise OSError("disk full (test)")

    monkeypatch.setattr(surface_ops, "surface_material", fail)
    with pytest.raises(RuntimeError, match="disk full"):
        run()
    assert scene_state() == before


# ---- ./exsynth run surface ---------------------------------------------------------
def test_cli_writes_mesh_mtl_and_atlas(tmp_path, capsys):
    mesh = tmp_path / "plane.obj"
    write_grid_obj(mesh)
    out, atlas, height = tmp_path / "out" / "plane_tex.obj", tmp_path / "out" / "atlas.png", tmp_path / "h.png"
    args = ["surface", "--mesh", str(mesh), "--exemplar", EXEMPLAR, "--height", EXEMPLAR,
            "--method", "coherent", "--face-resolution", "8", "--out", str(out), "--texture-out", str(atlas),
            "--height-out", str(height), "--seed", "3"]
    assert cli.main(args) == 0
    assert "surface: coherent" in capsys.readouterr().out
    assert out.exists() and atlas.exists() and height.exists()
    mtl = out.with_suffix(".mtl").read_text()
    assert "map_Kd" in mtl and "atlas.png" in mtl
    verts, _ = read_obj(str(out))
    assert np.ptp(verts[:, 2]) > 0  # displaced by the height


@pytest.mark.parametrize("extra, code, message", [
    (["--face-resolution", "0"], 2, "--face-resolution must be > 0"),
    (["--height-out", "h.png"], 2, "--height-out goes with --height"),
    (["--field", "nofield.npy"], 2, "nofield.npy"),
    (["--method", "multiscale", "--face-resolution", "600"], 2, "--face-resolution must be in 1..512"),
])
def test_cli_bad_arguments(tmp_path, monkeypatch, capsys, extra, code, message):
    monkeypatch.chdir(tmp_path)
    write_grid_obj(tmp_path / "plane.obj")
    args = ["surface", "--mesh", "plane.obj", "--exemplar", EXEMPLAR, "--out", "x.obj", "--texture-out", "x.png"]
    assert cli.main(args + extra) == code
    assert message in capsys.readouterr().err
    assert not (tmp_path / "x.obj").exists() and not (tmp_path / "x.png").exists()
