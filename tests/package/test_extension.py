# SPDX-License-Identifier: GPL-3.0-or-later
"""The zips of `./exsynth package --this-python` (build/dist/) for the Python
these tests run under: what they hold, that the bundled libraries resolve
among themselves, that the extension installs into a clean user folder of
the current Blender for that Python (the PyPI bpy module: 4.5 LTS for 3.11,
5.2 LTS for 3.13) and runs jobs, that the same Blender refuses the other
Python's zip, and that the legacy zip runs in Debian's own Blender.

Run by `./exsynth test` with /usr/bin/python3 after `./exsynth package`;
EXSYNTH_DIST names the zips' folder, EXSYNTH_BPY_PYTHON the bpy venv's
python, EXSYNTH_BPY_VERSION its Blender version.
"""

import glob
import json
import os
import re
import subprocess
import sys
import tomllib
import zipfile

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DIST = os.environ.get("EXSYNTH_DIST", os.path.join(ROOT, "build", "dist"))
BPY_PYTHON = os.environ["EXSYNTH_BPY_PYTHON"]
BPY_VERSION = os.environ["EXSYNTH_BPY_VERSION"]
JOB = os.path.join(os.path.dirname(os.path.abspath(__file__)), "extension_job.py")
sys.path.insert(0, os.path.join(ROOT, "build", "addon"))
sys.path.insert(0, os.path.join(ROOT, "packaging"))
from exsynth import _native, platforms  # noqa: E402  (the staged add-on: its table and module)
import make_package  # noqa: E402

PYTHON = sys.version_info[:2]
OTHER_PYTHON = next(p for p in sorted(platforms.PYTHONS) if p != PYTHON)
# What the package may take from the system (the manylinux assumption).
SYSTEM = re.compile(r"^(linux-vdso|ld-linux.*|libc|libm|libdl|librt|libpthread|libutil|libstdc\+\+|libgcc_s)\.so")


def one_zip(name_of):
    """The zip of this Python named by platforms' `name_of` (any version)."""
    found = glob.glob(os.path.join(DIST, name_of("*", PYTHON)))
    assert len(found) == 1, f"expected one {name_of('*', PYTHON)} in {DIST} (run ./exsynth package): {found}"
    return found[0]


@pytest.fixture(scope="module")
def extension_zip():
    return one_zip(platforms.extension_zip)


@pytest.fixture(scope="module")
def unpacked(extension_zip, tmp_path_factory):
    root = tmp_path_factory.mktemp("unpacked")
    with zipfile.ZipFile(extension_zip) as zf:
        zf.extractall(root)
    for path in root.rglob("*.so*"):
        path.chmod(0o755)
    return root


def test_manifest(unpacked):
    manifest = tomllib.loads((unpacked / "blender_manifest.toml").read_text())
    init = (unpacked / "__init__.py").read_text()
    version = re.search(r'"version":\s*\((\d+),\s*(\d+),\s*(\d+)\)', init).groups()
    assert manifest["id"] == "exsynth" and manifest["type"] == "add-on"
    assert manifest["version"] == ".".join(version)
    blender_min, blender_max = platforms.manifest_range(PYTHON)
    assert manifest["schema_version"] == "1.0.0" and manifest["blender_version_min"] == blender_min
    assert manifest.get("blender_version_max") == blender_max
    # The Blender range holds the bpy release this Python's tests run in.
    bpy_version = tuple(int(p) for p in BPY_VERSION.split("."))
    assert tuple(int(p) for p in blender_min.split(".")) <= bpy_version
    assert blender_max is None or bpy_version < tuple(int(p) for p in blender_max.split("."))
    assert manifest["license"] == ["SPDX:GPL-3.0-or-later"] and manifest["platforms"] == ["linux-x64"]
    assert "files" in manifest["permissions"]
    assert len(manifest["tagline"]) <= 64 and not manifest["tagline"].endswith((".", "!", "?"))
    assert not list(unpacked.rglob("__pycache__"))


