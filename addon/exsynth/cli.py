# SPDX-License-Identifier: GPL-3.0-or-later
"""Headless jobs, run inside `blender -b` by `./exsynth run JOB ARGS...`.

Each job takes the same path as its operator: Blender imports the input,
io/ turns it into arrays, the operator's Job runs through jobs.Runner.
Exit codes: 0 done, 1 the job failed (engine or file error), 2 bad arguments.
"""

import argparse
import math
import os
import signal
import sys
import threading

import bpy
import numpy as np

from . import _native, jobs
from .io import bake as bake_io
from .io import image as image_io
from .io import mesh as mesh_io
from .io import mesh_files
from .io import outputs
from .io.selection import select_only
from .operators import analogy as analogy_ops
from .operators import field as field_ops
from .operators import solid as solid_ops
from .operators.voxelize import VoxelizeJob
from .properties import GIB

MESH_FORMATS = (".obj", ".ply", ".stl")
POINTS_DENSITY = _native.POINTS_DEFAULT_DENSITY  # --density's default, as the panel's
VOXEL_FORMATS = (".vdb", ".npy")


class UsageError(Exception):
    """A bad argument; the message names it."""


EXIT_INTERRUPTED = 130  # the shell's code for a run ended by Ctrl-C (128 + SIGINT)


def main(argv=None) -> int:
    """Runs one job; returns the exit code. Each job function returns the
    line to print on success (the demo: an exit code). Its output files are
    declared in args.outputs and appear only when the whole job succeeded."""
    parser = _parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # argparse exits on --help (0) and on its own errors (2)
        return exc.code if isinstance(exc.code, int) else 2
    if args.job is None:
        parser.print_help(sys.stderr)
        return 2
    with _ctrl_c_cancels_jobs():
        try:
            with outputs.OutputFiles() as args.outputs:
                done = args.run(args)
        except (UsageError, outputs.OutputPathError, mesh_files.MeshFileError) as exc:
            print(f"exsynth {args.job}: error: {exc}", file=sys.stderr)
            return 2
        except _native.InvalidInputError as exc:  # the engine's own checks: a bad argument too
            print(f"exsynth {args.job}: error: {_with_flags(parser, args.job, str(exc))}; nothing was written",
                  file=sys.stderr)
            return 2
        except (KeyboardInterrupt, _native.CancelledError):
            print(f"exsynth {args.job}: interrupted (Ctrl-C); nothing was written", file=sys.stderr)
            return EXIT_INTERRUPTED
        except (jobs.REPORTED_ERRORS + (RuntimeError,)) as exc:  # RuntimeError: a bpy.ops failure
            print(f"exsynth {args.job}: failed: {exc}; nothing was written", file=sys.stderr)
            return 1
    if isinstance(done, str):
        print(done)
        return 0
    return done or 0  # the demo: its stages return a failure's exit code, or None


def _with_flags(parser, job, message):
    """The engine's message with its option names as this job's flags:
    'face_resolution' -> --face-resolution (quoted names, and bare ones
    with an underscore: a bare 'scale' may be a plain word)."""
    import re

    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction)).choices[job]
    for action in sub._actions:
        flag = next((o for o in action.option_strings if o.startswith("--")), None)
        if flag is None:
            continue
        name = action.dest
        message = message.replace(f"'{name}'", flag)
        if "_" in name:
            message = re.sub(rf"(?<![\w-]){name}(?!\w)", flag, message)
    return message


# ---- running a job: Ctrl-C and progress ------------------------------------------
class _CtrlC:
    """SIGINT while a job runs cancels it through its ExecContext (the engine
    stops at its next chunk); outside a job it raises KeyboardInterrupt. Blender
    itself only notes the signal ("internal break event") and carries on."""

    runner = None
    hit = False

    @classmethod
    def handle(cls, signum, frame):
        cls.hit = True
        if cls.runner is not None:
            cls.runner.cancel()
        else:
            raise KeyboardInterrupt


class _ctrl_c_cancels_jobs:
    """Installs _CtrlC.handle for SIGINT (signals reach only the main thread)
    and puts the previous handler back (the default one when Blender's own C
    handler was in place, which Python cannot hand back)."""

    def __enter__(self):
        _CtrlC.hit, _CtrlC.runner = False, None
        self._installed = threading.current_thread() is threading.main_thread()
        if self._installed:
            self._previous = signal.signal(signal.SIGINT, _CtrlC.handle)

    def __exit__(self, *exc):
        if self._installed:
            signal.signal(signal.SIGINT, self._previous if self._previous is not None else signal.SIG_DFL)
        return False


def _run_job(job, label):
    """Runs `job` on a worker thread while this (main) thread waits, so that
    the SIGINT handler can run; prints each new stage to stderr. Returns the
    job's result (raises its error, CancelledError after Ctrl-C)."""
    runner = jobs.Runner(job)
    _CtrlC.runner = runner
    try:
        runner.start()
        shown = None
        while runner.running:
            runner.join(0.05)
            stage, pct = runner.status()
            if stage != shown and runner.running:
                print(f"exsynth {label}: {stage} ({pct}%)", file=sys.stderr, flush=True)
                shown = stage
    finally:
        runner.join()
        _CtrlC.runner = None
    if _CtrlC.hit:
        raise KeyboardInterrupt
    return runner.outcome(), runner.seconds


