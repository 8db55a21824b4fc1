# SPDX-License-Identifier: GPL-3.0-or-later
"""The zips of `./exsynth package` (build/dist/): what they hold, that the
bundled libraries resolve among themselves, and that the extension installs
into a clean user folder of Blender 4.5 (the PyPI bpy module) and runs jobs.

Run by `./exsynth test` with /usr/bin/python3 after `./exsynth package`;
EXSYNTH_DIST names the zips' folder, EXSYNTH_BPY_PYTHON the bpy venv's python.
"""

import glob
import json
import os
import re
import subprocess
import tomllib
import zipfile

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DIST = os.environ.get("EXSYNTH_DIST", os.path.join(ROOT, "build", "dist"))
BPY_PYTHON = os.environ.get("EXSYNTH_BPY_PYTHON", os.path.join(ROOT, "build", "bpy-4.5.15", "bin", "python"))
JOB = os.path.join(os.path.dirname(os.path.abspath(__file__)), "extension_job.py")
# What the package may take from the system (the manylinux assumption).
SYSTEM = re.compile(r"^(linux-vdso|ld-linux.*|libc|libm|libdl|librt|libpthread|libutil|libstdc\+\+|libgcc_s)\.so")


def one_zip(pattern):
    found = glob.glob(os.path.join(DIST, pattern))
    assert len(found) == 1, f"expected one {pattern} in {DIST} (run ./exsynth package): {found}"
    return found[0]


@pytest.fixture(scope="module")
def extension_zip():
    return one_zip("exsynth-*-linux_x64.zip")


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
    assert manifest["schema_version"] == "1.0.0" and manifest["blender_version_min"] == "4.2.0"
    assert manifest["license"] == ["SPDX:GPL-3.0-or-later"] and manifest["platforms"] == ["linux-x64"]
    assert "files" in manifest["permissions"]
    assert len(manifest["tagline"]) <= 64 and not manifest["tagline"].endswith((".", "!", "?"))
    assert not list(unpacked.rglob("__pycache__"))


def test_legacy_zip_is_the_same_package_in_a_folder(extension_zip):
    legacy = one_zip("exsynth-*-legacy-addon.zip")
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
    assert (lib / "libembree3.so.3").exists()  # dlopened by the module, so not in its ldd list
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
def test_installs_into_a_clean_blender_45_and_runs_jobs(extension_zip, unpacked, tmp_path, mode):
    """mode global: Blender's libraries in the global symbol scope, as in the
    blender executable (with Embree bound by name, Voxelize came out empty)."""
    user = tmp_path / "user"
    user.mkdir()
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "LD_LIBRARY_PATH", "EXSYNTH_ADDON_DIR")}
    env["BLENDER_USER_RESOURCES"] = str(user)
    out = tmp_path / "seen.json"
    run = subprocess.run([BPY_PYTHON, JOB, extension_zip, mode, str(out)], env=env, cwd=tmp_path,
                         capture_output=True, text=True, timeout=600)
    assert run.returncode == 0 and out.exists(), run.stdout[-3000:] + run.stderr[-3000:]
    seen = json.loads(out.read_text())
    assert seen["blender"].startswith("4.5")
    assert not seen["exsynth_importable_before"] and seen["build_tree_on_path"] == []
    installed = str(user / "extensions" / "user_default" / "exsynth")
    assert seen["install"] == ["FINISHED"] and seen["addons"] == ["bl_ext.user_default.exsynth"]
    assert seen["package_dir"] == installed and seen["native_file"].startswith(installed + "/")
    # Voxelize: a filled torus, not the empty grid of a mis-bound Embree.
    assert seen["voxelize"] == ["FINISHED"] and seen["volumes"] == ["Torus_voxels"]
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


def test_legacy_zip_installs_into_debians_blender_34(tmp_path):
    legacy = one_zip("exsynth-*-legacy-addon.zip")
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
    assert seen["blender"].startswith("3.4") and seen["install"] == ["FINISHED"]
    assert seen["native_file"].startswith(str(scripts / "addons" / "exsynth") + "/")
    assert seen["voxelize"] == ["FINISHED"] and seen["sdf_inside_voxels"] > 500