def test_legacy_zip_is_the_same_package_in_a_folder(extension_zip):
    legacy = one_zip(platforms.legacy_zip)
    with zipfile.ZipFile(extension_zip) as zf:
        ext_names = set(zf.namelist()) - {"blender_manifest.toml"}
    with zipfile.ZipFile(legacy) as zf:
        names = zf.namelist()
        assert "bl_info" in zf.read("exsynth/__init__.py").decode()
    assert all(n.startswith("exsynth/") for n in names)
    assert {n[len("exsynth/"):] for n in names} == ext_names


def test_every_library_resolves_inside_the_package(unpacked):
    """ldd with LD_LIBRARY_PATH cleared, on the module and each bundled
    library: every dependency is bundled or one the system may provide."""
    lib = unpacked / "lib"
    targets = sorted(unpacked.glob("_native*.so")) + sorted(lib.iterdir())
    assert len(targets) > 10
    assert (lib / _native.EMBREE_LIBRARY).exists()  # dlopened by the module, so not in its ldd list
    assert [p.name for p in unpacked.glob("_native*.so")] == [
        f"_native.cpython-{PYTHON[0]}{PYTHON[1]}-x86_64-linux-gnu.so"]
    env = {k: v for k, v in os.environ.items() if k != "LD_LIBRARY_PATH"}
    for target in targets:
        out = subprocess.run(["ldd", str(target)], capture_output=True, text=True, env=env, check=True).stdout
        for line in out.splitlines():
            match = re.match(r"\s*(\S+)\s+=>\s+(\S+)", line)
            if not match:
                continue
            soname, resolved = match.groups()
            assert resolved != "not", f"{target.name}: {soname} not found"
            if not SYSTEM.match(soname):
                assert os.path.dirname(resolved) == str(lib), f"{target.name}: {soname} => {resolved}"
    readelf = subprocess.run(["readelf", "-d", str(targets[0])], capture_output=True, text=True, check=True).stdout
    assert "[$ORIGIN/lib]" in readelf


@pytest.mark.parametrize("mode", ["local", "global"])
def test_installs_into_a_clean_current_blender_and_runs_jobs(extension_zip, unpacked, tmp_path, mode):
    """mode global: Blender's libraries in the global symbol scope, as in the
    blender executable (with Embree bound by name, Voxelize came out empty)."""
    user = tmp_path / "user"
    user.mkdir()
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "LD_LIBRARY_PATH", "EXSYNTH_ADDON_DIR")}
    env["BLENDER_USER_RESOURCES"] = str(user)
    out = tmp_path / "seen.json"
    seen = run_job(extension_zip, mode, tmp_path, env)
    assert seen["blender"] == BPY_VERSION
    assert not seen["exsynth_importable_before"] and seen["build_tree_on_path"] == []
    installed = str(user / "extensions" / "user_default" / "exsynth")
    assert seen["install"] == ["FINISHED"] and seen["addons"] == ["bl_ext.user_default.exsynth"]
    assert seen["package_dir"] == installed and seen["native_file"].startswith(installed + "/")
    # Voxelize: a filled torus, not the empty grid of a mis-bound Embree.
    assert seen["voxelize"] == ["FINISHED"] and seen["volumes"] == ["Torus_voxels"]
    assert seen["tools"] == {name: ["FINISHED"] for name in
                             ("direction_field", "solid_texture", "surface_texture", "point_texture")}
    assert seen["tool_results"]["solid_texture"] and seen["tool_results"]["surface_texture"]
    assert seen["tool_results"]["point_texture"]
    assert seen["sdf_inside_voxels"] > 1000 and seen["density_sum"] > 1000
    assert len(seen["voxel_mesh_vertices"]) == 1 and seen["voxel_mesh_vertices"][0] > 1000
    assert seen["geometric_texture"] == ["FINISHED"]
    assert [name for name, _ in seen["texture_results"]] == ["Torus_spikes"]
    assert seen["texture_results"][0][1] > 1000
    assert seen["render_coverage"] > 0.05  # Cycles drew the scene
    # Every bundled library in use is the package's copy, unless Blender had
    # loaded one of the same SONAME first (then that one is shared).
    mapped = seen["mapped"]
    blender_libs = {os.path.basename(p) for p in mapped if "/bpy/lib/" in p}
    for name in sorted(os.listdir(unpacked / "lib")):
        users = [p for p in mapped if os.path.basename(p) == name]
        if name in blender_libs:
            assert all("/bpy/lib/" in p for p in users), users
        elif name.startswith(("libopenvdb", "libembree", "libosdCPU", "libImath", "libblosc", "libboost")):
            assert users == [os.path.join(installed, "lib", name)], (name, users)


