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
from .io import bake as bake_io
from .io import image as image_io
from .io import mesh as mesh_io
from .io.selection import select_only
from .operators import analogy as analogy_ops
from .operators import field as field_ops
from .operators import solid as solid_ops
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

    p = sub.add_parser(
        "solid", help="2D exemplar(s) -> solid texture (.vdb or .npy), optionally baked onto a mesh",
        description="Synthesize a tiling solid texture (Kopf et al. 2007) from exemplar images, as the "
        "Solid Texture operator does; with --mesh also bake it onto the mesh's UV map.",
    )
    p.add_argument("--exemplar", required=True, help="exemplar image (any format Blender reads)")
    p.add_argument("--exemplar-y", help="exemplar of the slices across Y (default: --exemplar)")
    p.add_argument("--exemplar-z", help="exemplar of the slices across Z (default: --exemplar)")
    p.add_argument("--size", type=int, default=64, help="voxels along each edge of the solid (default 64)")
    p.add_argument("--out", required=True,
                   help=".vdb (grid color, + alpha with --alpha) or .npy ((Z, Y, X, C) float32)")
    p.add_argument("--levels", type=int, default=3, help="coarse-to-fine levels (default 3)")
    p.add_argument("--iterations", type=int, default=3, help="optimisation rounds per level (default 3)")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--alpha", action="store_true", help="synthesize the exemplars' alpha as a 4th channel")
    p.add_argument("--scale", type=float, default=0.0,
                   help="edge length of one tile in mesh units (default: the mesh's longest side, "
                   "or 1 without --mesh); sets the .vdb's voxel size")
    p.add_argument("--mesh", help="also bake the solid onto this mesh (.obj, .ply, .stl; unwrapped with "
                   "Smart UV Project when it has no UVs)")
    p.add_argument("--bake-out", help="the baked texture (.png), with --mesh")
    p.add_argument("--bake-size", type=int, default=512, help="baked texture width and height (default 512)")
    p.add_argument("--mesh-out", help="with --mesh: write the mesh with the UV map the bake used (.obj)")
    p.add_argument("--memory-budget", type=float, default=0.0,
                   help="refuse jobs needing more than this many GiB (default: the engine's 8 GiB)")
    p.set_defaults(run=_run_solid)

    p = sub.add_parser(
        "image", help="2D exemplar -> larger (optionally tileable) image",
        description="2D texture synthesis with the solid engine's optimiser.",
    )
    p.add_argument("--exemplar", required=True, help="exemplar image (any format Blender reads)")
    p.add_argument("--width", type=int, required=True, help="output width in pixels")
    p.add_argument("--height", type=int, required=True, help="output height in pixels")
    p.add_argument("--out", required=True, help="output image (.png)")
    p.add_argument("--tileable", action="store_true", help="make the output tile (opposite edges continue)")
    p.add_argument("--levels", type=int, default=3, help="coarse-to-fine levels (default 3)")
    p.add_argument("--iterations", type=int, default=3, help="optimisation rounds per level (default 3)")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--alpha", action="store_true", help="synthesize the exemplar's alpha too")
    p.add_argument("--memory-budget", type=float, default=0.0,
                   help="refuse jobs needing more than this many GiB (default: the engine's 8 GiB)")
    p.set_defaults(run=_run_image)

    p = sub.add_parser(
        "field", help="mesh -> direction field (.npy, one unit tangent per vertex)",
        description="A direction field on a mesh, as the Direction Field operator makes it: from a "
        "preset, or by diffusing painted vectors (zero = free) over the surface. Written as a "
        "(V, 3) float32 .npy in the file's vertex order and coordinates (no axis conversion).",
    )
    p.add_argument("--mesh", required=True, help="input mesh: .obj or .ply")
    how = p.add_mutually_exclusive_group(required=True)
    how.add_argument("--preset", choices=("around_axis", "along_axis", "along_curve"),
                     help="a field from a rule (along_curve needs --curve)")
    how.add_argument("--paint", help="(V, 3) .npy of painted vectors in the file's vertex order; zero = free")
    p.add_argument("--axis", choices=("x", "y", "z"), default="z", help="the presets' axis (default z)")
    p.add_argument("--curve", help="along_curve: (N, 3) .npy polyline in the mesh's coordinates, N >= 2")
    p.add_argument("--out", required=True, help="the field: (V, 3) float32 .npy")
    p.set_defaults(run=_run_field)

    p = sub.add_parser(
        "analogy", help="mesh B + pair A -> A' -> B' (geometric texture by example: .obj, .vdb or .npy)",
        description="Geometric texture by analogy (Bhat et al. 2004): B' is to B as A' is to A, the "
        "pattern following a direction field on B. A -> A' is a built-in pair (--preset) or two meshes "
        "(--a, --a-prime: the same place and units as B, voxelized at B's voxel size). The field is a "
        "preset (--field-preset, --axis, --curve), for B and for a mesh pair's A. Coordinates stay "
        "those of the files (no axis conversion: OBJ files are often Y-up, use --axis 0 1 0).",
    )
    p.add_argument("--b", required=True, help="the mesh B to texture: .obj, .ply or .stl")
    pair = p.add_mutually_exclusive_group(required=True)
    pair.add_argument("--preset", choices=analogy_ops.PRESETS, help="a built-in pair")
    pair.add_argument("--a", help="the exemplar A (before the change): .obj, .ply or .stl; needs --a-prime")
    p.add_argument("--a-prime", help="the exemplar A' (A with the change modelled on it); goes with --a")
    p.add_argument("--a-region", help="with --a: learn only near these faces of A (a mesh file holding the "
                   "faces whose change A' shows, e.g. exported selected faces; need not be closed)")
    p.add_argument("--field-preset", choices=analogy_ops.FIELD_PRESETS, default="around_axis",
                   help="the direction field the pattern follows (default around_axis)")
    p.add_argument("--field", help="B's own field: .npy, one direction per vertex of --b (V by 3, e.g. from "
                   "'run field', painted and diffused); wins over --field-preset for B (A keeps the preset)")
    p.add_argument("--axis", type=float, nargs=3, metavar=("X", "Y", "Z"), default=(0.0, 0.0, 1.0),
                   help="around_axis / along_axis: the axis in the files' coordinates (default 0 0 1)")
    p.add_argument("--curve", help="along_curve: the curve as a polyline, .obj (vertices joined by "
                   "'l' lines) or .npy (N by 3), in the files' coordinates")
    p.add_argument("--resolution", type=int, default=128,
                   help="voxels along B's longest bounding-box side (default 128)")
    p.add_argument("--pattern-size", type=float, default=0.5,
                   help="built-in pairs: the pair's cube as a fraction of B's longest side (default 0.5); "
                   "the pair is made at resolution x pattern size voxels (8..512)")
    p.add_argument("--out", required=True,
                   help=".obj (B''s isosurface), .vdb (grids sdf and density) or .npy ((Z, Y, X) float32 "
                   "signed distance of B', positive outside)")
    p.add_argument("--dilation", type=float, default=0.15, help="dilate: A' radius minus A's (default 0.15)")
    p.add_argument("--spike-height", type=float, default=0.3, help="spikes: cone height (default 0.3)")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--memory-budget", type=float, default=0.0,
                   help="refuse jobs needing more than this many GiB (default: the engine's 8 GiB)")
    p.set_defaults(run=_run_analogy)

    p = sub.add_parser("demo", help="voxelize the bundled bunny, solid-texture the cow, give the bunny "
                       "spikes and grooves; render PNGs",
                       description="Voxelize assets/meshes/bunny.obj, solid-texture assets/meshes/cow.obj "
                       "cut open, give the bunny spikes and grooves (Geometric Texture), and render them "
                       "with Cycles.")
    p.add_argument("--assets", required=True, help="the repository's assets/ folder")
    p.add_argument("--out", required=True, help="folder for the PNGs")
    p.add_argument("--resolution", type=int, default=96, help="voxels along the longest side (default 96)")
    p.add_argument("--samples", type=int, default=16, help="Cycles samples per pixel (default 16)")
    p.add_argument("--solid-size", type=int, default=64, help="voxels along the solid's edge (default 64)")
    p.set_defaults(run=_run_demo)
    _add_surface_parser(sub)
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