def _parser():
    from . import demo  # for the demo's defaults (its bpy scene code loads only with the CLI)

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
    p.add_argument("--resolution", type=_int, default=128,
                   help="voxels along the longest bounding-box side (default 128)")
    p.add_argument("--voxel-size", type=_finite, default=0.0,
                   help="voxel edge length in mesh units; overrides --resolution when > 0")
    p.add_argument("--padding", type=_int, default=2, help="empty voxels on every side (default 2)")
    p.add_argument("--supersample", type=_int, default=2, help="sub-rays per voxel edge, 1..8 (default 2)")
    p.add_argument("--mesh-out", help="also write the rebuilt surface (zero level of the sdf) as .obj")
    _add_memory_budget(p)
    p.set_defaults(run=_run_voxelize)

    p = sub.add_parser(
        "solid", help="2D exemplar(s) -> solid texture (.vdb or .npy), optionally baked onto a mesh",
        description="Synthesize a tiling solid texture (Kopf et al. 2007) from exemplar images, as the "
        "Solid Texture operator does; with --mesh also bake it onto the mesh's UV map.",
    )
    p.add_argument("--exemplar", required=True, help="exemplar image (any format Blender reads)")
    p.add_argument("--exemplar-y", help="exemplar of the slices across Y (default: --exemplar)")
    p.add_argument("--exemplar-z", help="exemplar of the slices across Z (default: --exemplar)")
    p.add_argument("--size", type=_int, default=_native.SOLID_DEFAULT_SIZE,
                   help="voxels along each edge of the solid (default %(default)s)")
    p.add_argument("--out", required=True,
                   help=".vdb (grid color, + alpha with --alpha) or .npy ((Z, Y, X, C) float32)")
    p.add_argument("--levels", type=_int, default=_native.DEFAULT_LEVELS,
                   help="coarse-to-fine levels (default %(default)s)")
    p.add_argument("--iterations", type=_int, default=_native.DEFAULT_ITERATIONS,
                   help="optimisation rounds per level (default %(default)s)")
    p.add_argument("--method", choices=_native.SOLID_METHODS, default=_native.SOLID_DEFAULT_METHOD,
                   help="optimization (Kopf et al. 2007) or coordinates (exemplar coordinates, Dong et al. 2008: "
                   "crisper slices, square blocks on oblique cuts) (default %(default)s)")
    p.add_argument("--feature-weight", type=_finite, default=_native.SOLID_DEFAULT_FEATURE_WEIGHT,
                   help="with --method optimization: weight of the distance to the exemplar's dark features "
                   "(cracks, mortar) in the matching; higher = crisper, 0 = colours only (default %(default)s)")
    p.add_argument("--feature-threshold", type=_finite, default=_native.SOLID_DEFAULT_FEATURE_THRESHOLD,
                   help="with --method optimization: which exemplar pixels are features, in luminance standard "
                   "deviations below their window's mean; 0 = any darker pixel (softer cells), 1 = only deep cracks and "
                   "mortar (crisper; round cells need --rotate-exemplar auto or on) (default %(default)s)")
    p.add_argument("--feature-scale", type=int, default=_native.SOLID_DEFAULT_FEATURE_SCALE,
                   help="with --method optimization: exemplar pixels from a feature's edge at which its distance "
                   "stops growing; larger keeps round stones whole (crackedground: 16) but can line other textures "
                   "up as sheets; 0 = the neighbourhood's size (default %(default)s)")
    p.add_argument("--rotate-exemplar", choices=_native.ROTATE_EXEMPLAR_CHOICES, nargs="?",
                   const="on", default=_native.SOLID_DEFAULT_ROTATE_EXEMPLAR,
                   help="with --method optimization: also match the exemplar turned by 90, 180 and 270 degrees, "
                   "for textures with no preferred direction (cracks, cells), whose cells otherwise line up along "
                   "one diagonal; auto = when the exemplar's features are round, not for wood or bricks; on (the "
                   "flag alone) = always, about 1.4x the time at --size 128 for exemplars under 256 px (default %(default)s)")
    p.add_argument("--histogram-values", type=_finite, default=_native.SOLID_DEFAULT_HISTOGRAM_VALUES,
                   help="with --method optimization: how strongly each voxel's exemplar colour is picked to match "
                   "the exemplar's histogram (contrast); above 0.5 it oscillates, 0 = off (default %(default)s)")
    p.add_argument("--structure-sigma", type=_finite, default=_native.SOLID_DEFAULT_STRUCTURE_SIGMA,
                   help="with --method optimization: shapes larger than this many voxels (cells, stones) come from "
                   "the optimiser's average, finer grain from the exemplar's colours, then matched to the exemplar's "
                   "histogram; 0 = off (default %(default)s)")
    p.add_argument("--seed", type=_seed, default=0, help="random seed (default 0)")
    p.add_argument("--alpha", action="store_true", help="synthesize the exemplars' alpha as a 4th channel")
    p.add_argument("--scale", type=_finite, default=0.0,
                   help="edge length of one tile in mesh units (default: the mesh's longest side, "
                   "or 1 without --mesh); sets the .vdb's voxel size")
    p.add_argument("--mesh", help="also bake the solid onto this mesh (.obj, .ply, .stl; unwrapped with "
                   "Smart UV Project when it has no UVs)")
    p.add_argument("--bake-out", help="the baked texture (.png), with --mesh")
    p.add_argument("--bake-size", type=_int, help="with --mesh: baked texture width and height "
                   f"(default {_native.BAKE_DEFAULT_SIZE})")
    p.add_argument("--bake-interpolation", choices=_native.INTERPOLATION_CHOICES,
                   help="with --mesh: how texels read the solid between voxels; cubic keeps voxel-sized detail's "
                   f"contrast, linear is softer (default {_native.DEFAULT_INTERPOLATION})")
    p.add_argument("--mesh-out", help="with --mesh: write the mesh with the UV map the bake used (.obj)")
    _add_memory_budget(p)
    p.set_defaults(run=_run_solid)

    p = sub.add_parser(
        "image", help="2D exemplar -> larger (optionally tileable) image",
        description="2D texture synthesis: exemplar coordinates (Lefebvre & Hoppe 2005, the default) or the "
                    "solid engine's optimiser (--method optimization).",
    )
    p.add_argument("--exemplar", required=True, help="exemplar image (any format Blender reads)")
    p.add_argument("--width", type=_int, required=True, help="output width in pixels")
    p.add_argument("--height", type=_int, required=True, help="output height in pixels")
    p.add_argument("--out", required=True, help="output image (.png)")
    p.add_argument("--tileable", action="store_true", help="make the output tile (opposite edges continue)")
    p.add_argument("--method", choices=_native.IMAGE_METHODS, default=_native.IMAGE_DEFAULT_METHOD,
                   help="coordinates (fast, every pixel an exemplar pixel) or optimization (default %(default)s)")
    p.add_argument("--levels", type=_int,
                   help=f"with --method optimization: coarse-to-fine levels (default {_native.DEFAULT_LEVELS}; "
                   "coordinates takes its levels from the exemplar)")
    p.add_argument("--iterations", type=_int,
                   help=f"with --method optimization: rounds per level (default {_native.DEFAULT_ITERATIONS})")
    p.add_argument("--seed", type=_seed, default=0, help="random seed (default 0)")
    p.add_argument("--alpha", action="store_true", help="synthesize the exemplar's alpha too")
    _add_memory_budget(p)
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
    p.add_argument("--axis", type=_finite, nargs=3, metavar=("X", "Y", "Z"), default=(0.0, 0.0, 1.0),
                   help="around_axis / along_axis: the axis in the files' coordinates (default 0 0 1)")
    p.add_argument("--curve", help="along_curve: the curve as a polyline, .obj (vertices joined by "
                   "'l' lines) or .npy (N by 3), in the files' coordinates")
    p.add_argument("--resolution", type=_int, default=128,
                   help="voxels along B's longest bounding-box side (default 128); with a built-in pair and "
                   "the pattern size fitted, the least: raised until the pair has "
                   f"{_native.PAIR_DETAIL_RESOLUTION} voxels across (printed)")
    p.add_argument("--pattern-size", type=_finite, default=None,
                   help="built-in pairs: the pair's cube as a fraction of B's longest side (default: fitted "
                   "to B's thickness, as the add-on's Fit to Model); the pair is made at resolution x "
                   "pattern size voxels (8..512)")
    p.add_argument("--out", required=True,
                   help=".obj (B''s isosurface), .vdb (grids sdf and density) or .npy ((Z, Y, X) float32 "
                   "signed distance of B', positive outside)")
    p.add_argument("--dilation", type=_finite,
                   help=f"with --preset dilate: A' radius minus A's (default {analogy_ops.DEFAULT_GROWTH['dilation']:g})")
    p.add_argument("--spike-height", type=_finite,
                   help=f"with --preset spikes: cone height (default {analogy_ops.DEFAULT_GROWTH['feature_height']:g})")
    _add_memory_budget(p)
    p.set_defaults(run=_run_analogy)

    p = sub.add_parser("demo", help="voxelize the bundled bunny, solid-texture the cow, give the bunny "
                       "spikes and grooves, texture the cow's surface; render PNGs",
                       description="Voxelize assets/meshes/bunny.obj, solid-texture assets/meshes/cow.obj "
                       "cut open, give the bunny spikes and grooves (Geometric Texture), texture the cow's "
                       "subdivision surface (Surface Texture: coherent, multiscale, with height), and "
                       "render them with Cycles.")
    p.add_argument("--assets", required=True, help="the repository's assets/ folder")
    p.add_argument("--out", required=True, help="folder for the PNGs")
    p.add_argument("--resolution", type=_int, default=96, help="voxels along the longest side (default 96)")
    p.add_argument("--samples", type=_int, default=16, help="Cycles samples per pixel (default 16)")
    p.add_argument("--solid-size", type=_int, default=demo.DEMO_SOLID_SIZE,
                   help="voxels along the solid's edge (default %(default)s)")
    p.set_defaults(run=_run_demo)
    _points_parser(sub)
    _add_surface_parser(sub)
    return parser


