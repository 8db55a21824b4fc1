# SPDX-License-Identifier: GPL-3.0-or-later
"""Which zip fits which Blender: the one table that `./exsynth package`
(packaging/make_package.py) names and bounds the zips by, and that the add-on
reads when its compiled module does not load in the Blender at hand.

The compiled module exsynth._native is built for one Python (its ABI):
official Blender 4.2 to 5.0 run Python 3.11, 5.1 and later run 3.13. Each
Python has its own extension zip, whose manifest's Blender range keeps
Blender from installing it where that Python is not, and its own legacy
add-on zip (Blender 3.x, and Linux distributions' Blender builds, whose
Python is the distribution's). No bpy here: the packaging script and the
plain-Python tests import this file.
"""

import os
import re
import sys

# Python (major, minor) -> the official Blender releases that run it:
# [first, end) with end exclusive (None: no newer Blender known to change it).
PYTHONS = {
    (3, 11): ((4, 2, 0), (5, 1, 0)),
    (3, 13): ((5, 1, 0), None),
}


def _dotted(version):
    """(5, 2, 3) -> "5.2.3"; a string is already dotted."""
    return version if isinstance(version, str) else ".".join(str(part) for part in version)


def blender_range(python):
    """The official Blender releases whose Python is `python`, in words."""
    first, end = PYTHONS[tuple(python[:2])]
    if end is None:
        return f"Blender {_dotted(first[:2])} and later"
    last = (end[0], end[1] - 1) if end[1] > 0 else (end[0] - 1, "x")
    return f"Blender {_dotted(first[:2])} to {_dotted(last)}"


def extension_zip(version, python):
    """File name of the extension zip for `python` (Blender 4.2 and later)."""
    first, end = PYTHONS[tuple(python[:2])]
    span = f"{_dotted(first[:2])}-and-later" if end is None else f"{_dotted(first[:2])}-to-{_dotted((end[0], end[1] - 1))}"
    return f"exsynth-{version}-blender-{span}-linux_x64.zip"


def legacy_zip(version, python):
    """File name of the legacy add-on zip for `python` (Blender 3.x and
    distributions' Blender builds, installed under Add-ons)."""
    return f"exsynth-{version}-legacy-addon-python{python[0]}.{python[1]}.zip"


def manifest_range(python):
    """blender_version_min and blender_version_max (None: no maximum) of the
    extension zip for `python`, as the manifest spells them."""
    first, end = PYTHONS[tuple(python[:2])]
    return _dotted(first), None if end is None else _dotted(end)


def wrong_module_message(version, python=None, blender=None, reason=""):
    """One line for an artist whose Blender cannot load the module in this
    zip: what this Blender runs and which zip to get instead."""
    version = _dotted(version)
    python = tuple((python or sys.version_info)[:2])
    here = f"this Blender{' ' + _dotted(blender) if blender else ''} runs Python {_dotted(python)}"
    if python in PYTHONS:
        fix = (f"install {extension_zip(version, python)} ({blender_range(python)}) or, for a "
               f"distribution's Blender, {legacy_zip(version, python)} under Add-ons")
    else:
        known = ", ".join(f"{_dotted(p)} ({blender_range(p)})" for p in sorted(PYTHONS))
        fix = f"exsynth is built for Python {known} only"
    detail = f" ({reason})" if reason else ""
    return f"exsynth: the compiled module does not load: {here}; {fix}{detail}."


def module_pythons(package_dir):
    """The Pythons whose compiled module is in `package_dir` (from the file
    names' ABI tags, _native.cpython-311-x86_64-linux-gnu.so and the like)."""
    found = set()
    for name in os.listdir(package_dir):
        match = re.match(r"_native\.cpython-(\d)(\d+)-.*\.so$", name)
        if match:
            found.add((int(match.group(1)), int(match.group(2))))
    return sorted(found)


def module_failure(package_dir, version, blender, exc):
    """The message for an ImportError of exsynth._native from `package_dir`."""
    here = tuple(sys.version_info[:2])
    if here in module_pythons(package_dir):
        return (f"exsynth: the compiled module for Python {_dotted(here)} is here but does not load ({exc}); "
                "rebuild it with `./exsynth build`, or reinstall the zip from `./exsynth package`.")
    if not module_pythons(package_dir):
        return ("exsynth: the compiled module exsynth._native is missing: build it with `./exsynth build` and "
                "enable the add-on from build/addon/, or install a zip from `./exsynth package`.")
    return wrong_module_message(version, here, blender)
