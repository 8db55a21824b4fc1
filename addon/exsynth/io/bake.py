# SPDX-License-Identifier: GPL-3.0-or-later
"""Meshes as bake targets: what the engine needs to bake a volume onto them
(read on the main thread, before a job starts) and how a bake's result is put
on them (in finish(), each change recorded in `created` so it can be undone).

Positions are handed to the engine in the volume's own space ("grid space":
where the .vdb puts its voxels), through a 4×4 world → grid matrix.
"""

import dataclasses

import bpy
import numpy as np

from ..jobs import InputError

IMAGE, ATTRIBUTE = 'IMAGE', 'ATTRIBUTE'
ATTRIBUTE_NAME = "solid"
NEW_UV_MAP = "UVMap"  # made for a mesh without any
SOLID_UV_MAP = "SolidUV"  # made (or remade) on request beside the mesh's own
# Smart UV Project as Blender's own default, with a margin so that texels
# baked around one island do not bleed into the next.
SMART_UV = {"angle_limit": 1.15192, "island_margin": 0.02}


@dataclasses.dataclass
class BakeTarget:
    """One mesh object, as plain data the worker thread can read."""

    name: str                  # the object's name
    mesh_name: str             # its mesh datablock's name
    mode: str                  # IMAGE or ATTRIBUTE
    positions: np.ndarray      # IMAGE: (F, 3, 3) triangle corners; ATTRIBUTE: (L, 3) face corners; grid space
    uvs: np.ndarray = None     # IMAGE: (F, 3, 2) UVs of the triangle corners
    uv_map: str = ""           # IMAGE: the UV map the bake used
    new_uvs: np.ndarray = None  # IMAGE, mesh had no UV map: (L, 2) UVs to add as `uv_map` on success
    loop_count: int = 0        # face corners of the mesh when read (to notice edits during the run)


def mesh_objects(context, what):
    """The selected mesh objects, or an InputError saying what to select."""
    selected = list(context.selected_objects)
    meshes = [o for o in selected if o.type == 'MESH']
    if not meshes:
        others = ", ".join(f"'{o.name}' ({o.type.lower()})" for o in selected[:3])
        got = f" (selected: {others}{', …' if len(selected) > 3 else ''})" if selected else ""
        raise InputError(
            f"no mesh selected to bake onto{got}. Select one or more mesh objects "
            f"(click, Shift+click) and run {what} again"
        )
    return meshes


def world_bounds(objects):
    """(lower, upper) corners of the objects' evaluated bounding boxes in world space."""
    corners = []
    for obj in objects:
        m = np.array(obj.matrix_world, np.float64)
        box = np.array(obj.bound_box, np.float64)
        corners.append(box @ m[:3, :3].T + m[:3, 3])
    corners = np.concatenate(corners)
    return corners.min(axis=0), corners.max(axis=0)


def collect(context, objects, mode, world_to_grid, new_uvs=False):
    """A BakeTarget per object. A mesh without a UV map (image mode), or
    every mesh with `new_uvs`, is unwrapped with Smart UV Project on a
    temporary copy: the mesh itself is only given the UV map by apply_uvs()
    once the job has succeeded."""
    targets = []
    for obj in objects:
        mesh = obj.data
        if obj.library is not None or mesh.library is not None:
            raise InputError(
                f"the mesh '{obj.name}' is linked from another file, so it cannot get a new material "
                "or UV map. Make it local (Object > Relations > Make Local) or deselect it"
            )
        if len(mesh.polygons) == 0:
            raise InputError(
                f"the mesh '{obj.name}' has no faces (only vertices or edges), so there is no "
                "surface to bake onto. Give it faces or deselect it"
            )
        if mode == ATTRIBUTE:
            targets.append(_attribute_target(obj, world_to_grid))
        elif mesh.uv_layers.active is not None and not new_uvs:
            depsgraph = context.evaluated_depsgraph_get()
            target = _image_target(obj, obj, depsgraph, mesh.uv_layers.active.name, world_to_grid)
            targets.append(target)
        else:
            targets.append(_unwrapped_target(context, obj, world_to_grid))
    return targets


