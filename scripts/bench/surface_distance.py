"""Distance from each vertex of mesh A to the nearest vertex of mesh B, capped at 10 cm: mean,
median and 95th percentile (a reference-free map is compared with a reference map this way).
Usage: python3 scripts/bench/surface_distance.py A.ply B.ply"""
import collections
import math
import struct
import sys


PLY_TYPES = {"float": "f", "double": "d", "uchar": "B", "char": "b", "ushort": "H",
             "short": "h", "uint": "I", "int": "i"}


def read_ply_vertices(path):
    """(property names, vertex tuples) of a binary little-endian PLY. Raises OSError when the
    file cannot be read and ValueError naming what is wrong with it."""
    with open(path, "rb") as f:
        props, count, element, fmt = [], 0, None, None
        while True:
            line = f.readline()
            if not line:
                raise ValueError("%s: header has no end_header" % path)
            words = line.decode("ascii", "replace").split()
            if not words:
                continue
            if words[0] == "format":
                fmt = words[1]
            elif words[0] == "element":
                element = words[1]
                if element == "vertex":
                    count = int(words[2])
            elif words[0] == "property" and element == "vertex":
                if words[1] == "list" or words[1] not in PLY_TYPES:
                    raise ValueError("%s: vertex property '%s' not understood" % (
                        path, " ".join(words[1:])))
                props.append((words[2], PLY_TYPES[words[1]]))
            elif words[0] == "end_header":
                break
        if fmt != "binary_little_endian":
            raise ValueError("%s: format %s, expected binary_little_endian" % (path, fmt))
        layout = "<" + "".join(t for _, t in props)
        size = struct.calcsize(layout)
        data = f.read(size * count)
        if len(data) != size * count:
            raise ValueError("%s: %d vertices announced, the file ends before" % (path, count))
        return [name for name, _ in props], list(struct.iter_unpack(layout, data))


def load_vertices(path):
    """The vertices of a binary little-endian PLY as dicts of their scalar properties."""
    names, vertices = read_ply_vertices(path)
    return [dict(zip(names, v)) for v in vertices]


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
