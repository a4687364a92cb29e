#!/usr/bin/env python3
"""Follows one ground-truth object through the frames a mapper stored, frame by frame.

    python3 scripts/bench/trace_object.py --store DIR --gt MESH.ply --instance N [--with M]

DIR is a frame store (`panmap-mapper --frame-store DIR`, docs/LOOP_CLOSURE.md) of a run whose
poses are the ground truth's (a rendered sequence mapped with ground-truth poses); MESH.ply is
the sequence's gt/mesh.ply (vertex properties x, y, z, semantic, instance). Each of the
object's vertices is projected into every stored frame with the pose the frame was integrated
with; where the stored depth agrees (within --depth-tolerance) the vertex is visible, and the
pixel tells what the pipeline made of it: the panoptic mask there, whether the depth
segmentation gave it a geometric segment (0: an edge or a dropped small segment) and whether it
voted for a super-point (the pixel label association gave the integrator; 0: no vote).

That is the question "why is this object unlabelled in the map": seen, but never voting, is
a segmentation matter (docs/MAPPING.md, mask-only surfaces); voting for a super-point that
ends up without a class is the labelling's. With `--with M`, a second object (a neighbour the
first came out merged with) is followed alongside: each one's mask and the super-points its
pixels voted for, and the frames where one mask covers both ("ONE MASK": a network merging two
touching objects, which is when III-B may join their super-points). Needs the `zstd` command
(scripts/setup.sh).
"""

import argparse
import os
import shutil
import struct
import subprocess
import sys
from collections import Counter

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from surface_distance import read_ply_vertices  # noqa: E402  (same folder)


def fail(message):
    print("trace_object: " + message, file=sys.stderr)
    sys.exit(1)


def read_mesh(path):
    """read_ply_vertices, a failure named in one line."""
    try:
        return read_ply_vertices(path)
    except (OSError, ValueError) as e:
        fail(str(e) if isinstance(e, ValueError) else "cannot open %s: %s" % (path, e.strerror))


def read_plane(path):
    """Decodes a frame store plane (io/plane_codec.h): returns (width, pixels)."""
    try:
        blob = open(path, "rb").read()
    except OSError as e:
        fail("cannot open %s: %s" % (path, e.strerror))
    if len(blob) < 16 or blob[:4] != b"PMZP":
        fail("%s: not a frame store plane (stores of version 1 keep PNGs: not read here)" % path)
    _, kind, width, height = struct.unpack("<4sIII", blob[:16])
    raw = subprocess.run(["zstd", "-dc"], input=blob[16:], capture_output=True)
    if raw.returncode != 0:
        fail("%s: zstd could not decode it" % path)
    pixels = raw.stdout
    bytes_per_pixel = len(pixels) // (width * height) if width * height else 0
    code = {1: "B", 2: "H", 4: "i"}.get(bytes_per_pixel)
    if code is None or len(pixels) != width * height * bytes_per_pixel:
        fail("%s: %d bytes for %d x %d pixels" % (path, len(pixels), width, height))
    return width, struct.unpack("<%d%s" % (width * height, code), pixels)


def frames_of(store):
    """Yields (utime, fx, fy, cx, cy, width, height, depth scale, 3x4 pose) per index line."""
    index = os.path.join(store, "index.txt")
    if not os.path.exists(index):
        fail("%s: no index.txt (not a frame store)" % store)
    for line in open(index):
        words = line.split()
        if not words or words[0] != "frame":
            continue
        if len(words) < 21:
            fail("%s: a frame line has %d fields" % (index, len(words)))
        fx, fy, cx, cy = map(float, words[2:6])
        pose = list(map(float, words[9:21]))
        yield words[1], fx, fy, cx, cy, int(words[6]), int(words[7]), float(words[8]), pose


def project(points, M, fx, fy, cx, cy, width, height):
    """{pixel: depth} of the points that land in the image in front of the camera."""
    pixels = {}
    for p in points:
        d = (p[0] - M[3], p[1] - M[7], p[2] - M[11])
        # p_C = R^T (p_W - t), R row-major in M.
        x = M[0] * d[0] + M[4] * d[1] + M[8] * d[2]
        y = M[1] * d[0] + M[5] * d[1] + M[9] * d[2]
        z = M[2] * d[0] + M[6] * d[1] + M[10] * d[2]
        if z <= 0.05:
            continue
        u, v = int(round(fx * x / z + cx)), int(round(fy * y / z + cy))
        if 0 <= u < width and 0 <= v < height:
            pixels.setdefault((u, v), z)
    return pixels


def agreeing(pixels, depth, width, scale, tolerance):
    """The projected pixels where the stored depth agrees within `tolerance`."""
    return [(u, v) for (u, v), z in pixels.items()
            if depth[v * width + u] > 0 and abs(depth[v * width + u] * scale - z) < tolerance]


