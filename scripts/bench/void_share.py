#!/usr/bin/env python3
"""How well the share of frames without a mask (optimiser.max_void_share) separates surface the
ground truth leaves unannotated from annotated surface: for a map built with ground-truth poses,
counts the ground-truth vertices (class 0 = unannotated) nearest to the predicted mesh's vertices
by the void share of the super-point each predicted vertex belongs to.

  panmap-mapper --export-only --load MAP --out DIR --graph-json GRAPH
  python3 scripts/bench/void_share.py GRAPH DIR/mesh_instance.ply SEQ/gt/mesh.ply
"""
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from surface_distance import load_vertices, nearest  # noqa: E402  (same folder)

BINS = [0.0, 0.5, 0.7, 0.8, 0.9, 0.95]


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    try:
        with open(sys.argv[1]) as f:
            share = {v["id"]: v["void_share"] for v in json.load(f)["vertices"]}
        pred = load_vertices(sys.argv[2])
        gt = load_vertices(sys.argv[3])
    except (OSError, ValueError, KeyError) as e:
        sys.exit("void_share: %s" % e)
    xyz = lambda vs: [(v["x"], v["y"], v["z"]) for v in vs]  # noqa: E731
    counts = [[0, 0] for _ in BINS]  # per bin: annotated, unannotated GT vertices
    for v, (j, _) in zip(pred, nearest(xyz(pred), xyz(gt), cap=0.05)):
        if j is None or v["superpoint"] not in share:
            continue
        b = max(i for i, lo in enumerate(BINS) if share[v["superpoint"]] >= lo)
        counts[b][gt[j]["semantic"] == 0] += 1
    print("| void share | annotated GT vertices | unannotated GT vertices |")
    print("|---|---:|---:|")
    for i, lo in enumerate(BINS):
        hi = BINS[i + 1] if i + 1 < len(BINS) else 1.0
        print("| %.2f-%.2f%s | %d | %d |" % (lo, hi, "" if i + 1 < len(BINS) else " (incl.)",
                                             counts[i][0], counts[i][1]))


if __name__ == "__main__":
    main()
