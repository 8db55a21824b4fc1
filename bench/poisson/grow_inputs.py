"""Screened-Poisson comparison, step 1: chainmail and weave grown to 2 x 2 at 5000 points per
unit area (as docs/images/points_*.png), written as NAME.xyz (x y z nx ny nz). Then
vdb_mesh.py NAME.xyz NAME_vdb.obj, poisson_cgal NAME.xyz NAME_poisson.off (+ off2obj.py),
and blender -b --python render_compare.py -- MESH.obj OUT.png. Figures: docs/points.md."""
import os, sys, numpy as np
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "build", "addon"))
from exsynth import _native
for name in ("chainmail", "weave"):
    ex = _native.make_point_exemplar(name, density=5000)
    r = _native.synthesize_points(ex["positions"], ex["normals"], size=(2, 2), options=_native.point_texture_preset(name))
    np.savetxt(f"{name}.xyz", np.hstack([r["positions"], r["normals"]]), fmt="%.6f")
    print(name, len(r["positions"]))
