"""vdb_mesh.py IN.xyz OUT.obj: points_to_mesh (OpenVDB) on an oriented point file, timed."""
import os, sys, time, numpy as np
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "build", "addon"))
from exsynth import _native
a = np.loadtxt(sys.argv[1], dtype=np.float32)
t0 = time.perf_counter(); c0 = time.process_time()
m = _native.points_to_mesh(np.ascontiguousarray(a[:, :3]), np.ascontiguousarray(a[:, 3:]))
t1 = time.perf_counter(); c1 = time.process_time()
v, f = (m["vertices"], m["triangles"]) if isinstance(m, dict) else m
with open(sys.argv[2], "w") as out:
    for p in v: out.write("v %.6f %.6f %.6f\n" % tuple(p))
    for t in f: out.write("f %d %d %d\n" % tuple(np.asarray(t) + 1))
print(f"points_to_mesh: {len(a)} points -> {len(v)} vertices, {len(f)} triangles in {t1-t0:.2f} s wall, {c1-c0:.2f} s CPU")