# ---- voxelize ----------------------------------------------------------------
def _run_voxelize(args):
    mesh_path = _input_file("--mesh", args.mesh, MESH_FORMATS)
    out = args.outputs.add("--out", args.out, VOXEL_FORMATS)
    mesh_out = args.outputs.add("--mesh-out", args.mesh_out, (".obj",)) if args.mesh_out else None
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
        memory_budget=int(args.memory_budget * GIB),
    )
    voxels, seconds = _run_job(job, "voxelize")
    if voxels.warning():
        print(f"exsynth voxelize: warning: {voxels.warning()}", file=sys.stderr)

    if out.endswith(".vdb"):
        _native.write_vdb(out, {"density": voxels.density, "sdf": voxels.sdf}, voxels.origin, voxels.voxel_size)
    else:
        np.save(out, np.stack([voxels.density, voxels.sdf], axis=-1).astype(np.float32))
    nx, ny, nz = voxels.dims_xyz
    line = (f"voxelize: {nx}x{ny}x{nz} voxels of {voxels.voxel_size:.6g} "
            f"from {len(tris)} triangles in {seconds:.2f} s -> {args.out}")
    if mesh_out:
        export_obj(mesh_out, f"{job.name}_voxel_mesh", *voxels.surface)
        line += f", {len(voxels.surface[1])} triangles -> {args.mesh_out}"
    return line


# ---- analogy -----------------------------------------------------------------
def _run_analogy(args):
    b_path = _input_file("--b", args.b, MESH_FORMATS)
    out = args.outputs.add("--out", args.out, (".obj",) + VOXEL_FORMATS)
    out_ext = os.path.splitext(out)[1]
    _require(args.resolution > 0, f"--resolution must be > 0 (got {args.resolution})")
    _require(args.memory_budget >= 0, f"--memory-budget must be >= 0 GiB (got {args.memory_budget})")
    _require(bool(args.a) == bool(args.a_prime),
             "--a and --a-prime go together: give both meshes of the pair (or --preset instead)")
    _require(not args.a_region or args.a, "--a-region goes with --a and --a-prime")
    _require(args.field_preset != "along_curve" or args.curve,
             "--field-preset along_curve needs --curve CURVE.obj (or .npy)")
    _require(not args.curve or args.field_preset == "along_curve", "--curve goes with --field-preset along_curve")
    _require(any(args.axis), "--axis must not be 0 0 0: give the axis direction, e.g. --axis 0 0 1")
    _goes_with("--dilation", args.dilation is not None, args.preset == "dilate", "--preset dilate")
    _goes_with("--spike-height", args.spike_height is not None, args.preset == "spikes", "--preset spikes")
    _goes_with("--pattern-size", args.pattern_size is not None, args.preset, "a built-in pair (--preset)")
    if args.preset:
        _require(args.pattern_size is None or args.pattern_size > 0,
                 f"--pattern-size must be > 0 (got {args.pattern_size})")
        try:
            analogy_ops.check_settings(args.preset, args.resolution, args.pattern_size, _pair_options(args),
                                       names={"feature_height": "--spike-height", "dilation": "--dilation"})
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
    pattern_scale = args.pattern_size
    if args.preset and pattern_scale is None:
        try:
            pattern_scale, measure = analogy_ops.fitted_pattern_scale(b.vertices, b.triangles, args.resolution)
        except jobs.InputError as exc:
            raise UsageError(f"--b: {exc} (--pattern-size)")
        print(f"exsynth analogy: pattern size {pattern_scale:.3g} of B's longest side, fitted to its "
              f"thickness {measure['thickness']:.4g}", file=sys.stderr)
    job = analogy_ops.GeometricTextureJob(
        b=b, preset=args.preset or "spikes", resolution=args.resolution,
        pattern_scale=0.5 if pattern_scale is None else pattern_scale,
        fit_pattern=bool(args.preset) and args.pattern_size is None, pair_options=_pair_options(args),
        memory_budget=int(args.memory_budget * GIB),
    )
    if job.grid_resolution > args.resolution:
        print(f"exsynth analogy: resolution {job.grid_resolution} (--resolution {args.resolution} raised so that the "
              f"pair has {job.pair_resolution} voxels across, which its features need)", file=sys.stderr)
    elif args.preset and job.pair_resolution < _native.PAIR_DETAIL_RESOLUTION:
        print(f"exsynth analogy: the pair has {job.pair_resolution} voxels across; its features come out soft "
              f"under {_native.PAIR_DETAIL_RESOLUTION} (raise --resolution or --pattern-size, or leave "
              "--pattern-size out to have both fitted)", file=sys.stderr)
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
    try:
        result, seconds = _run_job(job, "analogy")
    except _native.OverBudgetError as exc:
        raise _native.OverBudgetError(str(exc).replace("set a larger Pattern Size by hand",
                                                       "give a larger --pattern-size")) from None

    if out_ext == ".obj":
        export_obj(out, analogy_ops.result_name(result), *result.surface)
    elif out_ext == ".vdb":
        _native.write_vdb(out, result.grids(), result.origin, result.voxel_size)
    else:
        np.save(out, np.ascontiguousarray(result.b_prime, np.float32))
    nx, ny, nz = result.dims_xyz
    px, py, pz = result.pair_dims
    stats = result.stats
    return (f"analogy: {result.pair} on {os.path.basename(b_path)}, {nx}x{ny}x{nz} voxels of "
            f"{result.voxel_size:.6g}, pair {px}x{py}x{pz}, field {result.field}; searched {stats['searched']}, "
            f"coherent {stats['coherent']}, culled {stats['culled']}, debris {stats['debris']}; "
            f"{len(result.surface[1])} triangles in {seconds:.2f} s -> {args.out}")


