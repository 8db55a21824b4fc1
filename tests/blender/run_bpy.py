# SPDX-License-Identifier: GPL-3.0-or-later
"""The add-on test tier in a current Blender built as a Python module (the
`bpy` wheels on PyPI: 4.2 LTS, 4.5 LTS, 5.x), beside Debian's Blender 3.4:

    VENV/bin/python tests/blender/run_bpy.py -- tests/blender -q -p no:cacheprovider

The module is a whole Blender in this interpreter; factory settings first
(they disable add-ons), then the same entry point as inside `blender -b`.
"""

import os
import runpy
import sys

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))


def main():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    print(f"run_bpy: Blender {bpy.app.version_string} as a Python module", flush=True)
    sys.path.insert(0, HERE)
    try:
        runpy.run_path(os.path.join(HERE, "run_tests.py"), run_name="__main__")
        code = 0
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else 1
    sys.stdout.flush()
    sys.stderr.flush()
    # Skip the interpreter's teardown: the 4.2.23 module segfaults there after
    # every test has passed (seen in this tier); the result is already known.
    os._exit(code)


if __name__ == "__main__":
    main()
