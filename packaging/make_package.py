# SPDX-License-Identifier: GPL-3.0-or-later
"""Builds the installable zips from the staged add-on (build/addon/exsynth):

    /usr/bin/python3 packaging/make_package.py --build build --out build/dist

- exsynth-VERSION-linux_x64.zip: a Blender 4.2+ extension (blender_manifest.toml
  at the root), for Edit > Preferences > Get Extensions > Install from Disk;
- exsynth-VERSION-legacy-addon.zip: the same package in an exsynth/ folder, for
  Edit > Preferences > Add-ons > Install (Blender 3.x with Python 3.11).

Both carry the compiled module and every shared library it needs that an
official Blender and a common Linux desktop lack, in exsynth/lib/, found with
ldd and given an $ORIGIN run path (patchelf), so the system's copies are not
needed. Excluded: what the manylinux policy assumes every Linux has (glibc's
libraries, libstdc++, libgcc_s). Blender's own TBB (same SONAME libtbb.so.12)
is reused when Blender has loaded it first; oneTBB keeps that ABI backward
compatible, so the module built against Debian's 2021.8 runs on Blender's newer
one. Embree 3 and Blender's Embree 4 share C function names: the module reaches
Embree through dlsym on its own copy (native/core/src/voxel/embree_api.hpp).
Both tested by tests/package/test_extension.py.
"""

import argparse
import ast
import os
import re
import shutil
import stat
import subprocess
import sys
import tempfile
import zipfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# What manylinux (PEP 599/600) lets a wheel assume: glibc's libraries, the
# GCC runtime, and the loader. Anything else ldd finds is bundled.
SYSTEM_LIBRARIES = re.compile(
    r"^(linux-vdso|ld-linux.*|libc|libm|libdl|librt|libpthread|libutil|libresolv|libnsl|libcrypt"
    r"|libstdc\+\+|libgcc_s)\.so"
)
LIB_DIR = "lib"
# Loaded by the module with dlopen, so ldd does not list them: bundled too.
DLOPENED = ("libembree3.so.3",)  # native/core/src/voxel/embree_api.cpp

MANIFEST = """\
schema_version = "1.0.0"

id = "exsynth"
version = "{version}"
name = "ExSynth"
tagline = "Example-based texture and geometry synthesis"
maintainer = "exsynth contributors"
type = "add-on"
tags = ["Modeling", "Mesh", "Material"]

blender_version_min = "4.2.0"
license = ["SPDX:{license}"]
platforms = ["linux-x64"]

[permissions]
files = "Read meshes and images, write volumes, meshes and textures"
"""


def addon_version(init_py):
    """bl_info["version"] of the add-on, as "X.Y.Z" (one place for it)."""
    tree = ast.parse(open(init_py, encoding="utf-8").read())
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(getattr(t, "id", None) == "bl_info" for t in node.targets):
            info = ast.literal_eval(node.value)
            return ".".join(str(part) for part in info["version"])
    raise SystemExit(f"make_package: no bl_info in {init_py}")


def spdx_license(license_file):
    """The SPDX id of the repository's LICENSE (the add-on's bl_info says "or later")."""
    text = open(license_file, encoding="utf-8").read(4000)
    if "GNU GENERAL PUBLIC LICENSE" in text and "Version 3" in text:
        return "GPL-3.0-or-later"
    raise SystemExit(f"make_package: cannot tell the SPDX id of {license_file}; add it to spdx_license()")


def needed_libraries(path):
    """{soname: resolved path} of every library ldd resolves for `path`
    (the whole closure), less the system ones."""
    out = subprocess.run(["ldd", path], check=True, capture_output=True, text=True,
                         env={**os.environ, "LD_LIBRARY_PATH": ""}).stdout
    found = {}
    for line in out.splitlines():
        match = re.match(r"\s*(\S+)\s+=>\s+(\S+)\s+\(", line)
        if not match:
            if "not found" in line:
                raise SystemExit(f"make_package: {path}: {line.strip()}")
            continue
        soname, resolved = match.groups()
        if not SYSTEM_LIBRARIES.match(soname):
            found[soname] = resolved
    return found