def _pair_options(args):
    """The built-in pair's shape options the CLI sets (as operators.analogy.pair_options)."""
    given = {"dilation": args.dilation, "feature_height": args.spike_height}
    return {k: v for k, v in given.items() if v is not None}


def _analogy_mesh(arg, path, field):
    """One mesh file as an analogy input (all its objects together, file coordinates)."""
    objects = import_mesh(path)
    verts, tris = mesh_io.world_triangles(objects, bpy.context.evaluated_depsgraph_get())
    if len(tris) == 0:
        raise UsageError(f"{arg}: {path} has no faces (the analogy works on solids: give a closed mesh)")
    try:
        _native.validate_mesh(verts, tris, f"{arg} {os.path.basename(path)}")
    except _native.InvalidInputError as exc:
        raise UsageError(str(exc)) from None
    name = os.path.splitext(os.path.basename(path))[0]
    return analogy_ops.MeshInput(name=name, vertices=verts, triangles=tris, field=field)


def _vertex_field(path, vertices):
    """A FieldSpec from a per-vertex direction file, or a UsageError."""
    vectors = _directions("--field", path, vertices, "--b")
    length = np.linalg.norm(vectors, axis=1)
    given = length > 1e-8 * max(1.0, float(length.max(initial=0.0)))
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
    _require(np.isfinite(points).all(), f"--curve: {path} has NaN or infinite coordinates; fix or re-export the curve")
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
    out = args.outputs.add("--out", args.out, VOXEL_FORMATS)
    paths = [_input_file("--exemplar", args.exemplar, None)]
    for arg, path in (("--exemplar-y", args.exemplar_y), ("--exemplar-z", args.exemplar_z)):
        paths.append(_input_file(arg, path, None) if path else None)
    _require(args.size > 0, f"--size must be > 0 (got {args.size})")
    _require(args.levels > 0, f"--levels must be > 0 (got {args.levels})")
    _texture_size("--size", (args.size,), args.levels, _native.SOLID_MAX_SIZE, "voxels")
    _require(args.iterations > 0, f"--iterations must be > 0 (got {args.iterations})")
    _require(args.feature_weight >= 0, f"--feature-weight must be >= 0 (got {args.feature_weight}); 0 = off")
    _require(0 <= args.feature_threshold <= _native.SOLID_MAX_FEATURE_THRESHOLD,
             f"--feature-threshold must be in 0..{_native.SOLID_MAX_FEATURE_THRESHOLD:g} "
             f"(got {args.feature_threshold}); 0 = any darker pixel is a feature")
    _require(0 <= args.feature_scale <= _native.SOLID_MAX_FEATURE_SCALE,
             f"--feature-scale must be in 0..{_native.SOLID_MAX_FEATURE_SCALE} exemplar pixels "
             f"(got {args.feature_scale}); 0 = the neighbourhood's size")
    _require(args.histogram_values >= 0,
             f"--histogram-values must be >= 0 (got {args.histogram_values}); 0 = off")
    _require(0 <= args.structure_sigma <= _native.SOLID_MAX_STRUCTURE_SIGMA,
             f"--structure-sigma must be in 0..{_native.SOLID_MAX_STRUCTURE_SIGMA:g} voxels "
             f"(got {args.structure_sigma}); 0 = off")
    _require(args.scale >= 0, f"--scale must be >= 0 (got {args.scale}); 0 picks it from the mesh")
    _require(args.memory_budget >= 0, f"--memory-budget must be >= 0 GiB (got {args.memory_budget})")
    _require(bool(args.mesh) == bool(args.bake_out), "--mesh and --bake-out go together")
    for flag, value in (("--mesh-out", args.mesh_out), ("--bake-size", args.bake_size),
                        ("--bake-interpolation", args.bake_interpolation)):
        _goes_with(flag, value is not None, args.mesh, "--mesh")
    args.bake_size = _native.BAKE_DEFAULT_SIZE if args.bake_size is None else args.bake_size
    args.bake_interpolation = args.bake_interpolation or _native.DEFAULT_INTERPOLATION
    if args.mesh:
        mesh_path = _input_file("--mesh", args.mesh, MESH_FORMATS)
        bake_out = args.outputs.add("--bake-out", args.bake_out, (".png",))
        _require(args.bake_size > 0, f"--bake-size must be > 0 (got {args.bake_size})")
    mesh_out = args.outputs.add("--mesh-out", args.mesh_out, (".obj",)) if args.mesh_out else None

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
        method=args.method, feature_weight=args.feature_weight, feature_threshold=args.feature_threshold,
        feature_scale=args.feature_scale, rotate_exemplar=args.rotate_exemplar, histogram_values=args.histogram_values,
        structure_sigma=args.structure_sigma, scale=scale, seed=args.seed,
        memory_budget=int(args.memory_budget * GIB), encoding=encoding,
        anchor=anchor, targets=targets, bake=solid_ops.BakeOptions(args.bake_size, args.bake_interpolation),
    )
    result, seconds = _run_job(job, "solid")
    solid = result.solid

    if out.endswith(".vdb"):
        _native.write_vdb(out, solid_ops.solid_grids(solid.values), solid.origin, solid.voxel_size)
    else:
        np.save(out, np.ascontiguousarray(solid.values, np.float32))
    n, c = solid.size, solid.values.shape[3]
    energy = f", final energy {solid.energy[-1]:.4g}" if solid.energy else ""
    line = (f"solid: {n}x{n}x{n} voxels x {c} channels of {solid.voxel_size:.6g} from "
            f"{os.path.basename(paths[0])} in {seconds:.2f} s{energy}{solid.turned_note()} -> {args.out}")
    if args.mesh:
        baked = result.baked[0]
        image_io.save_png(bake_out, baked.pixels, encoding)
        line += f", {args.bake_size}² texture ({100 * baked.covered:.0f} % covered) -> {args.bake_out}"
        if mesh_out:
            bake_io.apply_uvs(obj, baked.target, jobs.Created())
            export_selected_obj(mesh_out, obj, uvs=True)
            line += f", mesh -> {args.mesh_out}"
    return line