def run_job(zip_path, mode, tmp_path, env):
    out = tmp_path / "seen.json"
    run = subprocess.run([BPY_PYTHON, JOB, zip_path, mode, str(out)], env=env, cwd=tmp_path,
                         capture_output=True, text=True, timeout=900)
    assert run.returncode == 0 and out.exists(), run.stdout[-3000:] + run.stderr[-3000:]
    seen = json.loads(out.read_text())
    seen["stdout"] = run.stdout
    return seen


def test_the_other_pythons_zip_is_refused_by_blender(extension_zip, tmp_path):
    """The other Python's extension (its manifest's Blender range, as
    make_package writes it) is refused by this Blender at install, with
    Blender's own message naming the versions, and nothing is installed."""
    other = tmp_path / platforms.extension_zip("0.1.0", OTHER_PYTHON)
    blender_min, blender_max = platforms.manifest_range(OTHER_PYTHON)
    with zipfile.ZipFile(extension_zip) as src, zipfile.ZipFile(other, "w") as dst:
        manifest = tomllib.loads(src.read("blender_manifest.toml").decode())
        for item in src.infolist():
            data = src.read(item)
            if item.filename == "blender_manifest.toml":
                data = make_package.manifest_text(manifest["version"], manifest["license"][0][len("SPDX:"):],
                                                  blender_min, blender_max).encode()
            dst.writestr(item, data)
    user = tmp_path / "user"
    user.mkdir()
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "LD_LIBRARY_PATH", "EXSYNTH_ADDON_DIR")}
    env["BLENDER_USER_RESOURCES"] = str(user)
    seen = run_job(str(other), "refused", tmp_path, env)
    assert seen["blender"] == BPY_VERSION and seen["addons"] == []
    assert not (user / "extensions" / "user_default" / "exsynth").exists()
    # Blender reports the refusal (the operator itself returns FINISHED).
    bound = blender_min if blender_max is None else blender_max
    said = [line for line in seen["stdout"].splitlines() if line.startswith("ERROR exsynth:")]
    assert len(said) == 1 and f"({bound})" in said[0] and BPY_VERSION in said[0], seen["stdout"][-2000:]


def test_legacy_zip_installs_into_debians_blender(tmp_path):
    legacy = one_zip(platforms.legacy_zip)
    scripts = tmp_path / "scripts"
    scripts.mkdir()
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "EXSYNTH_ADDON_DIR")}
    env["BLENDER_USER_SCRIPTS"] = str(scripts)
    out = tmp_path / "seen.json"
    job = os.path.join(os.path.dirname(os.path.abspath(__file__)), "legacy_job.py")
    run = subprocess.run(["blender", "-b", "--factory-startup", "--python-exit-code", "1", "--python", job, "--",
                          legacy, str(out)], env=env, cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0 and out.exists(), run.stdout[-3000:] + run.stderr[-3000:]
    seen = json.loads(out.read_text())
    assert seen["python"] == list(PYTHON) and seen["install"] == ["FINISHED"]
    assert seen["native_file"].startswith(str(scripts / "addons" / "exsynth") + "/")
    assert seen["voxelize"] == ["FINISHED"] and seen["sdf_inside_voxels"] > 500
