# SPDX-License-Identifier: GPL-3.0-or-later
"""Loads the compiled module of a packaged add-on so that it binds to the
libraries bundled with it (./exsynth package puts them in lib/).

Official Blender ships its own Embree 4, OpenVDB 12, OpenSubdiv 3.6 and
TBB. The blender executable loads them as its own dependencies, so they sit
in the process's global symbol scope, which the dynamic loader searches
before a module's own libraries. Embree 3 and 4 export the same unversioned
C functions (rtcNewDevice, rtcIntersect1M, ...): without care the module's
Embree 3 calls land in Blender's Embree 4 and Voxelize silently returns an
empty grid (seen with the 4.5 bpy module when its libraries are loaded into
the global scope as the executable has them). RTLD_DEEPBIND makes the
module and its bundled libraries look in their own scope first. Libraries
with the same SONAME that Blender has already loaded (libtbb.so.12) are
shared, as they must be for one TBB scheduler per process.

The build tree (no lib/ folder) loads the module the ordinary way: the
system's libraries are the ones Debian's Blender uses too, and sanitizer
runtimes refuse RTLD_DEEPBIND.
"""

import importlib
import os
import sys

LIB_DIR = "lib"


def is_bundled():
    return os.path.isdir(os.path.join(os.path.dirname(os.path.abspath(__file__)), LIB_DIR))


def load_bundled():
    """Imports PACKAGE._native deep-bound when this is a packaged add-on; a
    load error is left for register() to report with advice."""
    name = f"{__package__}._native"
    if not is_bundled() or name in sys.modules or not hasattr(os, "RTLD_DEEPBIND"):
        return
    flags = sys.getdlopenflags()
    sys.setdlopenflags(flags | os.RTLD_DEEPBIND)
    try:
        importlib.import_module(name)
    except ImportError:
        pass
    finally:
        sys.setdlopenflags(flags)