def _run_image(args):
    exemplar_path = _input_file("--exemplar", args.exemplar, None)
    out = args.outputs.add("--out", args.out, (".png",))
    _require(args.width > 0 and args.height > 0,
             f"--width and --height must be > 0 (got {args.width}x{args.height})")
    for flag, value in (("--levels", args.levels), ("--iterations", args.iterations)):
        _goes_with(flag, value is not None, args.method == "optimization", "--method optimization")
    args.levels = _native.DEFAULT_LEVELS if args.levels is None else args.levels
    args.iterations = _native.DEFAULT_ITERATIONS if args.iterations is None else args.iterations
    _require(args.levels > 0, f"--levels must be > 0 (got {args.levels})")
    if args.method == "optimization":
        _texture_size("--width and --height", (args.width, args.height), args.levels, _native.IMAGE_MAX_SIZE,
                      "pixels")
    else:
        _require(max(args.width, args.height) <= _native.IMAGE_MAX_SIZE,
                 f"--width and --height must be at most {_native.IMAGE_MAX_SIZE} pixels "
                 f"(got {args.width}x{args.height})")
    _require(args.iterations > 0, f"--iterations must be > 0 (got {args.iterations})")
    _require(args.memory_budget >= 0, f"--memory-budget must be >= 0 GiB (got {args.memory_budget})")

    image = image_io.load(exemplar_path)
    exemplar, _, _, encoding = solid_ops.read_exemplars(image, use_alpha=args.alpha)
    job = solid_ops.ImageJob(
        exemplar=exemplar, width=args.width, height=args.height, tileable=args.tileable,
        levels=args.levels, iterations=args.iterations, seed=args.seed,
        memory_budget=int(args.memory_budget * GIB), method=args.method,
    )
    pixels, seconds = _run_job(job, "image")
    image_io.save_png(out, pixels[::-1], encoding)  # the engine's row 0 is the top
    tile = ", tileable" if args.tileable else ""
    return (f"image ({args.method}): {args.width}x{args.height}{tile} from {os.path.basename(exemplar_path)} "
            f"in {seconds:.2f} s -> {args.out}")


def _texture_size(option, sizes, levels, largest, unit):
    """The engine's one size rule (the coarsest level holds a neighbourhood),
    refused here as a bad argument that names the option."""
    if levels > 8:
        return  # the engine names --levels' own range
    smallest = _native.min_texture_size(levels)
    _require(all(smallest <= n <= largest for n in sizes),
             f"{option} must be {smallest}..{largest} {unit} with --levels {levels} (got "
             f"{'x'.join(map(str, sizes))}); give a larger size or fewer --levels (1 level allows from "
             f"{_native.min_texture_size(1)})")


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
    """Write (vertices, triangles) as OBJ in the same (unconverted) axes the
    input was read in (see mesh_files.write_obj for why not Blender's exporter)."""
    mesh_files.write_obj(path, name, vertices, triangles)


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
    out = args.outputs.add("--out", args.out, (".npy",))
    _require(args.preset != "along_curve" or args.curve, "--preset along_curve needs --curve CURVE.npy")
    _require(not args.curve or args.preset == "along_curve", "--curve goes with --preset along_curve")
    paint = _load_npy("--paint", args.paint) if args.paint else None
    curve = _load_npy("--curve", args.curve) if args.curve else None

    if mesh_path.lower().endswith(".obj"):  # read here: Blender's importer drops loose vertices
        verts, tris = mesh_files.read_obj("--mesh", mesh_path)
    else:
        objects = import_mesh(mesh_path)
        _require(len(objects) == 1, f"--mesh: {mesh_path} holds {len(objects)} meshes; the field needs exactly one")
        verts, tris = mesh_io.mesh_arrays(objects[0].data)
    if len(tris) == 0:
        raise UsageError(f"--mesh: {mesh_path} has no faces to put a field on")
    if paint is not None:
        _require(paint.shape == verts.shape,
                 f"--paint: {args.paint} is {paint.shape}, the mesh needs ({len(verts)}, 3): one vector per vertex")
        bad = np.flatnonzero(~np.isfinite(paint).all(axis=1))
        _require(len(bad) == 0, f"--paint: row {bad[0] if len(bad) else 0} of {args.paint} is not finite (NaN or "
                 "Inf); use a zero vector where the direction is free")
    job = field_ops.FieldJob(
        vertices=verts, triangles=tris, preset=args.preset or "around_axis",
        axis=field_ops.AXES[args.axis.upper()], curve=curve, given=paint,
    )
    field, seconds = _run_job(job, "field")
    np.save(out, np.ascontiguousarray(field, np.float32))
    how = f"diffused from {os.path.basename(args.paint)}" if paint is not None else args.preset
    return f"field: {len(field)} vertices, {how}, in {seconds:.2f} s -> {args.out}"


def _load_npy(arg, path):
    path = _input_file(arg, path, (".npy",))
    try:
        array = np.load(path, allow_pickle=False)
    except ValueError as exc:
        raise UsageError(f"{arg}: {path} is not a numeric .npy array ({exc})") from None
    _require(np.issubdtype(array.dtype, np.number) and not np.issubdtype(array.dtype, np.complexfloating),
             f"{arg}: {path} holds {array.dtype} values, not numbers; save it from a float array "
             "(numpy.save(path, array.astype('float32')))")
    return array


