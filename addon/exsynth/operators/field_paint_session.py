# SPDX-License-Identifier: GPL-3.0-or-later
"""The data side of Paint Direction Field, usable from scripts: a
`PaintSession` holds one mesh's painted constraints as a numpy array, applies
brush samples given in world space (exsynth.field_brush does the math),
writes the painted attribute and `exsynth_field`, and can put both back as
they were. `Diffuser` runs the engine's diffusion on a worker thread.
"""

import threading

import bpy
import numpy as np

from .. import _native, field_brush
from ..io import mesh as mesh_io
from ..jobs import InputError, active_mesh
from .field import FIELD_ATTRIBUTE, check_field_slot, read_vectors

UNDO_DEPTH = 64  # strokes Ctrl+Z can take back inside one session
# Diffuse while the stroke is dragged on meshes up to this size, else on
# release. Measured (bench/bench_paint.py, 2 cores): one diffusion takes
# ~0.1 s CPU (85 ms wall at load 1.5, 0.27 s at load 6) on the 26 k-vertex
# Armadillo, live enough; once subdivided to 104 k, 0.43 s wall at load 1.5
# and 1.3-2.4 s at load 6, which would lag the brush and compete with it for
# the two cores.
LIVE_DIFFUSION_LIMIT = 50000


def check_target(obj, paint_name):
    """The mesh to paint on, or an InputError saying what to change."""
    active_mesh(obj, "the mesh to paint a direction field on", "start Paint Direction Field again", editable=True)
    if len(obj.data.polygons) == 0:
        raise InputError(
            f"the mesh '{obj.name}' has no faces (only vertices or edges), so there is no surface to paint "
            "on. Give it faces (Edit Mode, select, F) or select another mesh"
        )
    if not paint_name:
        raise InputError(
            "no painted attribute named. Enter a name (default 'exsynth_paint') in the Direction Field panel"
        )
    attr = obj.data.attributes.get(paint_name)
    if attr is not None and (attr.domain, attr.data_type) != ('POINT', 'FLOAT_VECTOR'):
        raise InputError(
            f"the attribute '{paint_name}' of '{obj.name}' is {attr.data_type.lower()} on the "
            f"{attr.domain.lower()} domain; painted directions go into a Vector attribute on the Vertex "
            "domain. Rename or remove it, or enter another name in the Direction Field panel"
        )
    check_field_slot(obj)


class Diffuser:
    """At most one diffusion on a worker thread (the engine releases the GIL;
    only numpy arrays cross, never bpy); `request` while one runs keeps the
    newest constraints for the next."""

    def __init__(self, vertices, triangles):
        self.vertices, self.triangles = vertices, triangles
        self._thread, self._pending, self._result = None, None, None
        self._lock = threading.Lock()
        self.runs, self.error = 0, None
        self.requested = None  # the constraints of the last request (main thread only)

    def request(self, constraints):
        """Diffuse these constraints next (not again if they are the last ones asked for)."""
        if self.requested is not None and np.array_equal(constraints, self.requested):
            return
        self.requested = constraints.copy()
        with self._lock:
            self._pending = self.requested
        self._start_if_idle()

    def _start_if_idle(self):
        with self._lock:
            if self._pending is None or (self._thread is not None and self._thread.is_alive()):
                return
            given, self._pending = self._pending, None
        self._thread = threading.Thread(target=self._work, args=(given,), name="exsynth paint diffusion", daemon=True)
        self._thread.start()

    def _work(self, given):
        try:
            field = _native.diffuse_direction_field(self.vertices, self.triangles, given)
            error = None
        except _native.Error as exc:  # e.g. everything erased: no constraint left
            field, error = None, exc
        with self._lock:
            self._result, self.error = field, error
            self.runs += 1

    def take(self):
        """The newest finished field (or None), and starts the next pending request."""
        with self._lock:
            result, self._result = self._result, None
        self._start_if_idle()
        return result

    @property
    def busy(self):
        with self._lock:
            return self._pending is not None or (self._thread is not None and self._thread.is_alive())

    def wait(self):
        """Blocks until every request is diffused; returns the last field (or None)."""
        result = None
        while True:
            if self._thread is not None:
                self._thread.join()
            latest = self.take()
            if latest is not None:
                result = latest
            if not self.busy:
                return result


def _attribute_state(mesh, name):
    attr = mesh.attributes.get(name)
    return None if attr is None else read_vectors(mesh, name).copy()


