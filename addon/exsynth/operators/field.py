# SPDX-License-Identifier: GPL-3.0-or-later
"""Direction Field on the active mesh: a unit tangent vector per vertex,
stored as the FLOAT_VECTOR point attribute `exsynth_field`, in the mesh's
own (local) coordinates.

Two ways to make one: a preset (around or along an axis, along a curve
object) or diffusing vectors the user painted into a FLOAT_VECTOR point
attribute (zero = free) over the surface (Turk 2001, in the engine).
The field is computed on the base mesh (no modifiers), because it is
stored on that mesh's vertices.
"""

import dataclasses

import bpy
import numpy as np

from .. import _native
from ..io import mesh as mesh_io
from ..jobs import InputError, Job, JobOperator, active_mesh

FIELD_ATTRIBUTE = "exsynth_field"
PAINT_ATTRIBUTE = "exsynth_paint"
AXES = {'X': (1.0, 0.0, 0.0), 'Y': (0.0, 1.0, 0.0), 'Z': (0.0, 0.0, 1.0)}
PRESETS = {'AROUND_AXIS': "around_axis", 'ALONG_AXIS': "along_axis", 'ALONG_CURVE': "along_curve"}


@dataclasses.dataclass
class FieldJob(Job):
    """`given` set: diffuse it; otherwise the preset (`curve` for along_curve)."""

    vertices: np.ndarray  # V by 3, the mesh's local space
    triangles: np.ndarray  # F by 3
    preset: str = "around_axis"
    axis: tuple = (0.0, 0.0, 1.0)
    curve: np.ndarray = None  # N by 3 polyline, mesh space
    given: np.ndarray = None  # V by 3 painted vectors, zero = free

    label = "direction field"

    def run(self, ctx):
        if self.given is not None:
            return _native.diffuse_direction_field(self.vertices, self.triangles, self.given, ctx=ctx)
        return _native.preset_direction_field(
            self.vertices, self.triangles, self.preset, axis=self.axis, curve=self.curve, ctx=ctx
        )


def read_vectors(mesh, name):
    """The (V, 3) float32 values of a FLOAT_VECTOR point attribute."""
    values = np.empty(3 * len(mesh.vertices), np.float32)
    mesh.attributes[name].data.foreach_get("vector", values)
    return values.reshape(-1, 3)


def check_field_slot(obj):
    """An existing `exsynth_field` must be a FLOAT_VECTOR point attribute to be overwritten."""
    attr = obj.data.attributes.get(FIELD_ATTRIBUTE)
    if attr is not None and (attr.domain, attr.data_type) != ('POINT', 'FLOAT_VECTOR'):
        raise InputError(
            f"the mesh '{obj.name}' already has an attribute '{FIELD_ATTRIBUTE}' of another kind "
            f"({attr.data_type.lower()} on the {attr.domain.lower()} domain). Rename or remove it "
            "(Properties > Object Data > Attributes) and run again"
        )


def painted_vectors(obj, name):
    """The painted attribute `name` of the mesh, or an InputError saying how to make one."""
    if not name:
        raise InputError(
            "no painted attribute named. Enter the name of a Vector attribute on the Point domain "
            f"(default '{PAINT_ATTRIBUTE}') in the Direction Field panel"
        )
    attr = obj.data.attributes.get(name)
    if attr is None:
        raise InputError(
            f"the mesh '{obj.name}' has no attribute '{name}' to diffuse. Add one "
            "(Properties > Object Data > Attributes > +, Domain: Vertex, Data Type: Vector), "
            "paint directions into it (zero = free), or choose Mode: Preset"
        )
    if (attr.domain, attr.data_type) != ('POINT', 'FLOAT_VECTOR'):
        raise InputError(
            f"the attribute '{name}' of '{obj.name}' is {attr.data_type.lower()} on the "
            f"{attr.domain.lower()} domain; painted directions must be a Vector attribute on the "
            "Vertex (point) domain. Add one of that kind and paint into it"
        )
    return read_vectors(obj.data, name)


