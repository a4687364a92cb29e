"""Distance from each vertex of mesh A to the nearest vertex of mesh B, capped at 10 cm: mean,
median and 95th percentile (a reference-free map is compared with a reference map this way).
Usage: python3 scripts/bench/surface_distance.py A.ply B.ply"""
import collections
import math
import struct
import sys


def load_vertices(path):
    """The vertices of a binary little-endian PLY as dicts of their scalar properties."""
    f = open(path, 'rb'); props = []; n = 0
    while True:
        l = f.readline().decode().strip()
        if l.startswith('element vertex'): n = int(l.split()[2])
        elif l.startswith('property') and 'list' not in l: props.append(l.split()[1:])
        elif l == 'end_header': break
    fmt = '<' + ''.join({'float': 'f', 'uchar': 'B', 'int': 'i'}[t] for t, _ in props)
    names = [name for _, name in props]
    sz = struct.calcsize(fmt); data = f.read(sz * n)
    return [dict(zip(names, struct.unpack_from(fmt, data, i * sz))) for i in range(n)]


def load(path):
    return [(v['x'], v['y'], v['z']) for v in load_vertices(path)]


def nearest(a, b, cap=0.1):
    """For each point of a, (index of the nearest point of b, distance); (None, cap) when
    none is within cap."""
    C = cap; grid = collections.defaultdict(list)
    for j, p in enumerate(b): grid[(math.floor(p[0]/C), math.floor(p[1]/C), math.floor(p[2]/C))].append(j)
    out = []
    for p in a:
        k = (math.floor(p[0]/C), math.floor(p[1]/C), math.floor(p[2]/C)); best = cap * cap; at = None
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                for dz in (-1, 0, 1):
                    for j in grid.get((k[0]+dx, k[1]+dy, k[2]+dz), ()):
                        q = b[j]
                        d = (p[0]-q[0])**2 + (p[1]-q[1])**2 + (p[2]-q[2])**2
                        if d < best: best = d; at = j
        out.append((at, math.sqrt(best)))
    return out


def dist(a, b, cap=0.1):
    out = sorted(d for _, d in nearest(a, b, cap))
    return sum(out)/len(out), out[len(out)//2], out[len(out)*95//100]


if __name__ == '__main__':
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    a = load(sys.argv[1]); b = load(sys.argv[2])
    print('%s -> %s: mean %.2f cm, median %.2f cm, p95 %.2f cm (%d vertices, capped at 10 cm)' % (
        sys.argv[1], sys.argv[2], *(100*x for x in dist(a, b)), len(a)))
