# SPDX-License-Identifier: GPL-3.0-or-later
"""The one job runner every ExSynth operator uses.

A job is split in three so that Blender stays responsive and consistent:

1. ``make_job(context)`` (main thread) reads the scene and copies what the
   engine needs into plain data (numpy arrays, numbers) — a ``Job``.
2. ``Job.run(ctx)`` (worker thread) calls ``exsynth._native``, which releases
   the GIL; it must never touch bpy, because bpy is not thread-safe.
3. ``finish(context, result, created)`` (main thread) turns the result into
   datablocks. It registers everything it makes with ``created`` so that a
   failure half-way removes it all again: the scene is either fully updated
   or left exactly as it was.

``JobOperator`` is the operator mixin that wires this into Blender: a modal
run with status-bar progress and Esc to cancel when invoked from the UI, and
a synchronous run from ``execute`` (``blender -b``, scripts, redo).
"""

import os
import threading
import time

import bpy

from . import _native

# Called with each job's ExecContext right after it is created, before the
# job starts. Tests append a hook that calls ctx.cancel() to cancel a real run.
job_started_hooks = []

# Errors that mean "the job could not be done" rather than "the add-on has a
# bug": they become an operator report; anything else propagates.
REPORTED_ERRORS = (_native.Error, ValueError, MemoryError, OSError)


class InputError(ValueError):
    """The scene is not a valid input; the message says what to select or change."""


def active_mesh(obj, task, again, editable=False):
    """`obj` (the active object) when it is a mesh, else an InputError in the
    user's words: `task` names what to select ("the mesh to voxelize"),
    `again` how to retry ("run Voxelize again"). `editable`: the job writes
    an attribute onto it, so a mesh linked from another file is refused."""
    if obj is None:
        raise InputError(f"no active object. Select {task} (click it in the viewport or the Outliner) and {again}")
    if obj.type != 'MESH':
        raise InputError(f"the active object '{obj.name}' is a {obj.type.lower()}, not a mesh. "
                         f"Select a mesh object and {again}")
    if editable and (obj.library is not None or obj.data.library is not None):
        raise InputError(f"the mesh '{obj.name}' is linked from another file, so it cannot get an attribute. "
                         "Make it local (Object > Relations > Make Local)")
    return obj


class Job:
    """Plain data plus ``run(ctx) -> result``, executed off the main thread."""

    label = "job"

    def run(self, ctx):
        raise NotImplementedError

    @staticmethod
    def share(ctx, lo, hi):
        """Give the next engine call the part [lo, hi] of the job's progress
        bar (a job of several calls: one bar, not one per call)."""
        if ctx is not None:
            ctx.set_span(lo, hi)


class Runner:
    """Runs one Job, on a worker thread (``start``) or here (``run_here``)."""

    def __init__(self, job):
        self.job = job
        self.ctx = _native.ExecContext()
        self.seconds = 0.0
        self._result = None
        self._error = None
        self._thread = None
        for hook in list(job_started_hooks):
            hook(self.ctx)

    def start(self):
        # Daemon: a job still running when Blender quits must not keep it alive.
        self._thread = threading.Thread(
            target=self._work, name=f"exsynth {self.job.label}", daemon=True
        )
        self._thread.start()

    def run_here(self):
        self._work()

    def _work(self):
        t0 = time.perf_counter()
        try:
            self._result = self.job.run(self.ctx)
        except BaseException as exc:  # handed to the main thread by outcome()
            self._error = exc
        self.seconds = time.perf_counter() - t0

    @property
    def running(self):
        return self._thread is not None and self._thread.is_alive()

    def join(self, timeout=None):
        if self._thread is not None:
            self._thread.join(timeout)

    def cancel(self):
        self.ctx.cancel()

    def outcome(self):
        """The job's result, or its exception re-raised on the calling thread."""
        if self._error is not None:
            raise self._error
        return self._result

    def status(self):
        stage = self.ctx.stage or self.job.label
        if self.ctx.cancelled:
            stage += " (cancelling)"
        return stage, int(round(100 * self.ctx.progress))