def _directions(arg, path, vertices, mesh_flag):
    """A V by 3 direction file for the mesh of `mesh_flag` (zero rows are free), or a UsageError."""
    vectors = _load_npy(arg, path).astype(np.float64)
    _require(vectors.shape == vertices.shape,
             f"{arg}: {path} is {vectors.shape}; {mesh_flag} has {len(vertices)} vertices: give ({len(vertices)}, 3), "
             "one direction per vertex (e.g. './exsynth run field --mesh' on the same file)")
    _require(bool(np.isfinite(vectors).all()), f"{arg}: {path} has NaN or infinite values; fix or regenerate it")
    _require(bool((np.linalg.norm(vectors, axis=1) > 0).any()),
             f"{arg}: {path} is zero everywhere, so it gives the texture no direction; give a direction at some "
             "vertices (zero rows are filled in from them)")
    return vectors


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
            or demo.run_analogy(bunny, args.out, samples=args.samples)
            or demo.run_surface(cow, _input_file("--assets", os.path.join(args.assets, "textures", "drkwood2.png"), None),
                                stone, args.out, samples=args.samples))


# ---- argument checks ----------------------------------------------------------
# argparse types: a bad value is refused before anything runs, as
# "argument --seed: ...", with the valid range.
MAX_GIB = 1 << 20  # 1 PiB: any budget a machine can have


def _seed(text):
    try:
        value = int(text, 0)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a whole number; give 0 .. 2**64-1") from None
    if not 0 <= value < 1 << 64:
        raise argparse.ArgumentTypeError(f"{value} is out of range; give 0 .. 2**64-1")
    return value


def _int(text):
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a whole number") from None
    if abs(value) >= 1 << 31:
        raise argparse.ArgumentTypeError(f"{value} is far too large (the limit is 2**31-1)")
    return value


def _finite(text):
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a number") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"{text} is not a finite number")
    return value


def _gib(text):
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a number of GiB") from None
    if not (math.isfinite(value) and 0 <= value <= MAX_GIB):
        raise argparse.ArgumentTypeError(f"{text} GiB is out of range; give 0 (the engine's default) .. {MAX_GIB}")
    return value


def _add_memory_budget(p):
    p.add_argument("--memory-budget", type=_gib, default=0.0,
                   help="refuse jobs needing more than this many GiB (default: the engine's "
                   f"{_native.DEFAULT_MEMORY_BUDGET / GIB:g} GiB)")


def _goes_with(flag, given, ok, partner):
    """Refuse `flag` where it would do nothing: it goes with `partner`."""
    _require(not given or ok, f"{flag} goes with {partner}; here it would have no effect")


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
    _require(not os.path.isdir(path), f"{arg}: {path} is a folder; give a file in it")
    _require(os.path.isfile(path), f"{arg}: no such file: {path}")
    if allowed is not None:
        _extension(arg, path, allowed)
    mesh_files.check_indices(arg, path)  # what Blender's importers would drop silently
    return path


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
    size.add_argument("--texels-per-unit", type=_finite, help="texels per unit of surface length")
    size.add_argument("--face-resolution", type=_int, help="texels along every face map "
                      f"(default {_native.SURFACE_DEFAULT_FACE_RESOLUTION})")
    p.add_argument("--exemplar-scale", type=_finite, default=1.0,
                   help="exemplar pixels per texel; larger makes the pattern smaller (default 1)")
    field = p.add_mutually_exclusive_group()
    field.add_argument("--field-preset", choices=tuple(surface_ops.FIELD_MODES.values()), default="smooth",
                       help="which way the pattern runs (default smooth: a smooth field from --axis)")
    field.add_argument("--field", help="(V, 3) .npy, a direction per vertex of --mesh (e.g. 'run field')")
    p.add_argument("--axis", type=_finite, nargs=3, metavar=("X", "Y", "Z"),
                   help="the presets' axis in the file's coordinates (default 0 0 1)")
    p.add_argument("--segments", type=_int, default=_native.SURFACE_DEFAULT_SEGMENTS,
                   help="limit-mesh quads along each n-gon sub-face, twice that per quad (default %(default)s)")
    p.add_argument("--height-scale", type=_finite,
                   help="with --height: displacement per unit of height around 0.5 (default 0.02)")
    p.add_argument("--out", required=True, help="the textured limit mesh: .obj (+ .mtl)")
    p.add_argument("--texture-out", required=True, help="the atlas: .png")
    p.add_argument("--height-out", help="with --height: the height atlas, .png")
    p.add_argument("--seed", type=_seed, default=0, help="random seed (default 0)")
    _add_memory_budget(p)
    p.set_defaults(run=_run_surface)