def top(counts, n=3, classes=None):
    """The n largest counts; with classes ({mask id: class}), each mask named with its class."""
    if classes is None:
        return ", ".join("%d: %d" % kv for kv in counts.most_common(n))
    return ", ".join("%d (class %d): %d" % (k, classes.get(k, 0), c) if k > 0 else "0: %d" % c
                     for k, c in counts.most_common(n))


def mask_classes(path):
    """{segment id: class} of a frame's stored segment list (id, category, ...), {} without one."""
    if not os.path.exists(path):
        return {}
    classes = {}
    for line in open(path):
        words = line.split()
        if len(words) >= 2:
            classes[int(words[0])] = int(words[1])
    return classes


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--store", required=True, help="frame store folder of a ground-truth-pose run")
    parser.add_argument("--gt", required=True, help="the sequence's gt/mesh.ply")
    parser.add_argument("--instance", type=int, required=True, help="ground-truth instance id")
    parser.add_argument("--with", dest="other", type=int,
                        help="a second ground-truth instance (a neighbour the first was merged "
                             "with): frames where one mask covers both, and each one's votes")
    parser.add_argument("--depth-tolerance", type=float, default=0.03,
                        help="a vertex is visible where the stored depth is this close, metres")
    parser.add_argument("--quiet", action="store_true", help="the summary only")
    args = parser.parse_args()
    if shutil.which("zstd") is None:
        fail("needs the zstd command (apt-get install zstd; scripts/setup.sh installs it)")

    names, vertices = read_mesh(args.gt)
    for needed in ("x", "y", "z", "instance"):
        if needed not in names:
            fail("%s: no vertex property '%s'" % (args.gt, needed))
    ix, iy, iz, ii = (names.index(n) for n in ("x", "y", "z", "instance"))
    ids = [args.instance] + ([args.other] if args.other is not None else [])
    if len(set(ids)) != len(ids):
        fail("--with names the same instance as --instance")
    objects = {}
    for i in ids:
        objects[i] = [(v[ix], v[iy], v[iz]) for v in vertices if v[ii] == i]
        if not objects[i]:
            fail("%s: no vertex of instance %d" % (args.gt, i))
        print("instance %d: %d vertices" % (i, len(objects[i])))

    totals = Counter()
    for utime, fx, fy, cx, cy, width, height, scale, M in frames_of(args.store):
        totals["frames"] += 1
        projected = {i: project(objects[i], M, fx, fy, cx, cy, width, height) for i in ids}
        if not any(projected.values()):
            continue
        base = os.path.join(args.store, "frames", utime)
        _, depth = read_plane(base + ".depth.zst")
        seen = {i: agreeing(projected[i], depth, width, scale, args.depth_tolerance) for i in ids}
        if not seen[args.instance] and not (args.other is not None and seen[args.other]):
            continue
        _, labels = read_plane(base + ".labels.zst")
        masks = geometric = None
        classes = mask_classes(base + ".segments.txt")
        if os.path.exists(base + ".masks.zst"):
            _, masks = read_plane(base + ".masks.zst")
        if os.path.exists(base + ".geometric.zst"):
            _, geometric = read_plane(base + ".geometric.zst")
        parts, main_mask = [], {}
        for i in ids:
            visible = seen[i]
            if not visible:
                parts.append("%d unseen" % i if args.other is not None else "")
                continue
            prefix = "%d: " % i if args.other is not None else ""
            if i == args.instance:
                totals["frames seen"] += 1
                totals["pixels seen"] += len(visible)
            voted = sum(1 for u, v in visible if labels[v * width + u] > 0)
            if i == args.instance:
                totals["pixels voting"] += voted
            line = "%s%d pixels seen, %d voting" % (prefix, len(visible), voted)
            if masks is not None:
                counts = Counter(masks[v * width + u] for u, v in visible)
                main_mask[i] = counts.most_common(1)[0][0]
                line += ", masks %s" % top(counts, classes=classes)
            if geometric is not None:
                edge = sum(1 for u, v in visible if geometric[v * width + u] == 0)
                if i == args.instance:
                    totals["pixels without a geometric segment"] += edge
                line += ", %d without a geometric segment" % edge
            if args.other is not None:
                line += ", super-points %s" % top(Counter(labels[v * width + u]
                                                          for u, v in visible))
            parts.append(line)
        if args.other is not None and len(main_mask) == 2:
            totals["frames both seen"] += 1
            if main_mask[args.instance] > 0 and main_mask[args.instance] == main_mask[args.other]:
                totals["frames one mask covers both"] += 1
                parts.append("ONE MASK")
        if not args.quiet:
            print("frame %s: %s" % (utime, " | ".join(p for p in parts if p)))
    print("; ".join("%s %d" % kv for kv in totals.items()))


if __name__ == "__main__":
    main()
