"""addon/exsynth/platforms.py: which zip fits which Blender, and the one-line
message an artist sees when a zip's module is not for their Blender's Python.
Also: the module built here is for the Python running these tests, and
names the Embree library it loads (what a package must carry)."""

import re
import sys

import pytest

from exsynth import _native, platforms

ORDER = sorted(platforms.PYTHONS)


def parse(version):
    return tuple(int(p) for p in version.split("."))


def test_the_pythons_blender_ranges_follow_each_other_without_overlap():
    """Blender refuses an extension outside its manifest's range: the ranges
    must not overlap (two zips installable in one Blender) nor leave a gap."""
    assert ORDER == [(3, 11), (3, 13)]
    ranges = [platforms.manifest_range(p) for p in ORDER]
    assert ranges == [("4.2.0", "5.1.0"), ("5.1.0", None)]
    for (_, end), (start, _) in zip(ranges, ranges[1:]):
        assert parse(end) == parse(start)
    assert [platforms.blender_range(p) for p in ORDER] == ["Blender 4.2 to 5.0", "Blender 5.1 and later"]


def test_zip_names_say_which_blender_and_python():
    assert platforms.extension_zip("0.1.0", (3, 11)) == "exsynth-0.1.0-blender-4.2-to-5.0-linux_x64.zip"
    assert platforms.extension_zip("0.1.0", (3, 13)) == "exsynth-0.1.0-blender-5.1-and-later-linux_x64.zip"
    assert platforms.legacy_zip("0.1.0", (3, 13)) == "exsynth-0.1.0-legacy-addon-python3.13.zip"
    names = {platforms.extension_zip("1.2.3", p) for p in ORDER} | {platforms.legacy_zip("1.2.3", p) for p in ORDER}
    assert len(names) == 4


@pytest.mark.parametrize("python", [(3, 11), (3, 13)])
def test_wrong_module_message_names_the_zip_for_this_python(python):
    message = platforms.wrong_module_message((0, 1, 0), python, (4, 3, 2))
    assert "\n" not in message and message.startswith("exsynth: ")
    assert f"runs Python {python[0]}.{python[1]}" in message and "Blender 4.3.2" in message
    assert platforms.extension_zip("0.1.0", python) in message
    assert platforms.legacy_zip("0.1.0", python) in message
    other = next(p for p in ORDER if p != python)
    assert platforms.extension_zip("0.1.0", other) not in message


def test_an_unsupported_python_is_told_which_pythons_exist():
    message = platforms.wrong_module_message((0, 1, 0), (3, 12), (4, 1, 0))
    assert "runs Python 3.12" in message and "\n" not in message
    assert "3.11 (Blender 4.2 to 5.0)" in message and "3.13 (Blender 5.1 and later)" in message
    assert ".zip" not in message


def test_module_failure_tells_apart_missing_wrong_python_and_broken(tmp_path):
    here = sys.version_info[:2]
    other = next(p for p in ORDER if p != here)
    missing = platforms.module_failure(str(tmp_path), (0, 1, 0), (5, 2, 3), ImportError("x"))
    assert "missing" in missing and "./exsynth build" in missing
    (tmp_path / f"_native.cpython-{other[0]}{other[1]}-x86_64-linux-gnu.so").write_bytes(b"")
    wrong = platforms.module_failure(str(tmp_path), (0, 1, 0), (5, 2, 3), ImportError("x"))
    assert wrong == platforms.wrong_module_message("0.1.0", here, (5, 2, 3))
    (tmp_path / f"_native.cpython-{here[0]}{here[1]}-x86_64-linux-gnu.so").write_bytes(b"")
    broken = platforms.module_failure(str(tmp_path), (0, 1, 0), (5, 2, 3), ImportError("undefined symbol: f"))
    assert f"for Python {here[0]}.{here[1]} is here but does not load (undefined symbol: f)" in broken
    assert platforms.module_pythons(str(tmp_path)) == sorted([here, other])


def test_the_module_is_built_for_this_python_and_names_its_embree():
    assert re.search(rf"\.cpython-{sys.version_info[0]}{sys.version_info[1]}-", _native.__file__)
    assert tuple(sys.version_info[:2]) in platforms.PYTHONS
    assert _native.EMBREE_LIBRARY in ("libembree3.so.3", "libembree4.so.4")