# ---- analogy -----------------------------------------------------------------
def _run_analogy(args):
    b_path = _input_file("--b", args.b, MESH_FORMATS)
    out_ext = _extension("--out", args.out, (".obj",) + VOXEL_FORMATS)
    _require(args.resolution > 0, f"--resolution must be > 0 (got {args.resolution})")
    _require(args.memory_budget >= 0, f"--memory-budget must be >= 0 GiB (got {args.memory_budget})")
    _require(bool(args.a) == bool(args.a_prime),
             "--a and --a-prime go together: give both meshes of the pair (or --preset instead)")
    _require(not args.a_region or args.a, "--a-region goes with --a and --a-prime")
    _require(args.field_preset != "along_curve" or args.curve,
             "--field-preset along_curve needs --curve CURVE.obj (or .npy)")
    _require(not args.curve or args.field_preset == "along_curve", "--curve goes with --field-preset along_curve")
    _require(any(args.axis), "--axis must not be 0 0 0: give the axis direction, e.g. --axis 0 0 1")
    _require(all(np.isfinite(args.axis)), f"--axis must be finite numbers (got {' '.join(map(str, args.axis))})")
    if args.preset:
        _require(args.pattern_size > 0, f"--pattern-size must be > 0 (got {args.pattern_size})")
        try:
            analogy_ops.check_settings(args.preset, args.resolution, args.pattern_size)
        except jobs.InputError as exc:
            raise UsageError(str(exc).replace("Pattern Size", "--pattern-size").replace("Resolution", "--resolution"))
    else:
        a_path = _input_file("--a", args.a, MESH_FORMATS)
        a_prime_path = _input_file("--a-prime", args.a_prime, MESH_FORMATS)
        _require(not os.path.samefile(a_path, a_prime_path),
                 "--a and --a-prime are the same file, so there is no change to copy; give as "
                 "--a-prime a copy of A with the change modelled on it")
    curve = _read_curve(args.curve) if args.curve else None
    field = analogy_ops.FieldSpec(preset=args.field_preset, axis=tuple(args.axis), curve=curve)

    b = _analogy_mesh("--b", b_path, field)
    if args.field:
        b.field = _vertex_field(args.field, b.vertices)
    job = analogy_ops.GeometricTextureJob(
        b=b, preset=args.preset or "spikes", resolution=args.resolution, pattern_scale=args.pattern_size,
        pair_options={"dilate": {"dilation": args.dilation},
                      "spikes": {"feature_height": args.spike_height}}.get(args.preset, {}),
        memory_budget=int(args.memory_budget * GIB), seed=args.seed,
    )
    if not args.preset:
        job.a = _analogy_mesh("--a", a_path, field)
        job.a_prime = _analogy_mesh("--a-prime", a_prime_path, None)
        if args.a_region:
            region_path = _input_file("--a-region", args.a_region, MESH_FORMATS)
            verts, tris = mesh_io.world_triangles(import_mesh(region_path), bpy.context.evaluated_depsgraph_get())
            _require(len(tris) > 0, f"--a-region: {region_path} has no faces; give the faces of A to learn from")
            job.a.region = (verts, tris)
        try:
            analogy_ops.check_user_pair_grid(b.vertices, job.a.vertices, job.a_prime.vertices, args.resolution)
        except jobs.InputError as exc:
            raise UsageError(f"--a/--a-prime: {str(exc).replace('Resolution', '--resolution')}")
    runner = jobs.Runner(job)
    runner.run_here()
    result = runner.outcome()

    _make_parent(args.out)
    if out_ext == ".obj":
        export_obj(args.out, analogy_ops.result_name(result), *result.surface)
    elif out_ext == ".vdb":
        _native.write_vdb(args.out, result.grids(), result.origin, result.voxel_size)
    else:
        np.save(args.out, np.ascontiguousarray(result.b_prime, np.float32))
    nx, ny, nz = result.dims_xyz
    px, py, pz = result.pair_dims
    stats = result.stats
    print(f"analogy: {result.pair} on {os.path.basename(b_path)}, {nx}x{ny}x{nz} voxels of "
          f"{result.voxel_size:.6g}, pair {px}x{py}x{pz}, field {result.field}; searched {stats['searched']}, "
          f"coherent {stats['coherent']}, culled {stats['culled']}, debris {stats['debris']}; "
          f"{len(result.surface[1])} triangles in {runner.seconds:.2f} s -> {args.out}")
    return 0


