# SPDX-License-Identifier: GPL-3.0-or-later
"""Entry point of the add-on test tier; runs pytest inside headless Blender:

    blender -b --factory-startup --python-exit-code 1 \
        --python tests/blender/run_tests.py -- tests/blender -q -p no:cacheprovider

EXSYNTH_ADDON_DIR (set by ./exsynth) is the folder holding the staged
add-on package `exsynth` with its compiled `_native` module.
"""

import os
import sys

import addon_utils
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ADDON_DIR = os.environ.get("EXSYNTH_ADDON_DIR", os.path.join(ROOT, "build", "addon"))


def _raise(exc):
    raise exc


def main():
    if not os.path.isfile(os.path.join(ADDON_DIR, "exsynth", "__init__.py")):
        print(f"run_tests: no staged add-on in {ADDON_DIR}; run ./exsynth build "
              "(or set EXSYNTH_ADDON_DIR)", file=sys.stderr)
        return 2
    sys.path.insert(0, ADDON_DIR)
    # addon_utils swallows registration errors unless handle_error raises them.
    addon_utils.enable("exsynth", default_set=True, handle_error=_raise)
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else [os.path.dirname(__file__)]
    return int(pytest.main(argv))


if __name__ == "__main__":
    sys.exit(main())
