# SPDX-License-Identifier: GPL-3.0-or-later
"""Runs inside Debian's Blender (3.4 on Debian 12, 4.3 on 13; started by test_extension.py):

    BLENDER_USER_SCRIPTS=EMPTY_DIR blender -b --factory-startup --python legacy_job.py -- ZIP OUT.json

Installs the legacy add-on zip with Preferences › Add-ons › Install, enables
it and runs a Voxelize; writes what it saw as JSON."""

import json
import os
import sys

import addon_utils
import bpy
import numpy as np

zip_path, out_path = sys.argv[sys.argv.index("--") + 1:][:2]
seen = {"blender": bpy.app.version_string, "python": list(sys.version_info[:2])}
seen["install"] = sorted(bpy.ops.preferences.addon_install(filepath=zip_path))


def _raise(exc):
    raise exc


addon_utils.enable("exsynth", default_set=True, handle_error=_raise)
native = sys.modules["exsynth._native"]
seen["native_file"] = native.__file__
bpy.ops.mesh.primitive_torus_add(major_radius=1.0, minor_radius=0.35)
bpy.context.scene.exsynth.resolution = 32
seen["voxelize"] = sorted(bpy.ops.exsynth.voxelize())
volumes = [o for o in bpy.data.objects if o.type == 'VOLUME']
grids = native.read_vdb(bpy.path.abspath(volumes[0].data.filepath))["grids"] if volumes else {}
seen["sdf_inside_voxels"] = int((np.asarray(grids["sdf"]) < 0).sum()) if grids else 0
with open(out_path, "w", encoding="utf-8") as fh:
    json.dump(seen, fh)