def _analogy_mesh(arg, path, field):
    """One mesh file as an analogy input (all its objects together, file coordinates)."""
    objects = import_mesh(path)
    verts, tris = mesh_io.world_triangles(objects, bpy.context.evaluated_depsgraph_get())
    if len(tris) == 0:
        raise UsageError(f"{arg}: {path} has no faces (the analogy works on solids: give a closed mesh)")
    name = os.path.splitext(os.path.basename(path))[0]
    return analogy_ops.MeshInput(name=name, vertices=verts, triangles=tris, field=field)


def _vertex_field(path, vertices):
    """A FieldSpec from a per-vertex direction file, or a UsageError."""
    vectors = _load_npy("--field", path).astype(np.float64)
    _require(vectors.shape == vertices.shape,
             f"--field: {path} is {vectors.shape}; --b has {len(vertices)} vertices: give ({len(vertices)}, 3), "
             "one direction per vertex (e.g. './exsynth run field --mesh' on the same file)")
    _require(bool(np.isfinite(vectors).all()), f"--field: {path} has NaN or infinite values; fix or regenerate it")
    length = np.linalg.norm(vectors, axis=1)
    given = length > 1e-8 * max(1.0, float(length.max(initial=0.0)))
    _require(bool(given.any()), f"--field: {path} is zero everywhere, so it gives the pattern no direction")
    # Zero vectors are free: the frames fill them in from the nearest given ones.
    return analogy_ops.FieldSpec(points=np.ascontiguousarray(vertices[given]),
                                 vectors=np.ascontiguousarray(vectors[given] / length[given, None]),
                                 source=os.path.basename(path))


