#!/usr/bin/env python3
"""Whether the objects of a repaired map kept the ids they had before the repair (issue 22).

Reads two super-point graphs written by `panmap-mapper --graph-json` (the map before the
repair, e.g. the same log mapped without the correction, and the repaired map) and groups each
graph's super-points by their frame-count instance (`initial_instance`: the ids
PANMAP_OBJECTS publishes while mapping). For every group of at least --min-voxels voxels in the
repaired map, its counterpart is the group of the same class (the voxel-weighted majority of
`initial_class`) in the map before whose voxel-weighted centroid is nearest, within
--radius-m. Prints how many repaired objects have a counterpart and how many of those carry
its id; --details lists the others. A second line counts the super-points: how many of the
repaired graph's vertices carry an id the graph before had (a repair gives every other one an
id never used before, so a shared id is a kept one), the share of their voxels, and of the
graph before's edges between those super-points, how many the repaired graph has.

  python3 scripts/bench/object_ids.py BEFORE.json REPAIRED.json [--min-voxels 100]
                                      [--radius-m 0.3] [--details]
"""
import argparse
import collections
import json
import math
import sys


def load(path):
    """The graph JSON at path; exits with a one-line reason when it cannot be read."""
    try:
        with open(path) as f:
            graph = json.load(f)
        if not isinstance(graph["vertices"], list) or not isinstance(graph["edges"], list):
            raise ValueError("vertices and edges must be lists")
        return graph
    except (OSError, ValueError, KeyError) as e:
        sys.exit("object_ids: %s: %s" % (path, e))


def superpoint_ids(before, repaired):
    """(vertices, of them with an id of before, share of their voxels, edges of before between
    those, of them in repaired)."""
    old_ids = {v["id"] for v in before["vertices"]}
    kept = {v["id"] for v in repaired["vertices"] if v["id"] in old_ids}
    voxels = sum(v["voxels"] for v in repaired["vertices"])
    kept_voxels = sum(v["voxels"] for v in repaired["vertices"] if v["id"] in kept)
    def pairs(graph):
        return {(e["a"], e["b"]) for e in graph["edges"] if e["a"] in kept and e["b"] in kept}
    old_edges = pairs(before)
    return (len(repaired["vertices"]), len(kept), kept_voxels / voxels if voxels else 0.0,
            len(old_edges), len(old_edges & pairs(repaired)))


def objects(graph, min_voxels):
    """{instance: (voxels, centroid, class)} of the groups with at least min_voxels voxels."""
    vertices = graph["vertices"]
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
    before_graph, repaired_graph = load(args.before), load(args.repaired)
    before = objects(before_graph, args.min_voxels)
    repaired = objects(repaired_graph, args.min_voxels)
    with_counterpart, kept, others = compare(before, repaired, args.radius_m)
    print("object ids: %d repaired objects, %d with a counterpart before, %d of them keep its id"
          % (len(repaired), with_counterpart, kept))
    vertices, kept_ids, share, old_edges, kept_edges = superpoint_ids(before_graph, repaired_graph)
    print("super-point ids: %d of %d graph vertices keep an id (%.1f %% of their voxels); "
          "%d edges between them before, %d of them kept"
          % (kept_ids, vertices, 100.0 * share, old_edges, kept_edges))
    if args.details:
        for line in others:
            print("  " + line)


if __name__ == "__main__":
    main()