def _run_surface(args):
    from .operators import surface as surface_ops

    mesh_path = _input_file("--mesh", args.mesh, MESH_FORMATS)
    exemplar_path = _input_file("--exemplar", args.exemplar, None)
    height_path = _input_file("--height", args.height, None) if args.height else None
    for flag, value in (("--height-out", args.height_out), ("--height-scale", args.height_scale)):
        _goes_with(flag, value is not None, args.height, "--height")
    _goes_with("--axis", args.axis is not None, not args.field, "--field-preset (--field sets every direction)")
    args.axis = (0.0, 0.0, 1.0) if args.axis is None else args.axis
    args.height_scale = 0.02 if args.height_scale is None else args.height_scale
    out = args.outputs.add("--out", args.out, (".obj",))
    mtl_final = os.path.splitext(args.out)[0] + ".mtl"
    mtl = args.outputs.add("--out (its .mtl)", mtl_final, (".mtl",))
    texture_out = args.outputs.add("--texture-out", args.texture_out, (".png",))
    height_out = args.outputs.add("--height-out", args.height_out, (".png",)) if args.height_out else None
    _require(args.texels_per_unit is None or args.texels_per_unit > 0,
             f"--texels-per-unit must be > 0 (got {args.texels_per_unit})")
    _require(args.face_resolution is None or args.face_resolution > 0,
             f"--face-resolution must be > 0 (got {args.face_resolution})")
    _require(args.exemplar_scale > 0, f"--exemplar-scale must be > 0 (got {args.exemplar_scale})")
    top = _native.SURFACE_MAX_SEGMENTS
    _require(1 <= args.segments <= top, f"--segments must be in 1..{top} (got {args.segments})")
    if args.face_resolution is not None:
        top = _native.SURFACE_MAX_FACE_RESOLUTION
        _require(args.face_resolution <= top, f"--face-resolution must be in 1..{top} (got {args.face_resolution})")
    _require(any(args.axis) and all(np.isfinite(args.axis)), "--axis must be a finite, non-zero direction")

    objects = import_mesh(mesh_path)
    _require(bool(objects), f"--mesh: {mesh_path} holds no mesh")
    obj = _single_mesh(objects, mesh_path) if len(objects) > 1 else objects[0]
    try:
        mesh = surface_ops.control_mesh(obj)
    except jobs.InputError as exc:
        raise UsageError(f"--mesh: {exc}")
    field = None
    if args.field:
        field = _directions("--field", args.field, mesh.vertices, "--mesh")
    colour = image_io.load(exemplar_path)
    height = image_io.load(height_path) if height_path else None
    try:
        exemplar, channels, encoding = surface_ops.read_exemplar(colour, height, args.alpha)
    except jobs.InputError as exc:
        raise UsageError(str(exc))
    job = surface_ops.SurfaceJob(
        mesh=mesh, exemplar=exemplar, colour_channels=channels, has_height=height is not None,
        encoding=encoding, method=args.method, texels_per_unit=args.texels_per_unit or 0.0,
        face_resolution=args.face_resolution or _native.SURFACE_DEFAULT_FACE_RESOLUTION, exemplar_scale=args.exemplar_scale,
        field_mode=args.field_preset, axis=tuple(args.axis), field=field, height_scale=args.height_scale,
        segments=args.segments, memory_budget=int(args.memory_budget * GIB), seed=args.seed,
    )
    result, seconds = _run_job(job, "surface")

    # Written by exsynth, not Blender's exporter: the files must name each
    # other by their final names while they are written under temporary ones.
    atlas = result.atlas[::-1]
    image_io.save_png(texture_out, atlas[..., :channels], encoding)
    if height_out:
        image_io.save_png(height_out, atlas[..., channels:channels + 1], image_io.DATA)
    mesh_files.write_textured_obj(out, mtl, (args.out, mtl_final, args.texture_out), f"{result.name}_surface",
                                  result.vertices, result.quads, result.corner_uvs, alpha=channels == 4)
    h, w = result.atlas.shape[:2]
    return (f"surface: {result.method} on {os.path.basename(mesh_path)}, {result.texels} texels on "
            f"{result.faces} faces, field {result.field}, atlas {w}x{h}, {len(result.quads)} quads in "
            f"{seconds:.2f} s -> {args.out}, {args.texture_out}")


# ---- points --------------------------------------------------------------------
def _points_parser(sub):
    from .operators import points as points_ops

    p = sub.add_parser(
        "points", help="grow a geometry texture (oriented points) over a plane or a mesh: .ply or .obj",
        description="Patch-based geometry texture synthesis on point sets. The exemplar is a point file "
        "with normals (.ply, .xyz, .pwn), a grey height-field image (one pixel = --pixel-size units, height "
        "= grey / 255 x --height-scale) or a built-in (--preset, a 1 x 1 box: --size 4 4 asks for 16 "
        "exemplar areas). Grows over --size W D of the reference plane or over --target MESH.",
    )
    ex = p.add_mutually_exclusive_group(required=True)
    ex.add_argument("--exemplar", help="a point file (.ply with nx ny nz, .xyz, .pwn) or a grey image (.png)")
    ex.add_argument("--preset", choices=points_ops.PRESETS, help="a built-in geometry texture")
    out = p.add_mutually_exclusive_group(required=True)
    out.add_argument("--size", type=_finite, nargs=2, metavar=("W", "D"), help="output area, exemplar units")
    out.add_argument("--target", help="a mesh to cover (.obj, .ply, .stl; file coordinates)")
    p.add_argument("--field-preset", choices=analogy_ops.FIELD_PRESETS,
                   help="--target: the direction the texture's x axis follows (default around_axis; the "
                   "presets of 'run analogy')")
    p.add_argument("--axis", type=_finite, nargs=3, metavar=("X", "Y", "Z"),
                   help="around_axis / along_axis: the axis in the file's coordinates (default 0 0 1)")
    p.add_argument("--curve", help="along_curve: the curve as a polyline, .obj (vertices joined by 'l' lines) "
                   "or .npy (N by 3), in the target file's coordinates")
    p.add_argument("--field", help="--target's own field: .npy, one direction per vertex (V by 3, e.g. from "
                   "'run field'); wins over --field-preset")
    p.add_argument("--scale", type=_finite,
                   help="--target: target units per exemplar unit (default: chosen from the target's area for "
                   f"about {_native.POINTS_DEFAULT_OUTPUT:.3g} points, about half a minute; the estimate is "
                   "printed before the work)")
    p.add_argument("--patch-size", type=_finite, help="patch side, exemplar units (default: preset's)")
    p.add_argument("--density", type=_finite,
                   help="built-ins and height fields: points per unit area (height fields: per pixel^2 x "
                   f"this / 10000; default {POINTS_DENSITY:g})")
    p.add_argument("--pixel-size", type=_finite, help="height field: units per pixel (default 1)")
    p.add_argument("--height-scale", type=_finite, help="height field: height of white (default 1)")
    p.add_argument("--out", required=True, help="the points: .ply (binary, with normals) or .obj (v + vn)")
    p.add_argument("--mesh-out", help="also a surface made from the points: .obj")
    p.add_argument("--seed", type=_seed, default=0, help="random seed (default 0)")
    _add_memory_budget(p)
    p.set_defaults(run=_run_points)