def _read_curve(path):
    """A polyline from .npy (N by 3) or .obj (vertices joined by edges, in edge order)."""
    path = _input_file("--curve", path, (".obj", ".npy"))
    if path.endswith(".npy"):
        points = _load_npy("--curve", path)
    else:
        objects = import_mesh(path)
        _require(len(objects) == 1, f"--curve: {path} holds {len(objects)} objects; give one polyline")
        points = _polyline(objects[0].data)
        bpy.data.batch_remove([objects[0], objects[0].data])
        _require(points is not None, f"--curve: {path} is not one unbranched polyline (vertices joined by "
                 "'l' lines, each vertex in at most two)")
    _require(points.ndim == 2 and points.shape[1] == 3 and len(points) >= 2,
             f"--curve: {path} must hold N >= 2 points of 3 coordinates (got shape {points.shape})")
    _require(np.isfinite(points).all(), f"--curve: {path} has non-finite coordinates")
    return np.ascontiguousarray(points, np.float64)


def _polyline(mesh):
    """The mesh's vertices in edge order (closed loops repeat the first), or
    None if the edges are not one chain."""
    n = len(mesh.vertices)
    co = np.empty(3 * n, np.float32)
    mesh.vertices.foreach_get("co", co)
    co = co.reshape(-1, 3)
    edges = np.empty(2 * len(mesh.edges), np.int32)
    mesh.edges.foreach_get("vertices", edges)
    edges = edges.reshape(-1, 2)
    if len(edges) == 0:
        return co if n >= 2 else None  # bare vertices: take them in file order
    neighbours = [[] for _ in range(n)]
    for i, j in edges:
        neighbours[i].append(int(j))
        neighbours[j].append(int(i))
    used = [i for i in range(n) if neighbours[i]]
    if any(len(nb) > 2 for nb in neighbours):
        return None
    ends = [i for i in used if len(neighbours[i]) == 1]
    start = ends[0] if ends else used[0]
    order, prev = [start], None
    while True:
        nxt = [j for j in neighbours[order[-1]] if j != prev]
        if not nxt or (not ends and nxt[0] == start):
            break
        prev = order[-1]
        order.append(nxt[0])
        if len(order) > n:
            return None
    if len(order) != len(used):
        return None  # several pieces
    if not ends:
        order.append(start)
    return co[order].astype(np.float64)