def curve_points(curve_obj, mesh_obj, depsgraph):
    """The curve object's evaluated points (one spline) in the mesh's local space."""
    if curve_obj is None:
        raise InputError(
            "the Along Curve preset needs a curve. Pick a curve object in the Direction Field "
            "panel (Curve), or choose another preset"
        )
    if curve_obj.type != 'CURVE':
        raise InputError(
            f"'{curve_obj.name}' is a {curve_obj.type.lower()}, not a curve. Pick a curve object "
            "(Add > Curve) for the Along Curve preset"
        )
    if len(curve_obj.data.splines) != 1:
        raise InputError(
            f"the curve '{curve_obj.name}' has {len(curve_obj.data.splines)} splines; the field "
            "follows one. Separate the others (Edit Mode, select, P) or pick another curve"
        )
    curve_eval = curve_obj.evaluated_get(depsgraph)
    mesh = curve_eval.to_mesh()
    try:
        co = np.empty(3 * len(mesh.vertices), np.float32)
        mesh.vertices.foreach_get("co", co)
        closed = len(mesh.edges) == len(mesh.vertices) and len(mesh.vertices) > 2
        to_world = np.array(curve_eval.matrix_world, np.float64)
    finally:
        curve_eval.to_mesh_clear()
    points = co.reshape(-1, 3).astype(np.float64)
    if len(points) < 2:
        raise InputError(
            f"the curve '{curve_obj.name}' has fewer than 2 points after evaluation. "
            "Give it length (Edit Mode: add or move points) or pick another curve"
        )
    if closed:
        points = np.concatenate([points, points[:1]])
    matrix = np.linalg.inv(np.array(mesh_obj.matrix_world, np.float64)) @ to_world
    return points @ matrix[:3, :3].T + matrix[:3, 3]


def field_job(context, obj, settings):
    """The FieldJob for `obj` and the panel's settings (raises InputError)."""
    active_mesh(obj, "the mesh to give a direction field", "run Direction Field again", editable=True)
    verts, tris = mesh_io.mesh_arrays(obj.data)
    if len(tris) == 0:
        raise InputError(
            f"the mesh '{obj.name}' has no faces (only vertices or edges), so it has no surface "
            "to orient. Give it faces (Edit Mode, select, F) or select another mesh"
        )
    check_field_slot(obj)
    job = FieldJob(vertices=verts, triangles=tris)
    if settings.field_mode == 'DIFFUSE':
        job.given = painted_vectors(obj, settings.field_paint_attribute)
    else:
        job.preset = PRESETS[settings.field_preset]
        job.axis = AXES[settings.field_axis]
        if settings.field_preset == 'ALONG_CURVE':
            job.curve = curve_points(settings.field_curve, obj, context.evaluated_depsgraph_get())
    return job


def store_field(mesh, field, created):
    """Write `field` into the mesh's `exsynth_field` (created or overwritten), undoably."""
    attr = mesh.attributes.get(FIELD_ATTRIBUTE)
    mesh_name = mesh.name
    if attr is None:
        attr = mesh.attributes.new(FIELD_ATTRIBUTE, 'FLOAT_VECTOR', 'POINT')

        def undo():
            m = bpy.data.meshes[mesh_name]
            m.attributes.remove(m.attributes[FIELD_ATTRIBUTE])
    else:
        old = read_vectors(mesh, FIELD_ATTRIBUTE).ravel().copy()

        def undo():
            bpy.data.meshes[mesh_name].attributes[FIELD_ATTRIBUTE].data.foreach_set("vector", old)
    created.add_undo(undo)
    attr.data.foreach_set("vector", np.ascontiguousarray(field, np.float32).ravel())
    mesh.update()


def summary(obj_name, n, how):
    return f"ExSynth: direction field '{FIELD_ATTRIBUTE}' on '{obj_name}' ({n} vertices, {how})"


class EXSYNTH_OT_direction_field(JobOperator, bpy.types.Operator):
    """Give the active mesh a direction field (a unit tangent per vertex, the point attribute 'exsynth_field') from a preset or by diffusing painted vectors. Settings: ExSynth tab of the sidebar"""

    bl_idname = "exsynth.direction_field"
    bl_label = "Direction Field"
    bl_options = {'REGISTER', 'UNDO'}

    def make_job(self, context):
        if context.mode != 'OBJECT':
            raise InputError("works in Object Mode only. Press Tab to leave Edit Mode and run it again")
        obj = context.active_object
        settings = context.scene.exsynth
        job = field_job(context, obj, settings)
        self._object_name = obj.name
        if job.given is not None:
            self._how = f"diffused from '{settings.field_paint_attribute}'"
        else:
            self._how = job.preset.replace("_", " ")
            if job.preset != "along_curve":
                self._how += f" {settings.field_axis}"
        return job

    def finish(self, context, field, created):
        obj = bpy.data.objects.get(self._object_name)
        if obj is None or obj.type != 'MESH' or len(obj.data.vertices) != len(field):
            raise InputError(
                f"the mesh '{self._object_name}' changed while the field was computed. Run Direction Field again"
            )
        check_field_slot(obj)
        store_field(obj.data, field, created)
        return summary(obj.name, len(field), self._how)


CLASSES = (EXSYNTH_OT_direction_field,)