class PaintSession:
    """One painting session on one mesh: the constraints as a numpy array,
    written to the painted attribute as strokes go; the field diffused from
    them. Samples are given in world space (what the viewport ray-cast
    yields); distances are measured there, so the brush is round on a scaled
    object; directions are stored in the mesh's own space."""

    def __init__(self, obj, paint_name):
        check_target(obj, paint_name)
        self.object_name, self.mesh_name, self.paint_name = obj.name, obj.data.name, paint_name
        mesh = obj.data
        verts, tris = mesh_io.mesh_arrays(mesh)
        self.vertices = verts.astype(np.float64)
        self.triangles = tris
        self.normals = field_brush.vertex_normals(self.vertices, tris)
        self.matrix = np.array(obj.matrix_world, np.float64)
        self.to_local = np.linalg.inv(self.matrix)
        self.world = self.vertices @ self.matrix[:3, :3].T + self.matrix[:3, 3]
        # The scene as it was, for cancel.
        self.original = {name: _attribute_state(mesh, name) for name in (paint_name, FIELD_ATTRIBUTE)}
        paint = self.original[paint_name]
        self.constraints = np.zeros((len(verts), 3), np.float32) if paint is None else paint.astype(np.float32)
        field = self.original[FIELD_ATTRIBUTE]
        self.field = None if field is None else field.astype(np.float32)
        self.history = []  # constraints before each finished stroke (Ctrl+Z)
        self.before_stroke = None
        self.samples = 0
        self.diffuser = Diffuser(self.vertices, self.triangles)
        self.live = len(self.vertices) <= LIVE_DIFFUSION_LIMIT

    @property
    def mesh(self):
        mesh = bpy.data.meshes.get(self.mesh_name)
        if mesh is None or len(mesh.vertices) != len(self.vertices):
            raise InputError(f"the mesh '{self.mesh_name}' was removed or changed while painting; start again")
        return mesh

    # ---- strokes ---------------------------------------------------------
    def begin_stroke(self):
        self.before_stroke = self.constraints.copy()

    def apply(self, centre, direction, radius, mode='PAINT', mirror_axes=(), strength=1.0):
        """One sample: brush at world point `centre`, stroke tangent
        `direction` (world), brush `radius` (world units). Mirrors across the
        mesh's local axes in `mirror_axes` (0, 1, 2). Returns the number of
        vertices changed. Raises ValueError on a bad radius, mode or strength
        (nothing changed)."""
        centre = np.asarray(centre, np.float64)
        direction = np.asarray(direction, np.float64)
        if centre.shape != (3,) or direction.shape != (3,) or not (np.all(np.isfinite(centre))
                                                                   and np.all(np.isfinite(direction))):
            raise ValueError("a brush sample needs a finite world point and direction (3 numbers each)")
        field_brush.falloff(0.0, radius)  # validates the radius before anything changes
        local_centre = self.to_local[:3, :3] @ centre + self.to_local[:3, 3]
        local_dir = self.to_local[:3, :3] @ direction
        changed = 0
        for p, d in field_brush.mirrored_samples(local_centre, local_dir, mirror_axes):
            world_p = self.matrix[:3, :3] @ p + self.matrix[:3, 3]
            changed += len(field_brush.apply_brush(self.constraints, self.field, self.world, self.normals,
                                                   world_p, radius, d, mode=mode, strength=strength))
        self.samples += 1
        return changed

    def end_stroke(self):
        """Keeps the stroke: writes the constraints, asks for a diffusion."""
        if self.before_stroke is not None:
            self.history = (self.history + [self.before_stroke])[-UNDO_DEPTH:]
        self.before_stroke = None
        self.write_paint()
        self.request_diffusion()

    def cancel_stroke(self):
        if self.before_stroke is not None:
            self.constraints = self.before_stroke
            self.before_stroke = None
            self.write_paint()
            self.request_diffusion()

    def undo_stroke(self):
        """Takes back the last finished stroke; False when there is none."""
        if not self.history:
            return False
        self.constraints = self.history.pop()
        self.write_paint()
        self.request_diffusion()
        return True

    # ---- diffusion ---------------------------------------------------------
    def request_diffusion(self):
        if field_brush.has_constraints(self.constraints):
            self.diffuser.request(self.constraints)

    def poll_field(self):
        """Writes a finished diffusion into `exsynth_field`; True if it did."""
        field = self.diffuser.take()
        if field is None:
            return False
        self.write_field(field)
        return True

    def finish(self):
        """Waits for the last diffusion and writes everything (end of the tool)."""
        self.write_paint()
        if field_brush.has_constraints(self.constraints):
            self.diffuser.request(self.constraints)
        field = self.diffuser.wait()
        if field is not None:
            self.write_field(field)

    def changed(self):
        return any(not _same(self.original[name], _attribute_state(self.mesh, name))
                   for name in (self.paint_name, FIELD_ATTRIBUTE))

    # ---- the mesh ----------------------------------------------------------
    def write_paint(self):
        _write(self.mesh, self.paint_name, self.constraints)

    def write_field(self, field):
        self.field = np.asarray(field, np.float32)
        _write(self.mesh, FIELD_ATTRIBUTE, self.field)

    def restore(self):
        """Both attributes back as they were when the session began."""
        self.diffuser.wait()
        mesh = bpy.data.meshes.get(self.mesh_name)
        if mesh is None:
            return
        for name, values in self.original.items():
            attr = mesh.attributes.get(name)
            if values is None:
                if attr is not None:
                    mesh.attributes.remove(attr)
            else:
                _write(mesh, name, values)
        mesh.update()


def _same(a, b):
    if a is None or b is None:
        return a is None and b is None
    return a.shape == b.shape and np.array_equal(a, b)


def _write(mesh, name, values):
    attr = mesh.attributes.get(name)
    if attr is None:
        attr = mesh.attributes.new(name, 'FLOAT_VECTOR', 'POINT')
    attr.data.foreach_set("vector", np.ascontiguousarray(values, np.float32).ravel())
    mesh.update()