# ---- solid and image ----------------------------------------------------------------
def _run_solid(args):
    out_ext = _extension("--out", args.out, VOXEL_FORMATS)
    paths = [_input_file("--exemplar", args.exemplar, None)]
    for arg, path in (("--exemplar-y", args.exemplar_y), ("--exemplar-z", args.exemplar_z)):
        paths.append(_input_file(arg, path, None) if path else None)
    _require(args.size > 0, f"--size must be > 0 (got {args.size})")
    _require(args.levels > 0, f"--levels must be > 0 (got {args.levels})")
    _require(args.iterations > 0, f"--iterations must be > 0 (got {args.iterations})")
    _require(args.scale >= 0, f"--scale must be >= 0 (got {args.scale}); 0 picks it from the mesh")
    _require(args.memory_budget >= 0, f"--memory-budget must be >= 0 GiB (got {args.memory_budget})")
    _require(bool(args.mesh) == bool(args.bake_out), "--mesh and --bake-out go together")
    _require(not args.mesh_out or args.mesh, "--mesh-out needs --mesh")
    if args.mesh:
        mesh_path = _input_file("--mesh", args.mesh, MESH_FORMATS)
        _extension("--bake-out", args.bake_out, (".png",))
        _require(args.bake_size > 0, f"--bake-size must be > 0 (got {args.bake_size})")
    if args.mesh_out:
        _extension("--mesh-out", args.mesh_out, (".obj",))

    images = [image_io.load(p) if p else None for p in paths]
    exemplar, exemplar_y, exemplar_z, encoding = solid_ops.read_exemplars(*images, use_alpha=args.alpha)
    scale, anchor, targets, obj = args.scale or 1.0, np.zeros(3), [], None
    if args.mesh:
        obj = _single_mesh(import_mesh(mesh_path), mesh_path)
        anchor, upper = bake_io.world_bounds([obj])
        scale = args.scale or float(np.max(upper - anchor)) or 1.0
        targets = bake_io.collect(bpy.context, [obj], bake_io.IMAGE, solid_ops.translation(-anchor))
    job = solid_ops.SolidJob(
        name=solid_ops.exemplar_name(images[0]), exemplar=exemplar, exemplar_y=exemplar_y,
        exemplar_z=exemplar_z, size=args.size, levels=args.levels, iterations=args.iterations,
        scale=scale, seed=args.seed, memory_budget=int(args.memory_budget * GIB), encoding=encoding,
        anchor=anchor, targets=targets, bake=solid_ops.BakeOptions(args.bake_size),
    )
    runner = jobs.Runner(job)
    runner.run_here()
    result = runner.outcome()
    solid = result.solid

    _make_parent(args.out)
    if out_ext == ".vdb":
        _native.write_vdb(args.out, solid_ops.solid_grids(solid.values), solid.origin, solid.voxel_size)
    else:
        np.save(args.out, np.ascontiguousarray(solid.values, np.float32))
    n, c = solid.size, solid.values.shape[3]
    energy = f", final energy {solid.energy[-1]:.4g}" if solid.energy else ""
    line = (f"solid: {n}x{n}x{n} voxels x {c} channels of {solid.voxel_size:.6g} from "
            f"{os.path.basename(paths[0])} in {runner.seconds:.2f} s{energy} -> {args.out}")
    if args.mesh:
        baked = result.baked[0]
        _make_parent(args.bake_out)
        image_io.save_png(args.bake_out, baked.pixels, encoding)
        line += f", {args.bake_size}² texture ({100 * baked.covered:.0f} % covered) -> {args.bake_out}"
        if args.mesh_out:
            bake_io.apply_uvs(obj, baked.target, jobs.Created())
            _make_parent(args.mesh_out)
            export_selected_obj(args.mesh_out, obj, uvs=True)
            line += f", mesh -> {args.mesh_out}"
    print(line)
    return 0


