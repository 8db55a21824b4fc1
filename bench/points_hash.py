"""Usage: python3 bench/points_hash.py BUILD_DIR TARGET_POINTS [threads]: the points benchmark's case
(chainmail, ~71 k exemplar points, preset options) through _native.synthesize_points; prints the md5
of the output, wall and process CPU of the call, the split and the load (compare builds alternately)."""
import hashlib, os, sys, time
sys.path.insert(0, os.path.join(sys.argv[1], "addon"))
from exsynth import _native
target = float(sys.argv[2]); threads = int(sys.argv[3]) if len(sys.argv) > 3 else 0
probe = _native.make_point_exemplar("chainmail", density=1000.0)
ex = _native.make_point_exemplar("chainmail", density=1000.0 * 71000.0 / len(probe["positions"]))
p = ex["positions"]; inside = ((p[:, 0] >= 0) & (p[:, 0] <= 1) & (p[:, 1] >= 0) & (p[:, 1] <= 1)).sum()
side = (target / inside) ** 0.5
opt = _native.point_texture_preset("chainmail")
def run():
    return _native.synthesize_points(ex["positions"], ex["normals"], size=(side, side), options=opt)
t0, c0 = time.perf_counter(), time.process_time()
r = _native.with_threads(threads, run) if threads else run()
t1, c1 = time.perf_counter(), time.process_time()
h = hashlib.md5(r["positions"].tobytes() + r["normals"].tobytes()).hexdigest()
tm = r["times"]
print(f"{sys.argv[1][-20:]} n={len(r['positions'])} md5={h} wall={t1-t0:.2f} cpu={c1-c0:.2f} "
      f"search={tm['search']:.2f} warp={tm['warp']:.2f} blend={tm['blend']:.2f} other={tm['other']:.2f} load={os.getloadavg()[0]:.2f}")
