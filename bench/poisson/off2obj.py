"""off2obj.py IN.off OUT.obj (for Blender 3.4, which has no OFF importer)."""
import sys
lines = [l for l in open(sys.argv[1]).read().split("\n") if l.strip() and not l.startswith("#")]
assert lines[0].strip() == "OFF"
nv, nf, _ = map(int, lines[1].split())
with open(sys.argv[2], "w") as o:
    for l in lines[2:2 + nv]: o.write("v " + " ".join(l.split()[:3]) + "\n")
    for l in lines[2 + nv:2 + nv + nf]:
        p = l.split(); k = int(p[0]); o.write("f " + " ".join(str(int(i) + 1) for i in p[1:1 + k]) + "\n")
