"""Distance from each vertex of mesh A to the nearest vertex of mesh B, capped at 10 cm: mean,
median and 95th percentile (a reference-free map is compared with a reference map this way).
Usage: python3 scripts/bench/surface_distance.py A.ply B.ply"""
import math, struct, sys, collections
def load(path):
    f = open(path, 'rb'); props = []; n = 0
    while True:
        l = f.readline().decode().strip()
        if l.startswith('element vertex'): n = int(l.split()[2])
        elif l.startswith('property') and 'list' not in l: props.append(l.split()[1])
        elif l == 'end_header': break
    fmt = '<' + ''.join({'float': 'f', 'uchar': 'B', 'int': 'i'}[t] for t in props)
    sz = struct.calcsize(fmt); data = f.read(sz * n)
    return [struct.unpack_from(fmt, data, i * sz)[:3] for i in range(n)]
def dist(a, b, cap=0.1):
    C = cap; grid = collections.defaultdict(list)
    for p in b: grid[(math.floor(p[0]/C), math.floor(p[1]/C), math.floor(p[2]/C))].append(p)
    out = []
    for p in a:
        k = (math.floor(p[0]/C), math.floor(p[1]/C), math.floor(p[2]/C)); best = cap * cap
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                for dz in (-1, 0, 1):
                    for q in grid.get((k[0]+dx, k[1]+dy, k[2]+dz), ()):
                        d = (p[0]-q[0])**2 + (p[1]-q[1])**2 + (p[2]-q[2])**2
                        if d < best: best = d
        out.append(math.sqrt(best))
    out.sort()
    return sum(out)/len(out), out[len(out)//2], out[len(out)*95//100]
if len(sys.argv) != 3:
    sys.exit(__doc__)
a = load(sys.argv[1]); b = load(sys.argv[2])
print('%s -> %s: mean %.2f cm, median %.2f cm, p95 %.2f cm (%d vertices, capped at 10 cm)' % (
    sys.argv[1], sys.argv[2], *(100*x for x in dist(a, b)), len(a)))
