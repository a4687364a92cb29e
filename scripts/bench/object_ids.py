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

With --reference (the graph of the map from ground-truth poses) and the super-point meshes of
the repaired and the reference map, a third line says which of those edges the reference map
has too, for the edges kept and for the edges lost: each super-point of the repaired map is
paired with the reference super-point that holds most of its mesh vertices (vertices compared
by the --cell-m cell they fall in; both maps share the world frame of the ground-truth poses),
and an edge is in the reference when the reference graph joins the two partners. An edge the
reference lacks is a co-observation only the drifted poses made.

  python3 scripts/bench/object_ids.py BEFORE.json REPAIRED.json [--min-voxels 100]
                                      [--radius-m 0.3] [--details]
                                      [--reference GT.json --repaired-mesh R.ply
                                       --reference-mesh GT.ply [--cell-m 0.02]]
"""
import argparse
import collections
import json
import math
import sys

from surface_distance import read_ply_vertices  # same folder


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
    kept = kept_ids(before, repaired)
    voxels = sum(v["voxels"] for v in repaired["vertices"])
    kept_voxels = sum(v["voxels"] for v in repaired["vertices"] if v["id"] in kept)
    old_edges = edge_pairs(before, kept)
    return (len(repaired["vertices"]), len(kept), kept_voxels / voxels if voxels else 0.0,
            len(old_edges), len(old_edges & edge_pairs(repaired, kept)))


def kept_ids(before, repaired):
    """Ids of the repaired graph's vertices that the graph before has too."""
    old_ids = {v["id"] for v in before["vertices"]}
    return {v["id"] for v in repaired["vertices"] if v["id"] in old_ids}


def edge_pairs(graph, ids):
    """The graph's edges, as (smaller id, larger id), between vertices in ids."""
    return {(min(e["a"], e["b"]), max(e["a"], e["b"])) for e in graph["edges"]
            if e["a"] in ids and e["b"] in ids}


def mesh_superpoints(path, cell_m):
    """{cell: Counter of super-point ids} of a mesh_superpoint.ply's vertices; exits with a
    one-line reason when it cannot be read."""
    try:
        names, vertices = read_ply_vertices(path)
        x, y, z, sp = (names.index(n) for n in ("x", "y", "z", "superpoint"))
    except (OSError, ValueError) as e:
        sys.exit("object_ids: %s" % e)
    cells = collections.defaultdict(collections.Counter)
    for v in vertices:
        cells[(math.floor(v[x] / cell_m), math.floor(v[y] / cell_m),
               math.floor(v[z] / cell_m))][v[sp]] += 1
    return cells


def partners(mesh, reference_mesh):
    """{super-point of mesh: the reference super-point holding most of its vertices}, from
    two mesh_superpoints() of the same cell size. Ties go to the smaller id."""
    votes = collections.defaultdict(collections.Counter)
    for cell, counts in mesh.items():
        there = reference_mesh.get(cell)
        if not there:
            continue
        best = min(there.items(), key=lambda item: (-item[1], item[0]))[0]
        for sp, n in counts.items():
            votes[sp][best] += n
    return {sp: min(c.items(), key=lambda item: (-item[1], item[0]))[0]
            for sp, c in votes.items()}


def edges_in_reference(before, repaired, reference, partner):
    """For the graph before's edges between kept super-points: {(kept or lost, verdict):
    count}, verdict one of "in reference", "not in reference", "one partner" (both ends pair
    with one reference super-point), "no partner" (an end has none)."""
    ids = kept_ids(before, repaired)
    after = edge_pairs(repaired, ids)
    ref_edges = {(min(e["a"], e["b"]), max(e["a"], e["b"])) for e in reference["edges"]}
    out = collections.Counter()
    for a, b in sorted(edge_pairs(before, ids)):
        fate = "kept" if (a, b) in after else "lost"
        pa, pb = partner.get(a), partner.get(b)
        if pa is None or pb is None:
            verdict = "no partner"
        elif pa == pb:
            verdict = "one partner"
        else:
            verdict = "in reference" if (min(pa, pb), max(pa, pb)) in ref_edges else \
                "not in reference"
        out[(fate, verdict)] += 1
    return out


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


VERDICTS = ("in reference", "not in reference", "one partner", "no partner")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("before", help="graph JSON of the map before the repair")
    ap.add_argument("repaired", help="graph JSON of the repaired map")
    ap.add_argument("--min-voxels", type=int, default=100)
    ap.add_argument("--radius-m", type=float, default=0.3)
    ap.add_argument("--details", action="store_true", help="list the objects that changed id")
    ap.add_argument("--reference", help="graph JSON of the map from ground-truth poses")
    ap.add_argument("--repaired-mesh", help="mesh_superpoint.ply of the repaired map")
    ap.add_argument("--reference-mesh", help="mesh_superpoint.ply of the reference map")
    ap.add_argument("--cell-m", type=float, default=0.02, help="cell for pairing vertices")
    args = ap.parse_args()
    reference_args = (args.reference, args.repaired_mesh, args.reference_mesh)
    if any(reference_args) and not all(reference_args):
        sys.exit("object_ids: --reference needs --repaired-mesh and --reference-mesh")
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
    if args.reference:
        partner = partners(mesh_superpoints(args.repaired_mesh, args.cell_m),
                           mesh_superpoints(args.reference_mesh, args.cell_m))
        fates = edges_in_reference(before_graph, repaired_graph, load(args.reference), partner)
        print("against the reference: " + "; ".join(
            "%s %s" % (fate, ", ".join("%d %s" % (fates[(fate, v)], v) for v in VERDICTS))
            for fate in ("kept", "lost")))
    if args.details:
        for line in others:
            print("  " + line)


if __name__ == "__main__":
    main()