def system_library(soname):
    """Where the dynamic loader finds `soname` (ldconfig's cache)."""
    out = subprocess.run(["/sbin/ldconfig", "-p"], check=True, capture_output=True, text=True).stdout
    for line in out.splitlines():
        match = re.match(r"\s*(\S+)\s+\(([^)]*)\)\s+=>\s+(\S+)", line)
        if match and match.group(1) == soname and "x86-64" in match.group(2):
            return match.group(3)
    raise SystemExit(f"make_package: {soname} is not installed (./exsynth setup installs it)")


def patchelf(*args):
    if shutil.which("patchelf") is None:
        raise SystemExit("make_package: patchelf is missing (./exsynth setup installs it)")
    subprocess.run(["patchelf", *args], check=True)


def stage(addon_dir, dest):
    """Copies the add-on into dest/exsynth with its libraries in lib/."""
    pkg = os.path.join(dest, "exsynth")
    shutil.copytree(addon_dir, pkg, ignore=shutil.ignore_patterns("__pycache__", "*.pyc", LIB_DIR))
    natives = [f for f in os.listdir(pkg) if f.startswith("_native") and f.endswith(".so")]
    if len(natives) != 1:
        raise SystemExit(f"make_package: expected one compiled _native module in {addon_dir}, found {natives}")
    native = os.path.join(pkg, natives[0])
    libs = needed_libraries(native)
    for soname in DLOPENED:
        path = system_library(soname)
        libs[soname] = path
        libs.update(needed_libraries(path))
    os.makedirs(os.path.join(pkg, LIB_DIR))
    for soname, resolved in sorted(libs.items()):
        target = os.path.join(pkg, LIB_DIR, soname)
        shutil.copyfile(resolved, target)
        os.chmod(target, stat.S_IRUSR | stat.S_IWUSR | stat.S_IRGRP | stat.S_IROTH)
        # Each bundled library finds its own dependencies beside itself.
        patchelf("--set-rpath", "$ORIGIN", target)
    subprocess.run(["strip", "--strip-unneeded", native], check=True)
    patchelf("--set-rpath", f"$ORIGIN/{LIB_DIR}", native)
    return pkg, sorted(libs)


def write_zip(path, root, arc_prefix=""):
    """A deterministic zip of the tree under root (sorted, fixed timestamps)."""
    tmp = path + ".part"
    with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as zf:
        for dirpath, dirnames, filenames in os.walk(root):
            dirnames.sort()
            for name in sorted(filenames):
                full = os.path.join(dirpath, name)
                arc = os.path.join(arc_prefix, os.path.relpath(full, root))
                info = zipfile.ZipInfo(arc, date_time=(2024, 1, 1, 0, 0, 0))
                info.external_attr = (os.stat(full).st_mode & 0o777) << 16
                info.compress_type = zipfile.ZIP_DEFLATED
                with open(full, "rb") as fh:
                    zf.writestr(info, fh.read())
    os.replace(tmp, path)  # no partial zip under the final name


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", default=os.path.join(ROOT, "build"), help="the CMake build folder")
    parser.add_argument("--out", help="where the zips go (default BUILD/dist)")
    args = parser.parse_args(argv)
    addon_dir = os.path.join(args.build, "addon", "exsynth")
    if not os.path.isfile(os.path.join(addon_dir, "__init__.py")):
        raise SystemExit(f"make_package: no staged add-on in {addon_dir}: run ./exsynth build first")
    out = args.out or os.path.join(args.build, "dist")
    os.makedirs(out, exist_ok=True)
    version = addon_version(os.path.join(addon_dir, "__init__.py"))
    license_id = spdx_license(os.path.join(ROOT, "LICENSE"))
    with tempfile.TemporaryDirectory() as tmp:
        pkg, libs = stage(addon_dir, tmp)
        legacy = os.path.join(out, f"exsynth-{version}-legacy-addon.zip")
        write_zip(legacy, pkg, "exsynth")
        with open(os.path.join(pkg, "blender_manifest.toml"), "w", encoding="utf-8") as fh:
            fh.write(MANIFEST.format(version=version, license=license_id))
        extension = os.path.join(out, f"exsynth-{version}-linux_x64.zip")
        write_zip(extension, pkg)
    print(f"bundled {len(libs)} libraries: {' '.join(libs)}")
    for path in (extension, legacy):
        print(f"{path}  ({os.path.getsize(path) / 1e6:.1f} MB)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
