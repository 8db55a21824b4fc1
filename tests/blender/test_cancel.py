# SPDX-License-Identifier: GPL-3.0-or-later
"""Cancelled or failed runs leave the scene (and the cache folder) exactly as it was."""

import time

import bpy
import pytest

from exsynth import _native, jobs
from exsynth.io import materials
from exsynth.operators.voxelize import VoxelizeJob
from helpers import cancel_once_running, scene_state, world_mesh


def test_cancel_before_the_engine_starts(bunny):
    jobs.job_started_hooks.append(lambda ctx: ctx.cancel())
    bpy.context.scene.exsynth.resolution = 40
    before = scene_state()
    assert bpy.ops.exsynth.voxelize() == {'CANCELLED'}
    assert scene_state() == before


def test_cancel_while_the_engine_runs(bunny):
    seen = {}
    jobs.job_started_hooks.append(cancel_once_running(seen))
    bpy.context.scene.exsynth.resolution = 320  # seconds of work: time to cancel mid-way
    before = scene_state()
    t0 = time.perf_counter()
    assert bpy.ops.exsynth.voxelize() == {'CANCELLED'}
    assert 0.0 < seen["progress"] < 1.0 and seen["stage"]
    assert time.perf_counter() - t0 < 10
    assert scene_state() == before


def bunny_job(resolution):
    bunny = bpy.context.view_layer.objects.active
    verts, tris = world_mesh(bunny)
    return VoxelizeJob(name="bunny", vertices=verts, triangles=tris, resolution=resolution)


def test_worker_thread_runs_and_reports_progress(bunny):
    runner = jobs.Runner(bunny_job(32))
    runner.start()
    runner.join(timeout=60)
    assert not runner.running
    voxels = runner.outcome()
    assert voxels.density.shape == voxels.sdf.shape and voxels.surface is not None
    stage, pct = runner.status()
    assert pct == 100 and stage


def test_worker_thread_stops_when_cancelled(bunny):
    runner = jobs.Runner(bunny_job(320))
    runner.start()
    deadline = time.monotonic() + 30
    while runner.ctx.progress == 0.0 and time.monotonic() < deadline:
        time.sleep(0.001)  # the GIL is free while the engine works
    runner.cancel()
    runner.join(timeout=30)
    assert not runner.running
    assert "cancelling" in runner.status()[0]
    with pytest.raises(_native.CancelledError):
        runner.outcome()


@pytest.mark.parametrize("error", [OSError("disk full (test)"), KeyError("bug (test)")])
def test_failure_while_building_results_is_rolled_back(bunny, monkeypatch, error):
    # Fail after the .vdb, the Volume, its object and material exist.
    def fail(created):
        raise error

    monkeypatch.setattr(materials, "surface_material", fail)
    bpy.context.scene.exsynth.resolution = 32
    before = scene_state()
    with pytest.raises(RuntimeError, match="test"):
        bpy.ops.exsynth.voxelize()
    assert scene_state() == before
