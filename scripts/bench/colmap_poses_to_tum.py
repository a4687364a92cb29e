#!/usr/bin/env python3
"""Converts poses in COLMAP's convention (one image per line: NAME qw qx qy qz tx ty tz [...],
world-to-camera, p_cam = R(q) p_world + t) into a TUM trajectory (t tx ty tz qx qy qz qw,
camera-to-world) that panmap-eval --gt-traj reads, e.g. the structure-from-motion pseudo
ground truth that Brachmann et al. (ICCV 2021, github.com/tsattler/visloc_pseudo_gt_limitations,
pgt/sfm/7scenes/*.txt) publish for 7-Scenes: a reference for 7-Scenes trajectories that does not
come from depth tracking, as the recorded KinectFusion poses do.

The time stamp of a line is its frame number (the digits after FRAME_PREFIX in the name, minus
--first) divided by --rate-hz, the source's frame rate, as panmap-import stamps 7-Scenes frames
by their number at 30 Hz; --stride keeps every stride-th frame (7scenes-200 holds every 3rd).

  colmap_poses_to_tum.py IN OUT [--select seq-01/] [--rate-hz 30] [--stride 1]
                                [--frame-prefix frame-] [--first 0]
"""
import argparse
import math
import re
import sys


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("input")
    parser.add_argument("output")
    parser.add_argument("--select", default="", help="keep lines whose name starts with this")
    parser.add_argument("--rate-hz", type=float, default=30.0, help="the source's frame rate")
    parser.add_argument("--stride", type=int, default=1,
                        help="keep frames whose number is a multiple of this")
    parser.add_argument("--first", type=int, default=0, help="source frame number of its frame 0")
    parser.add_argument("--frame-prefix", default="frame-")
    args = parser.parse_args()
    if args.rate_hz <= 0 or args.stride <= 0:
        sys.exit("colmap_poses_to_tum: --rate-hz and --stride must be > 0")
    number = re.compile(re.escape(args.frame_prefix) + r"(\d+)")
    rows = []
    try:
        lines = open(args.input).read().splitlines()
    except OSError as e:
        sys.exit("colmap_poses_to_tum: cannot read %s: %s" % (args.input, e.strerror))
    for line_no, line in enumerate(lines, 1):
        fields = line.split()
        if not fields or fields[0].startswith("#") or not fields[0].startswith(args.select):
            continue
        m = number.search(fields[0])
        try:
            qw, qx, qy, qz, tx, ty, tz = (float(v) for v in fields[1:8])
        except ValueError:
            m = None
        if not m or len(fields) < 8:
            sys.exit("colmap_poses_to_tum: %s:%d: expected NAME qw qx qy qz tx ty tz with a "
                     "frame number after '%s'" % (args.input, line_no, args.frame_prefix))
        frame = int(m.group(1)) - args.first
        if frame < 0 or frame % args.stride:
            continue
        n = math.sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
        if not n > 0:
            sys.exit("colmap_poses_to_tum: %s:%d: zero quaternion" % (args.input, line_no))
        qw, qx, qy, qz = qw / n, qx / n, qy / n, qz / n
        r = [[1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qw * qz), 2 * (qx * qz + qw * qy)],
             [2 * (qx * qy + qw * qz), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qw * qx)],
             [2 * (qx * qz - qw * qy), 2 * (qy * qz + qw * qx), 1 - 2 * (qx * qx + qy * qy)]]
        t = (tx, ty, tz)
        # Camera centre -R^T t; the camera-to-world rotation R^T is the conjugate quaternion.
        centre = [-sum(r[j][i] * t[j] for j in range(3)) for i in range(3)]
        stamp = frame / args.rate_hz
        rows.append((stamp, centre, (-qx, -qy, -qz, qw)))
    if not rows:
        sys.exit("colmap_poses_to_tum: no pose in %s matches --select '%s'" % (args.input,
                                                                            args.select))
    rows.sort(key=lambda row: row[0])
    with open(args.output, "w") as out:
        out.write("# timestamp tx ty tz qx qy qz qw\n")
        for stamp, c, q in rows:
            out.write("%.6f %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n" % ((stamp,) + tuple(c) + q))
    print("colmap_poses_to_tum: %d poses -> %s" % (len(rows), args.output), file=sys.stderr)


if __name__ == "__main__":
    main()
