# SPDX-License-Identifier: GPL-3.0-or-later
"""Smoke test of the modal (UI) path, which `blender -b` cannot exercise:
invoke from a 3D viewport, watch progress, finish; invoke again, press Esc
mid-run, check the scene is unchanged. Needs a display, e.g. (xvfb package):

    EXSYNTH_ADDON_DIR=build/addon xvfb-run -a -s "-screen 0 1280x800x24" \
        blender --factory-startup --enable-event-simulate --python tests/blender/gui_smoke.py

Not collected by pytest (no test_ prefix). Exits 0 on success, 1 on failure.
"""

import os
import sys
import time
import traceback

import addon_utils
import bpy

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.environ.get("EXSYNTH_ADDON_DIR", os.path.join(ROOT, "build", "addon")))


def _raise(exc):
    raise exc


addon_utils.enable("exsynth", default_set=True, handle_error=_raise)
from exsynth import jobs  # noqa: E402  (needs the path set above)

state = {"step": "start", "ctx": None, "t0": 0.0}
jobs.job_started_hooks.append(lambda ctx: state.update(ctx=ctx))


def names():
    return sorted(o.name for o in bpy.data.objects)


def invoke_in_viewport():
    win = bpy.context.window_manager.windows[0]
    area = next(a for a in win.screen.areas if a.type == 'VIEW_3D')
    region = next(r for r in area.regions if r.type == 'WINDOW')
    with bpy.context.temp_override(window=win, screen=win.screen, area=area, region=region):
        return bpy.ops.exsynth.voxelize('INVOKE_DEFAULT')


def check(ok, what):
    print(("PASS " if ok else "FAIL ") + what, flush=True)
    if not ok:
        raise AssertionError(what)


def step():
    try:
        return STEPS[state["step"]]()
    except Exception:
        traceback.print_exc()
        os._exit(1)


def start():
    bpy.data.batch_remove(list(bpy.data.objects))
    bpy.ops.wm.obj_import(filepath=os.path.join(ROOT, "assets", "meshes", "bunny.obj"))
    bpy.context.scene.exsynth.resolution = 160
    check(invoke_in_viewport() == {'RUNNING_MODAL'}, "invoke returns RUNNING_MODAL")
    check(names() == ["bunny"], "nothing is created while the job runs")
    state.update(step="wait_finish", t0=time.monotonic())
    return 0.02


def wait_finish():
    if "bunny_voxels" not in bpy.data.objects:
        if time.monotonic() - state["t0"] > 60:
            check(False, "the job finishes within a minute")
        return 0.02
    check(names() == ["bunny", "bunny_voxel_mesh", "bunny_voxels"], "finish adds the two objects")
    bpy.context.view_layer.objects.active = bpy.data.objects["bunny"]
    bpy.context.scene.exsynth.resolution = 400  # long enough to press Esc mid-way
    state.update(before=names())
    check(invoke_in_viewport() == {'RUNNING_MODAL'}, "second invoke returns RUNNING_MODAL")
    state.update(step="press_esc")
    return 0.01


def press_esc():
    if state["ctx"].progress == 0.0:
        return 0.01
    win = bpy.context.window_manager.windows[0]
    win.event_simulate('ESC', 'PRESS')
    win.event_simulate('ESC', 'RELEASE')
    state.update(step="after_esc", t0=time.monotonic())
    return 0.1


def after_esc():
    if time.monotonic() - state["t0"] < 3.0:
        return 0.1
    check(state["ctx"].cancelled, "Esc cancels the job")
    check(names() == state["before"], "a cancelled run leaves the objects unchanged")
    print("gui_smoke: all passed", flush=True)
    os._exit(0)


STEPS = {"start": start, "wait_finish": wait_finish, "press_esc": press_esc, "after_esc": after_esc}
bpy.app.timers.register(step, first_interval=1.0)
