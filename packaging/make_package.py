# SPDX-License-Identifier: GPL-3.0-or-later
"""Builds the installable zips from the staged add-on (build/addon/exsynth),
for the Python this script runs under (the one the module was built for):

    /usr/bin/python3 packaging/make_package.py --build build --out build/dist

- exsynth-VERSION-blender-RANGE-linux_x64.zip: a Blender 4.2+ extension
  (blender_manifest.toml at the root), for Edit > Preferences > Get Extensions
  > Install from Disk; its manifest's Blender range is the releases that run
  this Python (addon/exsynth/platforms.py), so Blender refuses it elsewhere;
- exsynth-VERSION-legacy-addon-pythonX.Y.zip: the same package in an exsynth/
  folder, for Edit > Preferences > Add-ons > Install (Blender 3.x, and
  distributions' Blender builds, with this Python).

`./exsynth package` runs this once on this machine and once in a Debian root
with the other Python (Debian 12: 3.11, Debian 13: 3.13).

Both carry the compiled module and every shared library it needs that an
official Blender and a common Linux desktop lack, in exsynth/lib/, found with
ldd and given an $ORIGIN run path (patchelf), so the system's copies are not
needed. Excluded: what the manylinux policy assumes every Linux has (glibc's
libraries, libstdc++, libgcc_s). Blender's own TBB (same SONAME libtbb.so.12)
is reused when Blender has loaded it first; oneTBB keeps that ABI backward
compatible, so the module built against Debian's 2021.8 runs on Blender's newer
one. Embree 3 and Blender's Embree 4 share C function names: the module reaches
Embree through dlsym on its own copy (native/core/src/voxel/embree_api.hpp).
Both tested by tests/package/test_extension.py. Printed: the newest glibc
symbol version the zip's binaries need (the oldest glibc that loads them).
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

MANIFEST = """\
schema_version = "1.0.0"

id = "exsynth"
version = "{version}"
name = "ExSynth"
tagline = "Example-based texture and geometry synthesis"
maintainer = "exsynth contributors"
type = "add-on"
tags = ["Modeling", "Mesh", "Material"]

blender_version_min = "{blender_min}"
{blender_max}license = ["SPDX:{license}"]
platforms = ["linux-x64"]

[permissions]
files = "Read meshes and images, write volumes, meshes and textures"
"""


def manifest_text(version, license_id, blender_min, blender_max):
    """blender_manifest.toml of the extension for Blender [min, max)."""
    return MANIFEST.format(version=version, license=license_id, blender_min=blender_min,
                           blender_max=f'blender_version_max = "{blender_max}"\n' if blender_max else "")


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


def symbol_floor(paths, prefix):
    """The newest `prefix`x.y[.z] symbol version (GLIBC_, GLIBCXX_) any of
    `paths` needs from the system, as a tuple of ints."""
    newest = (0,)
    for path in paths:
        out = subprocess.run(["objdump", "-T", path], check=True, capture_output=True, text=True).stdout
        for version in re.findall(r"\*UND\*\s+\S+\s+(?:\(|)" + prefix + r"(\d+(?:\.\d+)+)", out):
            newest = max(newest, tuple(int(p) for p in version.split(".")))
    return newest


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


def stage(addon_dir, dest, dlopened):
    """Copies the add-on into dest/exsynth with its libraries in lib/."""
    pkg = os.path.join(dest, "exsynth")
    shutil.copytree(addon_dir, pkg, ignore=shutil.ignore_patterns("__pycache__", "*.pyc", LIB_DIR))
    natives = [f for f in os.listdir(pkg) if f.startswith("_native") and f.endswith(".so")]
    if len(natives) != 1:
        raise SystemExit(f"make_package: expected one compiled _native module in {addon_dir}, found {natives}")
    native = os.path.join(pkg, natives[0])
    libs = needed_libraries(native)
    for soname in dlopened:  # loaded with dlopen, so ldd does not list them
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
    # The staged add-on's own table and module (built for this Python).
    sys.path.insert(0, os.path.dirname(addon_dir))
    from exsynth import _native, platforms

    python = sys.version_info[:2]
    if tuple(python) not in platforms.PYTHONS:
        raise SystemExit(f"make_package: no Blender release runs Python {python[0]}.{python[1]} "
                         f"(addon/exsynth/platforms.py knows {sorted(platforms.PYTHONS)})")
    blender_min, blender_max = platforms.manifest_range(python)
    with tempfile.TemporaryDirectory() as tmp:
        pkg, libs = stage(addon_dir, tmp, [_native.EMBREE_LIBRARY])
        binaries = [os.path.join(pkg, n) for n in os.listdir(pkg) if n.endswith(".so")]
        binaries += [os.path.join(pkg, LIB_DIR, n) for n in libs]
        glibc, glibcxx = symbol_floor(binaries, "GLIBC_"), symbol_floor(binaries, "GLIBCXX_")
        legacy = os.path.join(out, platforms.legacy_zip(version, python))
        write_zip(legacy, pkg, "exsynth")
        with open(os.path.join(pkg, "blender_manifest.toml"), "w", encoding="utf-8") as fh:
            fh.write(manifest_text(version, license_id, blender_min, blender_max))
        extension = os.path.join(out, platforms.extension_zip(version, python))
        write_zip(extension, pkg)
    print(f"Python {python[0]}.{python[1]} ({platforms.blender_range(python)}): "
          f"bundled {len(libs)} libraries: {' '.join(libs)}")
    for path in (extension, legacy):
        print(f"{path}  ({os.path.getsize(path) / 1e6:.1f} MB)")
    dotted = lambda v: ".".join(map(str, v))  # noqa: E731
    print(f"system floor: the binaries need glibc {dotted(glibc)} (GLIBC_{dotted(glibc)}) and the "
          f"libstdc++ of GLIBCXX_{dotted(glibcxx)} or newer")
    return 0


if __name__ == "__main__":
    sys.exit(main())
