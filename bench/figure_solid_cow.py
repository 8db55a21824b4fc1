#!/usr/bin/env python3
"""The demo's solid-textured cow with a chosen solid method, for docs/solid.md.

Runs the solid part of `./exsynth demo` (the cow cut open, Solid Texture and
Re-bake from assets/textures/crackedground.png, Cycles) inside headless
Blender with the add-on's method set, at a larger resolution so the
texture's structure can be judged, and writes OUT.png.

usage: blender -b --factory-startup --python bench/figure_solid_cow.py -- \\
           --build build --out OUT.png [--method coordinates] [--size 64] [--samples 16] [--resolution 960 720] \\
           [--exemplar IMAGE.png]
"""
import argparse
import os
import sys


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--method", default=None, help="a SOLID_METHODS name (default: the add-on's)")
    ap.add_argument("--size", type=int, default=64)
    ap.add_argument("--exemplar", default=None, help="an image Blender reads (default: the demo's crackedground.png)")
    ap.add_argument("--options", default="",
                    help="extra engine options for the solid, e.g. \"finest_iterations=1\" "
                         "(a developer's experiment: wraps _native.synthesize_solid)")
    ap.add_argument("--samples", type=int, default=16)
    ap.add_argument("--resolution", type=int, nargs=2, default=(960, 720))
    args = ap.parse_args(argv)
    sys.path.insert(0, os.path.join(os.path.abspath(args.build), "addon"))
    from exsynth import demo, demo_stage
    if args.options:
        from exsynth import _native
        extra = eval(f"dict({args.options})", {})  # noqa: S307 - a developer's command line
        plain = _native.synthesize_solid
        _native.synthesize_solid = lambda *a, **kw: plain(*a, **{**kw, **extra})

    demo_stage.RESOLUTION_PX = tuple(args.resolution)
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    out = os.path.abspath(args.out)
    return demo.run_solid(os.path.join(root, "assets", "meshes", "cow.obj"),
                          os.path.abspath(args.exemplar or os.path.join(root, "assets", "textures", "crackedground.png")),
                          os.path.dirname(out), size=args.size, samples=args.samples, method=args.method,
                          name=os.path.basename(out))


if __name__ == "__main__":
    sys.exit(main(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []))