def _points_exemplar(args, points_ops):
    from .io import point_files

    point_file = bool(args.exemplar) and point_files.is_point_file(args.exemplar)
    _require(not point_file or args.density is None,
             "--density goes with --preset or a height-field image; a point file's points are used as they are")
    for flag, value in (("--pixel-size", args.pixel_size), ("--height-scale", args.height_scale)):
        _require(value is None or (args.exemplar and not point_file),
                 f"{flag} goes with a height-field image as --exemplar (a grey .png)")
    density = POINTS_DENSITY if args.density is None else args.density
    _require(density > 0, f"--density must be > 0 points per unit area (got {density:g})")
    if args.preset:
        return points_ops.Exemplar(name=args.preset, preset=args.preset, density=density), args.preset
    path = _input_file("--exemplar", args.exemplar, None)
    name = os.path.splitext(os.path.basename(path))[0]
    if point_file:
        try:
            pos, nrm = point_files.read_points(path)
        except point_files.PointFileError as exc:
            raise UsageError(f"--exemplar: {exc}")
        return points_ops.Exemplar(name=name, positions=pos, normals=nrm), "default"
    pixel_size = 1.0 if args.pixel_size is None else args.pixel_size
    height_scale = 1.0 if args.height_scale is None else args.height_scale
    _require(pixel_size > 0, f"--pixel-size must be > 0 (got {pixel_size:g})")
    image = image_io.load(path)
    try:
        grey = image_io.exemplar_pixels(image, role="height field")[::-1, :, 0]  # row 0 = y 0
    finally:
        bpy.data.images.remove(image)
    heights = np.ascontiguousarray(grey * height_scale, np.float32)
    _require(bool(np.isfinite(heights).all()), f"--height-scale {height_scale:g} makes the heights overflow")
    pad = max(2, min(heights.shape) // 8)
    try:
        ex = _native.height_field_exemplar(heights, pixel_size=pixel_size, padding=pad, seed=args.seed,
                                           density=density / 10000.0 / pixel_size ** 2)
    except _native.OverBudgetError as exc:
        raise UsageError(f"--exemplar {os.path.basename(path)} as a height field at --height-scale "
                         f"{height_scale:g}, --pixel-size {pixel_size:g}, --density {density:g}: {exc}") from None
    lo, hi = np.array(ex["box_min"]), np.array(ex["box_max"])
    exemplar = points_ops.Exemplar(name=name, positions=ex["positions"] - np.r_[lo, 0.0], normals=ex["normals"])
    exemplar.box = ((0.0, 0.0), tuple(hi - lo))
    return exemplar, "heightfield"


def _points_options(args, exemplar, preset):
    """The engine options: the preset's, with --patch-size or one fitted to a given exemplar's box."""
    options = _native.point_texture_preset(preset)
    if args.patch_size is not None:
        options["patch_size"] = args.patch_size
    elif preset == "default" and exemplar.box is None and exemplar.positions is not None:
        from .operators.points import user_box

        lo, hi = user_box(exemplar.positions)
        _require(min(np.subtract(hi, lo)) > 0, f"--exemplar: the points of {args.exemplar} span no area in x and y "
                 "(one point, or all on one line or spot); give an oriented point set spread over a surface")
        options["patch_size"] = 0.35 * float(min(np.subtract(hi, lo)))
    elif exemplar.box is not None:
        options["patch_size"] = 0.35 * float(min(exemplar.box[1]))
    return options


def _points_target(args, exemplar, field_preset, points_ops):
    """(Target, scale) for --target MESH."""
    path = _input_file("--target", args.target, MESH_FORMATS)
    verts, tris = mesh_io.world_triangles(import_mesh(path), bpy.context.evaluated_depsgraph_get())
    _require(len(tris) > 0, f"--target: {path} has no faces to cover")
    axis = (0.0, 0.0, 1.0) if args.axis is None else tuple(args.axis)
    _require(any(axis), "--axis must be a non-zero direction, e.g. --axis 0 0 1")
    target = points_ops.Target(name=os.path.splitext(os.path.basename(path))[0], vertices=verts, triangles=tris,
                               preset=field_preset, axis=axis, curve=_read_curve(args.curve) if args.curve else None)
    if args.field:
        target.field = np.ascontiguousarray(_directions("--field", args.field, verts, "--target"))
    try:
        scale = args.scale or points_ops.default_scale(exemplar, target)
    except _native.InvalidInputError as exc:
        raise UsageError(f"--target: {path}: {exc}") from None
    return target, scale


def _run_points(args):
    from .io import point_files
    from .operators import points as points_ops

    out = args.outputs.add("--out", args.out, (".ply", ".obj"))
    mesh_out = args.outputs.add("--mesh-out", args.mesh_out, (".obj",)) if args.mesh_out else None
    on_plane = ("--scale", args.scale), ("--field-preset", args.field_preset), ("--axis", args.axis), \
        ("--curve", args.curve), ("--field", args.field)
    for flag, value in on_plane if args.size else ():
        _require(value is None, f"{flag} goes with --target MESH; over a plane --size gives the output's extent")
    if args.patch_size is not None:
        _require(args.patch_size > 0, f"--patch-size must be > 0 exemplar units (got {args.patch_size:g})")
    if args.scale is not None:
        _require(args.scale > 0, f"--scale must be > 0 target units per exemplar unit (got {args.scale:g}); leave "
                 "it out to have it chosen from the target")
    exemplar, preset = _points_exemplar(args, points_ops)
    job = points_ops.PointTextureJob(exemplar=exemplar, options=_points_options(args, exemplar, preset),
                                     make_mesh=bool(args.mesh_out), memory_budget=int(args.memory_budget * GIB),
                                     seed=args.seed)
    field_preset = args.field_preset or "around_axis"
    _require(field_preset != "along_curve" or args.curve or args.field,
             "--field-preset along_curve needs --curve CURVE.obj (or .npy)")
    _require(not args.curve or field_preset == "along_curve", "--curve goes with --field-preset along_curve")
    if args.size:
        _require(min(args.size) > 0, f"--size must be two positive lengths (got {args.size[0]} {args.size[1]})")
        job.size = tuple(args.size)
    else:
        job.target, job.scale = _points_target(args, exemplar, field_preset, points_ops)
        e = points_ops.estimate(exemplar, job.target, job.scale, job.options)
        print(f"exsynth points: scale {job.scale:.3g}{'' if args.scale else ' (from the target area)'}: "
              f"{points_ops.estimate_text(e)}", file=sys.stderr, flush=True)
        budget = args.memory_budget * GIB or _native.DEFAULT_MEMORY_BUDGET
        _require(e["bytes"] <= budget,
                 f"--scale {job.scale:.3g}: about {e['points']:.3g} points need about {e['bytes'] / GIB:.3g} GiB, "
                 f"over the memory budget of {budget / GIB:.3g} GiB; raise --scale (the default for this target: "
                 f"{points_ops.default_scale(exemplar, job.target):.3g}) or --memory-budget")
        if e["seconds"] > 60:
            print(f"exsynth points: that is long; --scale {job.scale * math.sqrt(e['seconds'] / 30):.3g} makes about "
                  "half a minute (larger patterns, fewer patches)", file=sys.stderr, flush=True)
    result, seconds = _run_job(job, "points")
    point_files.write_points(out, result.positions, result.normals)
    t = result.stats["times"]
    line = (f"points: {exemplar.name} ({preset} weights) -> {len(result.positions)} points, "
            f"{result.stats['patches']} patches, {result.stats['pairs']} pairs (search {t['search']:.2f} s, warp {t['warp']:.2f} s, blend "
            f"{t['blend']:.2f} s, other {t['other']:.2f} s) in {seconds:.2f} s -> {args.out}")
    if mesh_out:
        export_obj(mesh_out, result.name.replace("_points", "_surface"), *result.surface)
        line += f", {len(result.surface[1])} triangles -> {args.mesh_out}"
    return line
