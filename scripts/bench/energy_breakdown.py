#!/usr/bin/env python3
"""Why III-C relabels the super-points the network called class C: what keeping C would cost.

Reads a graph written by `panmap-mapper --graph-json` and takes every super-point whose scores'
argmax is C but whose final class is not. With every other super-point at its final class, it
sums the unary gain of giving them C back and the pairwise cost that adds (Eq. 7-9 as
src/graph/semantic_energy.cpp computes them with `weighting: surface`), and splits the cost by
the neighbours' size and observations per voxel: the mechanism docs/MAPPING.md describes.

  python3 scripts/bench/energy_breakdown.py graph.json --class 5 [--K-C 120] [--theta 0.5]
      [--link-scale smaller|geometric] [--link-half-observations 0] [--no-discount-apart]
      [--max-void-share 1]

Super-points left unlabelled (void share above --max-void-share; 1: none) are not III-C's
choice: they are left out of the group and their links cost nothing. The class consensus that
follows the swap (`optimiser.class_consensus`, docs/MAPPING.md) relabels whole groups the
network showed as one object, which no energy here explains: export the graph with
`optimiser.class_consensus: 0` to see the swap alone.
"""
import argparse
import json
import math
import sys


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("graph", help="JSON from panmap-mapper --graph-json")
    parser.add_argument("--class", dest="cls", type=int, required=True,
                        help="the class the network gave them (NYU40 id)")
    parser.add_argument("--K-C", type=float, default=120.0)
    parser.add_argument("--theta", type=float, default=0.5)
    parser.add_argument("--score-floor", type=float, default=1e-6)
    parser.add_argument("--link-scale", choices=("smaller", "geometric"), default="smaller")
    parser.add_argument("--link-half-observations", type=float, default=0.0)
    parser.add_argument("--no-discount-apart", action="store_true")
    parser.add_argument("--max-void-share", type=float, default=1.0)
    args = parser.parse_args()
    try:
        with open(args.graph) as f:
            graph = json.load(f)
        vertices = {v["id"]: v for v in graph["vertices"]}
        edges = graph["edges"]
    except (OSError, ValueError, KeyError) as e:
        sys.exit("energy_breakdown: %s: %s" % (args.graph, e))

    def score_sum(v):
        return sum(s for s in v["scores"].values() if s > 0)

    def share(v, c):
        total = score_sum(v)
        return v["scores"].get(str(c), 0.0) / total if total > 0 else 0.0

    def weight(v):
        return max(1, v["voxels"])

    def unary(v, c):
        if score_sum(v) <= 0:
            return 0.0
        return weight(v) * -math.log(max(share(v, c), args.score_floor))

    def observations(v):
        return score_sum(v) / weight(v)

    def unlabelled(v):
        return v.get("void_share", 0.0) > args.max_void_share

    def pairwise(a, b, e, ca, cb):
        if ca == cb or unlabelled(a) or unlabelled(b):
            return 0.0
        same = sum(e["confidences"].values())
        if same <= 0:
            return 0.0
        if not args.no_discount_apart:
            same = same * same / (same + e["apart"])
        sa, sb = score_sum(a), score_sum(b)
        scale = math.sqrt(sa * sb) if args.link_scale == "geometric" else min(sa, sb)
        if scale <= 0:
            return 0.0
        c = same / scale
        if args.link_half_observations > 0:
            n = min(observations(a), observations(b))
            c *= n / (n + args.link_half_observations) if n > 0 else 0.0
        if c <= 0:
            return 0.0
        product = share(a, ca) * share(b, cb)
        cost = args.K_C * min(weight(a), weight(b))
        return cost if product <= 0 else cost * math.exp(-product / (2 * args.theta ** 2 * c))

    def argmax(v):
        scored = [(s, int(c)) for c, s in v["scores"].items() if s > 0]
        return max(scored)[1] if scored else None

    group = {i for i, v in vertices.items()
             if argmax(v) == args.cls and v["class"] != args.cls and not unlabelled(v)}
    if not group:
        print("no super-point with argmax class %d ends with another class" % args.cls)
        return
    final = {i: v["class"] for i, v in vertices.items()}
    kept = dict(final)
    kept.update({i: args.cls for i in group})
    gain = sum(unary(vertices[i], final[i]) - unary(vertices[i], args.cls) for i in group)
    rows = []  # (extra cost, neighbour) per link that costs more when the group keeps its class
    for e in edges:
        a, b = e["a"], e["b"]
        if a not in group and b not in group:
            continue
        va, vb = vertices[a], vertices[b]
        extra = (pairwise(va, vb, e, kept[a], kept[b]) - pairwise(va, vb, e, final[a], final[b]))
        if extra > 0:
            rows.append((extra, vb if a in group else va))
    cost = sum(r[0] for r in rows)
    sizes = sorted(vertices[i]["voxels"] for i in group)
    print("%d super-points (%d voxels, %d-%d each) have argmax class %d and end as %s" % (
        len(group), sum(sizes), sizes[0], sizes[-1], args.cls,
        ", ".join("%d x %d" % (n, c) for c, n in sorted(
            {c: sum(1 for i in group if final[i] == c) for c in {final[i] for i in group}}
            .items()))))
    print("keeping class %d: unary gain %.1f, pairwise cost %.1f over %d links (%s)" % (
        args.cls, gain, cost, len(rows), "kept" if gain > cost else "relabelled"))
    if cost > 0:
        for limit in (6, 24, 100):
            part = sum(r[0] for r in rows if r[1]["voxels"] <= limit)
            print("  from neighbours of <= %d voxels: %.0f %%" % (limit, 100 * part / cost))
        for limit in (2, 5, 10):
            part = sum(r[0] for r in rows if observations(r[1]) < limit)
            print("  from neighbours observed < %d times per voxel: %.0f %%" % (
                limit, 100 * part / cost))


if __name__ == "__main__":
    main()
