#!/usr/bin/env python3
"""Prints the Markdown table of panmap's integration stage against Open3D's, from the JSON
files scripts/bench/speed.sh leaves in its work folder:
  ours_<input>_<voxel>_<threads>.json     (panmap-bench-mapping --json)
  open3d_<input>_<voxel>_<threads>.json   (panmap-bench-open3d --json)
Usage: open3d_ratio.py WORK_DIR OPEN3D_BUILT(0|1)"""
import glob
import json
import os
import sys

NAMES = {"7scenes": "7scenes-200", "room1": "synthetic room 1"}


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    work, built = sys.argv[1], sys.argv[2] == "1"
    rows = []
    for path in sorted(glob.glob(os.path.join(work, "ours_*.json"))):
        _, name, voxel, threads = os.path.basename(path)[:-5].split("_")
        with open(path) as f:
            ours = json.load(f)["stages"]["integration"]
        other = os.path.join(work, "open3d_%s_%s_%s.json" % (name, voxel, threads))
        if built and os.path.exists(other):
            with open(other) as f:
                o3d = json.load(f)
            theirs = o3d["integration"]
            ratio = theirs["median_ms"] / ours["median_ms"]
            o3d_cell = "%.1f / %.1f" % (theirs["median_ms"], theirs["p95_ms"])
            ratio_cell = "**%.1fx**" % ratio
        else:
            o3d_cell, ratio_cell = "not measured", "-"
        rows.append((NAMES.get(name, name), float(voxel), int(threads),
                     "%.1f / %.1f" % (ours["median_ms"], ours["p95_ms"]), o3d_cell, ratio_cell))
    print("| input | voxel | threads | panmap integration | Open3D Integrate | ratio |")
    print("|---|---|---|---|---|---|")
    for name, voxel, threads, ours, theirs, ratio in sorted(rows):
        print("| %s | %.0f cm | %d | %s | %s | %s |" % (name, voxel * 100, threads, ours, theirs,
                                                       ratio))
    if not built:
        print("\nOpen3D was not available (libopen3d-dev could not be installed or built).")


if __name__ == "__main__":
    main()