def _run_image(args):
    exemplar_path = _input_file("--exemplar", args.exemplar, None)
    _extension("--out", args.out, (".png",))
    _require(args.width > 0 and args.height > 0,
             f"--width and --height must be > 0 (got {args.width}x{args.height})")
    _require(args.levels > 0, f"--levels must be > 0 (got {args.levels})")
    _require(args.iterations > 0, f"--iterations must be > 0 (got {args.iterations})")
    _require(args.memory_budget >= 0, f"--memory-budget must be >= 0 GiB (got {args.memory_budget})")

    image = image_io.load(exemplar_path)
    exemplar, _, _, encoding = solid_ops.read_exemplars(image, use_alpha=args.alpha)
    job = solid_ops.ImageJob(
        exemplar=exemplar, width=args.width, height=args.height, tileable=args.tileable,
        levels=args.levels, iterations=args.iterations, seed=args.seed,
        memory_budget=int(args.memory_budget * GIB),
    )
    runner = jobs.Runner(job)
    runner.run_here()
    pixels = runner.outcome()
    _make_parent(args.out)
    image_io.save_png(args.out, pixels[::-1], encoding)  # the engine's row 0 is the top
    tile = ", tileable" if args.tileable else ""
    print(f"image: {args.width}x{args.height}{tile} from {os.path.basename(exemplar_path)} "
          f"in {runner.seconds:.2f} s -> {args.out}")
    return 0


def _single_mesh(objects, path):
    """The imported objects as one mesh object (joined when the file has several)."""
    if not objects:
        raise UsageError(f"--mesh: {path} holds no mesh")
    if len(objects) > 1:
        with bpy.context.temp_override(active_object=objects[0], object=objects[0],
                                       selected_objects=objects, selected_editable_objects=objects):
            bpy.ops.object.join()
    obj = objects[0]
    if len(obj.data.polygons) == 0:
        raise UsageError(f"--mesh: {path} has no faces to bake onto")
    select_only(bpy.context.view_layer, [obj])
    return obj


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
    export_selected_obj(path, obj)


def export_selected_obj(path, obj, uvs=False):
    select_only(bpy.context.view_layer, [obj])
    bpy.ops.wm.obj_export(filepath=path, export_selected_objects=True, forward_axis='Y',
                          up_axis='Z', export_materials=False, export_uv=uvs)


def _enable_bundled_addon(name):
    import addon_utils

    loaded_default, loaded_state = addon_utils.check(name)
    if not loaded_state and addon_utils.enable(name, default_set=False) is None:
        raise RuntimeError(f"Blender's bundled add-on {name} could not be enabled")


# ---- field ---------------------------------------------------------------------
def _run_field(args):
    mesh_path = _input_file("--mesh", args.mesh, (".obj", ".ply"))
    _extension("--out", args.out, (".npy",))
    _require(args.preset != "along_curve" or args.curve, "--preset along_curve needs --curve CURVE.npy")
    _require(not args.curve or args.preset == "along_curve", "--curve goes with --preset along_curve")
    paint = _load_npy("--paint", args.paint) if args.paint else None
    curve = _load_npy("--curve", args.curve) if args.curve else None

    objects = import_mesh(mesh_path)
    _require(len(objects) == 1, f"--mesh: {mesh_path} holds {len(objects)} meshes; the field needs exactly one")
    verts, tris = mesh_io.mesh_arrays(objects[0].data)
    if len(tris) == 0:
        raise UsageError(f"--mesh: {mesh_path} has no faces to put a field on")
    if paint is not None:
        _require(paint.shape == verts.shape,
                 f"--paint: {args.paint} is {paint.shape}, the mesh needs ({len(verts)}, 3): one vector per vertex")
    job = field_ops.FieldJob(
        vertices=verts, triangles=tris, preset=args.preset or "around_axis",
        axis=field_ops.AXES[args.axis.upper()], curve=curve, given=paint,
    )
    runner = jobs.Runner(job)
    runner.run_here()
    field = runner.outcome()
    _make_parent(args.out)
    np.save(args.out, np.ascontiguousarray(field, np.float32))
    how = f"diffused from {os.path.basename(args.paint)}" if paint is not None else args.preset
    print(f"field: {len(field)} vertices, {how}, in {runner.seconds:.2f} s -> {args.out}")
    return 0


def _load_npy(arg, path):
    path = _input_file(arg, path, (".npy",))
    try:
        return np.load(path, allow_pickle=False)
    except ValueError as exc:
        raise UsageError(f"{arg}: {path} is not a numeric .npy array ({exc})")