class Created:
    """What finish() made so far, so that a failure can take it all back."""

    def __init__(self):
        self.ids = []
        self.files = []
        self.undos = []

    def add(self, id_block):
        self.ids.append(id_block)
        return id_block

    def add_file(self, path):
        """A file or a new folder; folders are removed only when empty."""
        self.files.append(path)
        return path

    def add_undo(self, undo):
        """A change to existing data (a new UV map, a replaced material):
        `undo()` puts it back. Undos run first, newest first, then the new
        datablocks and files go."""
        self.undos.append(undo)

    def rollback(self):
        # Best effort throughout: the error that caused the rollback is the
        # one the user needs to see, not a second one from cleaning up.
        for undo in reversed(self.undos):
            try:
                undo()
            except (ReferenceError, RuntimeError, KeyError, ValueError, AttributeError):
                pass
        alive = []
        for id_block in reversed(self.ids):
            try:
                id_block.name  # raises ReferenceError if already removed
                alive.append(id_block)
            except ReferenceError:
                pass
        if alive:
            bpy.data.batch_remove(alive)
        for path in reversed(self.files):  # files before the folders they are in
            try:
                if os.path.isdir(path):
                    os.rmdir(path)  # only if empty: never a folder someone else filled
                else:
                    os.remove(path)
            except OSError:
                pass
        self.ids.clear()
        self.files.clear()
        self.undos.clear()


class JobOperator:
    """Mixin for operators that run a Job (put it before bpy.types.Operator).

    Subclasses define ``make_job(self, context) -> Job`` (raise InputError for
    bad input) and ``finish(self, context, result, created) -> str`` (returns
    a one-line summary for the info report). Use bl_options {'REGISTER', 'UNDO'}.
    """

    def make_job(self, context):
        raise NotImplementedError

    def finish(self, context, result, created):
        raise NotImplementedError

    # ---- synchronous path: blender -b, scripts, redo ----------------------
    def execute(self, context):
        runner = self._start(context)
        if runner is None:
            return {'CANCELLED'}
        runner.run_here()
        return self._conclude(context, runner)

    # ---- modal path: the UI stays live while the worker runs -------------
    def invoke(self, context, event):
        # Background Blender still has a window in its context, but no event
        # loop to deliver timer events: run synchronously there.
        if bpy.app.background or context.window is None:
            return self.execute(context)
        runner = self._start(context)
        if runner is None:
            return {'CANCELLED'}
        self._runner = runner
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.progress_begin(0, 100)
        wm.modal_handler_add(self)
        runner.start()
        self._show_progress(context)
        return {'RUNNING_MODAL'}

    def modal(self, context, event):
        runner = self._runner
        if event.type in {'ESC', 'RIGHTMOUSE'} and event.value == 'PRESS':
            runner.cancel()  # the worker notices at its next chunk and ends
            self._show_progress(context)
            return {'RUNNING_MODAL'}
        if event.type != 'TIMER':
            return {'PASS_THROUGH'}
        if runner.running:
            self._show_progress(context)
            return {'PASS_THROUGH'}
        self._end_ui(context)
        return self._conclude(context, runner)

    def cancel(self, context):
        # Blender ends the modal operator itself (file loaded, window closed).
        runner = getattr(self, "_runner", None)
        if runner is not None:
            runner.cancel()
        self._end_ui(context)

    # ---- shared -----------------------------------------------------------
    def _start(self, context):
        try:
            job = self.make_job(context)
        except InputError as exc:
            self.report({'ERROR'}, f"ExSynth {self.bl_label}: {exc}")
            return None
        preview = job.preview() if hasattr(job, "preview") else None
        if preview:
            self.report({'INFO'}, f"ExSynth {self.bl_label}: {preview}")
        return Runner(job)

    def _conclude(self, context, runner):
        try:
            result = runner.outcome()
        except _native.CancelledError:
            self.report({'WARNING'}, f"ExSynth {self.bl_label}: cancelled; the scene is unchanged")
            return {'CANCELLED'}
        except REPORTED_ERRORS as exc:
            self.report({'ERROR'}, f"ExSynth {self.bl_label}: {exc}")
            return {'CANCELLED'}

        created = Created()
        try:
            summary = self.finish(context, result, created)
        except REPORTED_ERRORS as exc:
            created.rollback()
            self.report({'ERROR'}, f"ExSynth {self.bl_label}: {exc}")
            return {'CANCELLED'}
        except BaseException:
            created.rollback()
            raise
        if summary:
            self.report({'INFO'}, f"{summary} in {runner.seconds:.2f} s")
        return {'FINISHED'}

    def _show_progress(self, context):
        stage, pct = self._runner.status()
        context.workspace.status_text_set(f"ExSynth: {stage} {pct}%  (Esc to cancel)")
        context.window_manager.progress_update(pct)

    def _end_ui(self, context):
        wm = context.window_manager
        timer = getattr(self, "_timer", None)
        if timer is not None:
            wm.event_timer_remove(timer)
            self._timer = None
        wm.progress_end()
        if context.workspace is not None:
            context.workspace.status_text_set(None)
