#!/usr/bin/env python3
"""Whether the objects of a repaired map kept the ids they had before the repair (issue 22).

Reads two super-point graphs written by `panmap-mapper --graph-json` (the map before the
repair, e.g. the same log mapped without the correction, and the repaired map) and groups each
graph's super-points by their frame-count instance (`initial_instance`: the ids
PANMAP_OBJECTS publishes while mapping). For every group of at least --min-voxels voxels in the
repaired map, its counterpart is the group of the same class (the voxel-weighted majority of
`initial_class`) in the map before whose voxel-weighted centroid is nearest, within
--radius-m. Prints how many repaired objects have a counterpart and how many of those carry
its id; --details lists the others.

  python3 scripts/bench/object_ids.py BEFORE.json REPAIRED.json [--min-voxels 100]
                                      [--radius-m 0.3] [--details]
"""
import argparse
import collections
import json
import math
import sys


def objects(path, min_voxels):
    """{instance: (voxels, centroid, class)} of the groups with at least min_voxels voxels."""
    try:
        with open(path) as f:
            graph = json.load(f)
        vertices = graph["vertices"]
    except (OSError, ValueError, KeyError) as e:
        sys.exit("object_ids: %s: %s" % (path, e))
    groups = collections.defaultdict(lambda: [0, [0.0, 0.0, 0.0], collections.Counter()])
    for v in vertices:
        instance = v["initial_instance"]
        if instance <= 0:
            continue
        g = groups[instance]
        g[0] += v["voxels"]
        for k in range(3):
            g[1][k] += v["voxels"] * v["centroid"][k]
        g[2][v["initial_class"]] += v["voxels"]
    out = {}
    for instance, (voxels, weighted, classes) in groups.items():
        if voxels < min_voxels or voxels == 0:
            continue
        # Ties of class go to the smaller id, as the mapper's own majorities do.
        cls = min(classes.items(), key=lambda item: (-item[1], item[0]))[0]
        out[instance] = (voxels, [c / voxels for c in weighted], cls)
    return out


def compare(before, repaired, radius_m):
    """(repaired objects with a counterpart, those keeping its id, lines on the others)."""
    with_counterpart, kept, others = 0, 0, []
    for instance, (voxels, centroid, cls) in sorted(repaired.items()):
        best = None
        for old, (old_voxels, old_centroid, old_cls) in sorted(before.items()):
            distance = math.dist(centroid, old_centroid)
            if old_cls == cls and distance < radius_m and (best is None or distance < best[0]):
                best = (distance, old)
        if best is None:
            continue
        with_counterpart += 1
        if best[1] == instance:
            kept += 1
            continue
        own = before.get(instance)
        others.append("repaired %d (class %d, %d voxels): nearest before %d at %.2f m; id %d before: %s"
                      % (instance, cls, voxels, best[1], best[0], instance,
                         "class %d, %d voxels, %.2f m away" % (own[2], own[0],
                                                               math.dist(centroid, own[1]))
                         if own else "none (a new id)"))
    return with_counterpart, kept, others


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("before", help="graph JSON of the map before the repair")
    ap.add_argument("repaired", help="graph JSON of the repaired map")
    ap.add_argument("--min-voxels", type=int, default=100)
    ap.add_argument("--radius-m", type=float, default=0.3)
    ap.add_argument("--details", action="store_true", help="list the objects that changed id")
    args = ap.parse_args()
    before = objects(args.before, args.min_voxels)
    repaired = objects(args.repaired, args.min_voxels)
    with_counterpart, kept, others = compare(before, repaired, args.radius_m)
    print("object ids: %d repaired objects, %d with a counterpart before, %d of them keep its id"
          % (len(repaired), with_counterpart, kept))
    if args.details:
        for line in others:
            print("  " + line)


if __name__ == "__main__":
    main()