# ---- demo --------------------------------------------------------------------
def _run_demo(args):
    from . import demo

    bunny = _input_file("--assets", os.path.join(args.assets, "meshes", "bunny.obj"), (".obj",))
    cow = _input_file("--assets", os.path.join(args.assets, "meshes", "cow.obj"), (".obj",))
    stone = _input_file("--assets", os.path.join(args.assets, "textures", "crackedground.png"), None)
    _require(args.resolution > 0, f"--resolution must be > 0 (got {args.resolution})")
    _require(args.samples > 0, f"--samples must be > 0 (got {args.samples})")
    _require(args.solid_size > 0, f"--solid-size must be > 0 (got {args.solid_size})")
    os.makedirs(args.out, exist_ok=True)
    return (demo.run(bunny, args.out, resolution=args.resolution, samples=args.samples)
            or demo.run_solid(cow, stone, args.out, size=args.solid_size, samples=args.samples)
            or demo.run_analogy(bunny, args.out, samples=args.samples))


# ---- argument checks ----------------------------------------------------------
def _require(ok, message):
    if not ok:
        raise UsageError(message)


def _extension(arg, path, allowed):
    ext = os.path.splitext(path)[1].lower()
    _require(ext in allowed, f"{arg}: unsupported file type '{ext or path}' (use {', '.join(allowed)})")
    return ext


def _input_file(arg, path, allowed):
    """An existing file; `allowed` extensions (None: any, e.g. images Blender reads)."""
    path = os.path.abspath(path)
    _require(os.path.isfile(path), f"{arg}: no such file: {path}")
    if allowed is not None:
        _extension(arg, path, allowed)
    return path


def _make_parent(path):
    parent = os.path.dirname(os.path.abspath(path))
    os.makedirs(parent, exist_ok=True)


# ---- surface (texture synthesis on subdivision surfaces) ---------------------------
def _add_surface_parser(sub):
    from .operators import surface as surface_ops

    p = sub.add_parser(
        "surface", help="control mesh + exemplar image -> subdivided limit mesh with UVs + atlas PNG",
        description="Texture synthesis directly on the Catmull-Clark surface of a control mesh (Ying et "
        "al. 2001): one map per ptex face, packed into one atlas with gutters. OUT.obj is the limit "
        "mesh (Blender's Subdivision modifier, boundary smooth All, limit surface) with UVs into "
        "ATLAS.png, which its .mtl names. Coordinates stay those of the files.",
    )
    p.add_argument("--mesh", required=True, help="the control mesh: .obj, .ply or .stl")
    p.add_argument("--exemplar", required=True, help="the exemplar image (any format Blender reads)")
    p.add_argument("--height", help="a height image of the exemplar's size, synthesized with it: the "
                   "mesh is displaced along its normal (and --height-out written)")
    p.add_argument("--alpha", action="store_true", help="synthesize the exemplar's alpha too")
    p.add_argument("--method", choices=surface_ops.METHODS, default="coherent", help="default coherent")
    size = p.add_mutually_exclusive_group()
    size.add_argument("--texels-per-unit", type=float, help="texels per unit of surface length")
    size.add_argument("--face-resolution", type=int, help="texels along every face map (default 16)")
    p.add_argument("--exemplar-scale", type=float, default=1.0,
                   help="exemplar pixels per texel; larger makes the pattern smaller (default 1)")
    field = p.add_mutually_exclusive_group()
    field.add_argument("--field-preset", choices=tuple(surface_ops.FIELD_MODES.values()), default="smooth",
                       help="which way the pattern runs (default smooth: a smooth field from --axis)")
    field.add_argument("--field", help="(V, 3) .npy, a direction per vertex of --mesh (e.g. 'run field')")
    p.add_argument("--axis", type=float, nargs=3, metavar=("X", "Y", "Z"), default=(0.0, 0.0, 1.0),
                   help="the presets' axis in the file's coordinates (default 0 0 1)")
    p.add_argument("--segments", type=int, default=2,
                   help="limit-mesh quads along each n-gon sub-face, twice that per quad (default 2)")
    p.add_argument("--height-scale", type=float, default=0.02,
                   help="displacement per unit of height around 0.5 (default 0.02)")
    p.add_argument("--out", required=True, help="the textured limit mesh: .obj (+ .mtl)")
    p.add_argument("--texture-out", required=True, help="the atlas: .png")
    p.add_argument("--height-out", help="with --height: the height atlas, .png")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--memory-budget", type=float, default=0.0,
                   help="refuse jobs needing more than this many GiB (default: the engine's 8 GiB)")
    p.set_defaults(run=_run_surface)


