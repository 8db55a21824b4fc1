# SPDX-License-Identifier: GPL-3.0-or-later
"""Headless jobs, run inside `blender -b` by `./exsynth run JOB ARGS...`.

Each job takes the same path as its operator: Blender imports the input,
io/ turns it into arrays, the operator's Job runs through jobs.Runner.
Exit codes: 0 done, 1 the job failed (engine or file error), 2 bad arguments.
"""

import argparse
import os
import sys

import bpy
import numpy as np

from . import _native, jobs
from .io import mesh as mesh_io
from .operators.voxelize import VoxelizeJob
from .properties import GIB

MESH_FORMATS = (".obj", ".ply", ".stl")
VOXEL_FORMATS = (".vdb", ".npy")


class UsageError(Exception):
    """A bad argument; the message names it."""


def main(argv=None) -> int:
    parser = _parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # argparse exits on --help (0) and on its own errors (2)
        return exc.code if isinstance(exc.code, int) else 2
    if args.job is None:
        parser.print_help(sys.stderr)
        return 2
    try:
        return args.run(args)
    except UsageError as exc:
        print(f"exsynth {args.job}: error: {exc}", file=sys.stderr)
        return 2
    except (jobs.REPORTED_ERRORS + (RuntimeError,)) as exc:  # RuntimeError: a bpy.ops failure
        print(f"exsynth {args.job}: failed: {exc}", file=sys.stderr)
        return 1


def _parser():
    parser = argparse.ArgumentParser(
        prog="./exsynth run", description="Headless exsynth jobs (run inside Blender)."
    )
    sub = parser.add_subparsers(dest="job", title="jobs", metavar="JOB")

    p = sub.add_parser(
        "voxelize", help="mesh -> density and signed-distance voxels (.vdb or .npy)",
        description="Voxelize a mesh file. Coordinates stay those of the file (no axis conversion).",
    )
    p.add_argument("--mesh", required=True, help="input mesh: .obj, .ply or .stl")
    p.add_argument("--out", required=True,
                   help=".vdb (grids density and sdf) or .npy ((Z, Y, X, 2) float32: density, sdf)")
    p.add_argument("--resolution", type=int, default=128,
                   help="voxels along the longest bounding-box side (default 128)")
    p.add_argument("--voxel-size", type=float, default=0.0,
                   help="voxel edge length in mesh units; overrides --resolution when > 0")
    p.add_argument("--padding", type=int, default=2, help="empty voxels on every side (default 2)")
    p.add_argument("--supersample", type=int, default=2, help="sub-rays per voxel edge, 1..8 (default 2)")
    p.add_argument("--mesh-out", help="also write the rebuilt surface (zero level of the sdf) as .obj")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--memory-budget", type=float, default=0.0,
                   help="refuse jobs needing more than this many GiB (default: the engine's 8 GiB)")
    p.set_defaults(run=_run_voxelize)

    p = sub.add_parser("demo", help="voxelize the bundled bunny and render PNGs",
                       description="Voxelize assets/meshes/bunny.obj and render it with Cycles.")
    p.add_argument("--assets", required=True, help="the repository's assets/ folder")
    p.add_argument("--out", required=True, help="folder for the PNGs")
    p.add_argument("--resolution", type=int, default=96, help="voxels along the longest side (default 96)")
    p.add_argument("--samples", type=int, default=16, help="Cycles samples per pixel (default 16)")
    p.set_defaults(run=_run_demo)
    return parser


