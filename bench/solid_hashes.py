#!/usr/bin/env python3
"""SHA-256 of the optimiser's outputs (solid or image, and the energies) for
option sets that exercise its paths, to show that a speed change left the
output byte-identical: run it with the old and the new module and compare.
"full" adds the default 128^3 solid; a thread count runs every case on
exactly that many threads (_native.with_threads).

usage: PYTHONPATH=BUILD/addon /usr/bin/python3 bench/solid_hashes.py [quick|full] [threads]
       (ONLY=name,name,... runs a subset)
"""
import hashlib, sys, os, time, resource
import numpy as np
from PIL import Image
from exsynth import _native
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ex = np.asarray(Image.open(f"{ROOT}/assets/textures/crackedground.png").convert("RGB"))
granite = np.asarray(Image.open(f"{ROOT}/assets/textures/granite1.png").convert("RGB"))  # priced histogram values
ex6 = np.concatenate([ex, ex[::-1, ::-1]], axis=2).astype(np.float32) / 255.0
cons = np.zeros((32, 32, 32, 4), np.float32); cons[..., :3] = 0.5; cons[8:16, 8:16, 8:16, 3] = 0.7
cases = [
    ("solid64", lambda: _native.synthesize_solid(ex, size=64, seed=1)),
    ("solid64_clamped", lambda: _native.synthesize_solid(ex, size=64, seed=2, tileable=False)),
    ("solid48_meanshift", lambda: _native.synthesize_solid(ex, size=48, seed=3, mean_shift=True)),
    ("solid48_nohist", lambda: _native.synthesize_solid(ex, size=48, seed=4, histogram_matching=False)),
    ("solid32_constraint", lambda: _native.synthesize_solid(ex, size=32, seed=5, constraint=cons)),
    ("solid32_6ch_xz", lambda: _native.synthesize_solid(ex6, size=32, seed=6, views="xz")),
    ("solid48_noexval", lambda: _native.synthesize_solid(ex, size=48, seed=7, exemplar_values=False)),
    ("solid32_kdtree", lambda: _native.synthesize_solid(ex, size=32, seed=8, search="kdtree")),
    ("solid32_hist1", lambda: _native.synthesize_solid(ex, size=32, seed=9, histogram_strength=1.0, coherent_upsampling=False)),
    ("solid32_feature", lambda: _native.synthesize_solid(ex, size=32, seed=10, feature_weight=1.0)),
    ("solid48_plainvalues", lambda: _native.synthesize_solid(ex, size=48, seed=11, histogram_values=0)),
    ("solid48_histvalues", lambda: _native.synthesize_solid(ex, size=48, seed=12, histogram_values=0.1, histogram_value_window=0.5)),
    ("solid48_granite_priced", lambda: _native.synthesize_solid(granite, size=48, seed=13)),
    ("solid40_granite_window", lambda: _native.synthesize_solid(granite, size=40, seed=14, histogram_value_window=0.5)),
    ("solid48_rotate_t1", lambda: _native.synthesize_solid(ex, size=48, seed=15, feature_threshold=1, rotate_exemplar=True)),
    ("image128_opt", lambda: _native.synthesize_image(ex, width=128, height=128, seed=1, method="optimization")),
    ("image96_opt_tile", lambda: _native.synthesize_image(ex, width=96, height=80, seed=2, method="optimization", tileable=True)),
    ("coord64", lambda: _native.synthesize_solid(ex, size=64, seed=1, method="coordinates")),
]
if len(sys.argv) > 1 and sys.argv[1] == "full":
    cases.append(("solid128", lambda: _native.synthesize_solid(ex, size=128, seed=1)))
    cases.append(("solid128_granite", lambda: _native.synthesize_solid(granite, size=128, seed=1)))
only = os.environ.get("ONLY")
threads = int(sys.argv[2]) if len(sys.argv) > 2 else 0
for name, fn in cases:
    if only and name not in only.split(","): continue
    t = time.perf_counter(); r0 = resource.getrusage(resource.RUSAGE_SELF)
    res = _native.with_threads(threads, fn) if threads else fn()
    r1 = resource.getrusage(resource.RUSAGE_SELF)
    key = "solid" if "solid" in res else "image"
    h = hashlib.sha256(np.ascontiguousarray(res[key]).tobytes())
    h.update(np.asarray(res["energy"], np.float64).tobytes())
    cpu = r1.ru_utime + r1.ru_stime - r0.ru_utime - r0.ru_stime
    print(f"{name:22s} {h.hexdigest()[:16]}  {time.perf_counter()-t:6.2f}s wall {cpu:6.2f}s cpu", flush=True)