def _run_surface(args):
    from .operators import surface as surface_ops

    mesh_path = _input_file("--mesh", args.mesh, MESH_FORMATS)
    exemplar_path = _input_file("--exemplar", args.exemplar, None)
    height_path = _input_file("--height", args.height, None) if args.height else None
    _extension("--out", args.out, (".obj",))
    _extension("--texture-out", args.texture_out, (".png",))
    _require(not args.height_out or args.height, "--height-out needs --height")
    if args.height_out:
        _extension("--height-out", args.height_out, (".png",))
    _require(args.texels_per_unit is None or args.texels_per_unit > 0,
             f"--texels-per-unit must be > 0 (got {args.texels_per_unit})")
    _require(args.face_resolution is None or args.face_resolution > 0,
             f"--face-resolution must be > 0 (got {args.face_resolution})")
    _require(args.exemplar_scale > 0, f"--exemplar-scale must be > 0 (got {args.exemplar_scale})")
    _require(1 <= args.segments <= 32, f"--segments must be in 1..32 (got {args.segments})")
    _require(any(args.axis) and all(np.isfinite(args.axis)), "--axis must be a finite, non-zero direction")
    _require(args.memory_budget >= 0, f"--memory-budget must be >= 0 GiB (got {args.memory_budget})")

    objects = import_mesh(mesh_path)
    _require(bool(objects), f"--mesh: {mesh_path} holds no mesh")
    obj = _single_mesh(objects, mesh_path) if len(objects) > 1 else objects[0]
    try:
        mesh = surface_ops.control_mesh(obj)
    except jobs.InputError as exc:
        raise UsageError(f"--mesh: {exc}")
    field = None
    if args.field:
        field = _load_npy("--field", args.field).astype(np.float64)
        _require(field.shape == mesh.vertices.shape,
                 f"--field: {args.field} is {field.shape}; --mesh has {len(mesh.vertices)} vertices: give "
                 f"({len(mesh.vertices)}, 3)")
    colour = image_io.load(exemplar_path)
    height = image_io.load(height_path) if height_path else None
    try:
        exemplar, channels, encoding = surface_ops.read_exemplar(colour, height, args.alpha)
    except jobs.InputError as exc:
        raise UsageError(str(exc))
    job = surface_ops.SurfaceJob(
        mesh=mesh, exemplar=exemplar, colour_channels=channels, has_height=height is not None,
        encoding=encoding, method=args.method, texels_per_unit=args.texels_per_unit or 0.0,
        face_resolution=args.face_resolution or 16, exemplar_scale=args.exemplar_scale,
        field_mode=args.field_preset, axis=tuple(args.axis), field=field, height_scale=args.height_scale,
        segments=args.segments, memory_budget=int(args.memory_budget * GIB), seed=args.seed,
    )
    runner = jobs.Runner(job)
    runner.run_here()
    result = runner.outcome()

    created = jobs.Created()
    try:
        out = surface_ops.add_result_object(bpy.context, result, created)
        atlas = result.atlas[::-1]
        _make_parent(args.texture_out)
        image_io.save_png(args.texture_out, atlas[..., :channels], encoding)
        if args.height_out:
            _make_parent(args.height_out)
            image_io.save_png(args.height_out, atlas[..., channels:channels + 1], image_io.DATA)
        # The material names the PNG, so the .mtl written with the OBJ does too.
        for node in out.active_material.node_tree.nodes:
            if node.type == 'TEX_IMAGE' and node.image is not None and node.image.name.endswith("_atlas"):
                node.image = created.add(image_io.load(args.texture_out))
        _make_parent(args.out)
        select_only(bpy.context.view_layer, [out])
        bpy.ops.wm.obj_export(filepath=os.path.abspath(args.out), export_selected_objects=True,
                              forward_axis='Y', up_axis='Z', export_materials=True, export_uv=True,
                              export_normals=True, path_mode='RELATIVE')
    except BaseException:
        created.rollback()
        raise
    h, w = result.atlas.shape[:2]
    print(f"surface: {result.method} on {os.path.basename(mesh_path)}, {result.texels} texels on "
          f"{result.faces} faces, field {result.field}, atlas {w}x{h}, {len(result.quads)} quads in "
          f"{runner.seconds:.2f} s -> {args.out}, {args.texture_out}")
    return 0