# ---- voxelize ----------------------------------------------------------------
def _run_voxelize(args):
    mesh_path = _input_file("--mesh", args.mesh, MESH_FORMATS)
    out_ext = _extension("--out", args.out, VOXEL_FORMATS)
    if args.mesh_out:
        _extension("--mesh-out", args.mesh_out, (".obj",))
    _require(args.resolution > 0, f"--resolution must be > 0 (got {args.resolution})")
    _require(args.voxel_size >= 0, f"--voxel-size must be >= 0 (got {args.voxel_size}); 0 uses --resolution")
    _require(args.padding >= 0, f"--padding must be >= 0 (got {args.padding})")
    _require(args.memory_budget >= 0, f"--memory-budget must be >= 0 GiB (got {args.memory_budget})")

    objects = import_mesh(mesh_path)
    verts, tris = mesh_io.world_triangles(objects, bpy.context.evaluated_depsgraph_get())
    if len(tris) == 0:
        raise UsageError(f"--mesh: {mesh_path} has no faces to voxelize")
    job = VoxelizeJob(
        name=os.path.splitext(os.path.basename(mesh_path))[0], vertices=verts, triangles=tris,
        resolution=args.resolution, voxel_size=args.voxel_size, padding=args.padding,
        supersample=args.supersample, make_mesh=bool(args.mesh_out),
        memory_budget=int(args.memory_budget * GIB), seed=args.seed,
    )
    runner = jobs.Runner(job)
    runner.run_here()
    voxels = runner.outcome()

    _make_parent(args.out)
    if out_ext == ".vdb":
        _native.write_vdb(args.out, {"density": voxels.density, "sdf": voxels.sdf},
                          voxels.origin, voxels.voxel_size)
    else:
        np.save(args.out, np.stack([voxels.density, voxels.sdf], axis=-1).astype(np.float32))
    nx, ny, nz = voxels.dims_xyz
    line = (f"voxelize: {nx}x{ny}x{nz} voxels of {voxels.voxel_size:.6g} "
            f"from {len(tris)} triangles in {runner.seconds:.2f} s -> {args.out}")
    if args.mesh_out:
        _make_parent(args.mesh_out)
        export_obj(args.mesh_out, f"{job.name}_voxel_mesh", *voxels.surface)
        line += f", {len(voxels.surface[1])} triangles -> {args.mesh_out}"
    print(line)
    return 0


def import_mesh(path):
    """Import a mesh file without axis conversion; returns the new mesh objects."""
    before = {o.name for o in bpy.data.objects}
    ext = os.path.splitext(path)[1].lower()
    if ext == ".obj":
        bpy.ops.wm.obj_import(filepath=path, forward_axis='Y', up_axis='Z')
    elif f"{ext[1:]}_import" in dir(bpy.ops.wm):  # Blender >= 4.0: C++ PLY/STL importers
        getattr(bpy.ops.wm, f"{ext[1:]}_import")(filepath=path)
    else:  # Blender 3.x: the bundled Python add-ons (default axes: none)
        _enable_bundled_addon({".ply": "io_mesh_ply", ".stl": "io_mesh_stl"}[ext])
        getattr(bpy.ops.import_mesh, ext[1:])(filepath=path)
    return [o for o in bpy.data.objects if o.name not in before and o.type == 'MESH']


def export_obj(path, name, vertices, triangles):
    """Write (vertices, triangles) as OBJ through Blender's exporter, in the
    same (unconverted) axes the input was read in."""
    obj = bpy.data.objects.new(name, mesh_io.new_mesh(name, vertices, triangles))
    bpy.context.scene.collection.objects.link(obj)
    for other in list(bpy.context.view_layer.objects.selected):
        other.select_set(False)
    obj.select_set(True)
    bpy.ops.wm.obj_export(filepath=path, export_selected_objects=True, forward_axis='Y',
                          up_axis='Z', export_materials=False, export_uv=False)


def _enable_bundled_addon(name):
    import addon_utils

    loaded_default, loaded_state = addon_utils.check(name)
    if not loaded_state and addon_utils.enable(name, default_set=False) is None:
        raise RuntimeError(f"Blender's bundled add-on {name} could not be enabled")


# ---- demo --------------------------------------------------------------------
def _run_demo(args):
    from . import demo

    bunny = _input_file("--assets", os.path.join(args.assets, "meshes", "bunny.obj"), (".obj",))
    _require(args.resolution > 0, f"--resolution must be > 0 (got {args.resolution})")
    _require(args.samples > 0, f"--samples must be > 0 (got {args.samples})")
    os.makedirs(args.out, exist_ok=True)
    return demo.run(bunny, args.out, resolution=args.resolution, samples=args.samples)


# ---- argument checks ----------------------------------------------------------
def _require(ok, message):
    if not ok:
        raise UsageError(message)


def _extension(arg, path, allowed):
    ext = os.path.splitext(path)[1].lower()
    _require(ext in allowed, f"{arg}: unsupported file type '{ext or path}' (use {', '.join(allowed)})")
    return ext


def _input_file(arg, path, allowed):
    path = os.path.abspath(path)
    _require(os.path.isfile(path), f"{arg}: no such file: {path}")
    _extension(arg, path, allowed)
    return path


def _make_parent(path):
    parent = os.path.dirname(os.path.abspath(path))
    os.makedirs(parent, exist_ok=True)