def _attribute_target(obj, world_to_grid):
    mesh = obj.data
    attr = mesh.attributes.get(ATTRIBUTE_NAME)
    if attr is not None and (attr.domain, attr.data_type) != ('CORNER', 'FLOAT_COLOR'):
        raise InputError(
            f"the mesh '{obj.name}' already has an attribute '{ATTRIBUTE_NAME}' of another kind "
            f"({attr.data_type.lower()} on the {attr.domain.lower()} domain). Rename or remove it "
            "(Properties > Object Data > Attributes) and run again"
        )
    co = np.empty(3 * len(mesh.vertices), np.float32)
    mesh.vertices.foreach_get("co", co)
    loops = np.empty(len(mesh.loops), np.int32)
    mesh.loops.foreach_get("vertex_index", loops)
    matrix = world_to_grid @ np.array(obj.matrix_world, np.float64)
    grid = _transform(co.reshape(-1, 3), matrix)
    return BakeTarget(obj.name, mesh.name, ATTRIBUTE, np.ascontiguousarray(grid[loops], np.float32),
                      loop_count=len(mesh.loops))


def _image_target(obj, source, depsgraph, uv_map, world_to_grid):
    """Triangles and UVs of `source` (obj or its temporary copy) after modifiers."""
    source_eval = source.evaluated_get(depsgraph)
    mesh = source_eval.to_mesh()
    try:
        mesh.calc_loop_triangles()
        co = np.empty(3 * len(mesh.vertices), np.float32)
        mesh.vertices.foreach_get("co", co)
        n_tris = len(mesh.loop_triangles)
        tri_verts = np.empty(3 * n_tris, np.int32)
        mesh.loop_triangles.foreach_get("vertices", tri_verts)
        tri_loops = np.empty(3 * n_tris, np.int32)
        mesh.loop_triangles.foreach_get("loops", tri_loops)
        layer = mesh.uv_layers.get(uv_map)
        if layer is None:
            raise InputError(
                f"the modifiers of '{obj.name}' drop its UV map '{uv_map}'. Apply or disable the "
                "modifier that removes it, or use Bake To: Color Attribute"
            )
        uv = np.empty(2 * len(mesh.loops), np.float32)
        layer.data.foreach_get("uv", uv)
        matrix = world_to_grid @ np.array(source_eval.matrix_world, np.float64)
    finally:
        source_eval.to_mesh_clear()
    if n_tris == 0:
        raise InputError(
            f"the mesh '{obj.name}' has no faces after its modifiers, so there is no surface to "
            "bake onto. Check its modifiers or deselect it"
        )
    grid = _transform(co.reshape(-1, 3), matrix)
    return BakeTarget(
        obj.name, obj.data.name, IMAGE,
        positions=np.ascontiguousarray(grid[tri_verts.reshape(-1, 3)], np.float32),
        uvs=np.ascontiguousarray(uv.reshape(-1, 2)[tri_loops.reshape(-1, 3)], np.float32),
        uv_map=uv_map, loop_count=len(obj.data.loops),
    )


def _unwrapped_target(context, obj, world_to_grid):
    """Smart UV Project on a temporary copy of the object (its modifiers
    included); the copy is gone, and selection restored, before this returns."""
    uv_map = SOLID_UV_MAP if len(obj.data.uv_layers) else NEW_UV_MAP
    if obj.data.uv_layers.get(uv_map) is None and len(obj.data.uv_layers) >= 8:
        raise InputError(
            f"the mesh '{obj.name}' has 8 UV maps, the most Blender allows, so there is no room for "
            f"'{uv_map}'. Remove one (Properties > Object Data > UV Maps) and run again"
        )
    view_layer = context.view_layer
    selected = list(context.selected_objects)
    active = view_layer.objects.active
    temp = obj.copy()
    temp.data = obj.data.copy()
    temp_ids = [temp, temp.data]
    try:
        uv_layers = temp.data.uv_layers
        uv_layers.active = uv_layers.get(uv_map) or uv_layers.new(name=uv_map)
        context.scene.collection.objects.link(temp)
        for other in selected:
            other.select_set(False)
        temp.select_set(True)
        view_layer.objects.active = temp
        bpy.ops.object.mode_set(mode='EDIT')
        try:
            bpy.ops.mesh.reveal(select=False)
            bpy.ops.mesh.select_all(action='SELECT')
            bpy.ops.uv.smart_project(**SMART_UV)
        finally:
            bpy.ops.object.mode_set(mode='OBJECT')
        layer = temp.data.uv_layers.active
        new_uvs = np.empty(2 * len(temp.data.loops), np.float32)
        layer.data.foreach_get("uv", new_uvs)
        target = _image_target(obj, temp, context.evaluated_depsgraph_get(), layer.name, world_to_grid)
    finally:
        bpy.data.batch_remove(temp_ids)
        for other in selected:
            other.select_set(True)
        view_layer.objects.active = active
    target.uv_map = uv_map
    target.new_uvs = new_uvs.reshape(-1, 2)
    return target


def _transform(points, matrix):
    # float64: world offsets can be large; the grid-space result is small.
    return np.asarray(points, np.float64) @ matrix[:3, :3].T + matrix[:3, 3]


# ---- results --------------------------------------------------------------------------
def target_object(target):
    """The object a target was read from, unchanged in the meantime, or an error."""
    obj = bpy.data.objects.get(target.name)
    if obj is None or obj.type != 'MESH':
        raise InputError(f"the mesh '{target.name}' was removed or renamed while the job ran; run again")
    if len(obj.data.loops) != target.loop_count:
        raise InputError(f"the mesh '{target.name}' was edited while the job ran; run again")
    return obj


def apply_uvs(obj, target, created):
    """Give the mesh the UV map the bake made (a new one, or new UVs in the
    one of that name)."""
    if target.new_uvs is None:
        return
    mesh = obj.data
    layer = mesh.uv_layers.get(target.uv_map)
    if layer is None:
        layer = mesh.uv_layers.new(name=target.uv_map)
        name = layer.name
        created.add_undo(lambda: mesh.uv_layers.remove(mesh.uv_layers[name]))
    else:
        old = np.empty(2 * len(layer.data), np.float32)
        layer.data.foreach_get("uv", old)
        name = layer.name
        created.add_undo(lambda: mesh.uv_layers[name].data.foreach_set("uv", old))
    layer.data.foreach_set("uv", target.new_uvs.ravel())


def replace_materials(obj, material, created):
    """Show `material` on every face: each slot gets it (face material
    indices stay valid); a mesh without slots gets one."""
    if len(obj.material_slots) == 0:
        mesh = obj.data
        mesh.materials.append(material)
        created.add_undo(lambda: mesh.materials.pop(index=len(mesh.materials) - 1))
        return
    for index, slot in enumerate(obj.material_slots):
        old = slot.material
        created.add_undo(lambda i=index, m=old: setattr(obj.material_slots[i], "material", m))
        slot.material = material


def write_color_attribute(obj, colors, created):
    """`colors` (L, 4) float32 scene-linear into the CORNER attribute 'solid',
    made the active colour attribute. An existing one is overwritten (its old
    values are restored if the job fails later)."""
    mesh = obj.data
    attrs = mesh.color_attributes
    old_active = attrs.active_color.name if attrs.active_color is not None else None
    attr = attrs.get(ATTRIBUTE_NAME)
    if attr is None:
        attr = attrs.new(ATTRIBUTE_NAME, 'FLOAT_COLOR', 'CORNER')
        created.add_undo(lambda: attrs.remove(attrs[ATTRIBUTE_NAME]))
    else:
        old = np.empty(4 * len(attr.data), np.float32)
        attr.data.foreach_get("color", old)
        created.add_undo(lambda: attrs[ATTRIBUTE_NAME].data.foreach_set("color", old))
    attr.data.foreach_set("color", np.ascontiguousarray(colors, np.float32).ravel())
    attrs.active_color = attr

    def restore_active():
        if old_active is not None and attrs.get(old_active) is not None:
            attrs.active_color = attrs[old_active]

    created.add_undo(restore_active)
    mesh.update()
