#!/usr/bin/env python3
"""The accuracy suite's noise floor: how much a score moves when nothing that should matter
changes. Every run of docs/RESULTS.md (same sequences, the full
method as the suite maps it) is mapped twice: as given, and with every pose moved by a
fraction of a voxel (`panmap-mapper --grid-shift`), which puts the voxel boundaries elsewhere
on the same surfaces and leaves everything else (frames, masks, the method) as it was. Both
maps are scored after the rigid alignment of their trajectories to the ground truth (which
removes the shift exactly). Writes docs/NOISE_FLOOR.md: per run, mAP50 and mIoU of both, and
every ground-truth object whose outcome changed. A difference between two methods that stays
within these figures is not evidence for either. About 15 minutes on 2 cores with the suite's
sequences kept (`accuracy.sh --keep-logs`); missing sequences are rendered first.

  scripts/bench/noise_floor.py [--shift 0.35,0.55,0.65] [--seeds 1,2] [--scannet-like 31,32,33]
                               [--rooms 3,4,5] [--report-only]
                               [--work build/noise_floor] [--sequences build/accuracy]
"""
import argparse
import concurrent.futures
import datetime
import json
import os
import shutil
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import accuracy  # noqa: E402  (same folder)
from accuracy import pct  # noqa: E402
import suite  # noqa: E402


def mapper_args(spec, voxel_m):
    """The suite's mapper command for the full method of a spec (suite.map_sequence)."""
    args = [suite.tool("panmap-mapper"), "-q", "--voxel-size", str(voxel_m), "--threads", "1",
            "--no-snapshots"]
    # "all" maps drifting poses as given for the variants; the full method as a user runs it
    # (the first column of the report) is the default tracking whenever poses drift.
    if spec.poses == "gt":
        args += ["--tracking", "off"]
    return args


def map_and_score(spec, seq_dir, out, shift_m, voxel_m):
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    cmd = mapper_args(spec, voxel_m) + ["--log", os.path.join(seq_dir, "sequence.lcmlog"),
                                        "--out", out]
    if shift_m:
        cmd += ["--grid-shift", ",".join("%.6f" % s for s in shift_m)]
    suite.run(cmd, os.path.join(out, "commands.log"))
    result = suite.evaluate(out, seq_dir, voxel_m, os.path.join(out, "trajectory.txt"))
    suite.drop_map(out)
    return result


def outcome(thing):
    return "%s %.2f" % (thing["cause"], thing["best_same_class_iou"])


def changed_things(a, b):
    before = {t["instance_id"]: t for t in a["diagnostics"]["gt_things"]}
    rows = []
    for t in b["diagnostics"]["gt_things"]:
        old = before.get(t["instance_id"])
        if old and (old["cause"] == "matched") != (t["cause"] == "matched"):
            rows.append((t["instance_id"], t["class_id"], t["vertices"], outcome(old),
                         outcome(t)))
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--shift", default="0.35,0.55,0.65",
                        help="grid shift in voxels along x, y, z")
    parser.add_argument("--seeds", default=",".join(map(str, accuracy.REPORT_SEEDS)))
    parser.add_argument("--scannet-like", default=",".join(map(str, accuracy.REPORT_SCANNET_LIKE)))
    parser.add_argument("--rooms", default=",".join(map(str, accuracy.REPORT_ROOMS)))
    parser.add_argument("--scannet", nargs="*", default=None, metavar="DIR")
    parser.add_argument("--frames-scannet", type=int, default=600)
    parser.add_argument("--frames-like", type=int, default=600)
    parser.add_argument("--frames-room", type=int, default=450)
    parser.add_argument("--voxel-size", type=float, default=0.02)
    parser.add_argument("--work", default=os.path.join(suite.BUILD, "noise_floor"))
    parser.add_argument("--sequences", default=os.path.join(suite.BUILD, "accuracy"),
                        help="work folder whose seq/ holds (or receives) the rendered sequences")
    parser.add_argument("--out", default=os.path.join(suite.ROOT, "docs", "NOISE_FLOOR.md"))
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 2)
    parser.add_argument("--report-only", action="store_true",
                        help="write the report from the scores of the last run in --work")
    args = parser.parse_args()
    start = time.time()
    shift_vox = [float(x) for x in args.shift.split(",")]
    if len(shift_vox) != 3:
        sys.exit("noise_floor: --shift needs three values")
    shift_m = [s * args.voxel_size for s in shift_vox]
    seeds = [int(s) for s in args.seeds.split(",") if s]
    like = [int(r) for r in args.scannet_like.split(",") if r]
    for name in ("panmap-mapper", "panmap-synth", "panmap-eval"):
        if not os.access(suite.tool(name), os.X_OK):
            sys.exit("noise_floor: %s is not built (scripts/setup.sh)" % suite.tool(name))
    dirs = suite.scene_dirs(args.scannet)
    specs = accuracy.real_specs(dirs, seeds, args.frames_scannet)
    specs += accuracy.like_specs(like, args.frames_like)
    specs += accuracy.weaker_specs(dirs, seeds, like, args.frames_scannet, args.frames_like)
    specs += accuracy.room_specs([int(r) for r in args.rooms.split(",") if r], args.frames_room)

    def load(folder):
        with open(os.path.join(folder, "eval.json")) as f:
            return json.load(f)

    def job(spec):
        if args.report_only:
            return (load(os.path.join(args.work, "given", spec.name())),
                    load(os.path.join(args.work, "shifted", spec.name())))
        seq = suite.render(args.sequences, spec)
        base = map_and_score(spec, seq, os.path.join(args.work, "given", spec.name()), None,
                             args.voxel_size)
        moved = map_and_score(spec, seq, os.path.join(args.work, "shifted", spec.name()),
                              shift_m, args.voxel_size)
        print("noise_floor: %s: mAP50 %s -> %s" % (spec.name(), pct(base["map50"]),
                                                   pct(moved["map50"])),
              file=sys.stderr, flush=True)
        return base, moved
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        results = list(pool.map(job, specs))

    # What the maps were made with and how long it took: kept beside them for --report-only.
    run_file = os.path.join(args.work, "run.json")
    if args.report_only:
        with open(run_file) as f:
            made = json.load(f)
    else:
        made = {"version": accuracy.code_version(), "minutes": (time.time() - start) / 60}
        with open(run_file, "w") as f:
            json.dump(made, f)
    rows, diffs, miou_diffs, all_diffs, changes = [], [], [], [], []
    for spec, (a, b) in zip(specs, results):
        d = 100 * ((b["map50"] or 0) - (a["map50"] or 0))
        diffs.append(d)
        miou_diffs.append(100 * (b["miou_gt_classes"] - a["miou_gt_classes"]))
        all_diffs.append(100 * (b["miou"] - a["miou"]))
        rows.append("| %s | %s | %s | %+.1f | %s | %s | %s | %s | %d / %d |" % (
            spec.name(), pct(a["map50"]), pct(b["map50"]), d, pct(a["miou_gt_classes"]),
            pct(b["miou_gt_classes"]), pct(a["miou"]), pct(b["miou"]), a["spurious_classes"],
            b["spurious_classes"]))
        changes += [(spec.name(),) + c for c in changed_things(a, b)]

    def spread(values):
        mags = sorted(abs(v) for v in values)
        return "mean |difference| %.1f, largest %.1f, %d of %d runs changed" % (
            sum(mags) / len(mags), mags[-1], sum(1 for v in mags if v > 0.05), len(mags))
    near = sum(1 for c in changes
               if abs(float(c[4].split()[-1]) - 0.5) < 0.05 and
               abs(float(c[5].split()[-1]) - 0.5) < 0.05)
    md = ["# Noise floor of the accuracy suite", "",
          "Generated by `scripts/bench/noise_floor.py` (do not edit by hand) on %s, maps of "
          "commit %s, in %.1f minutes." % (datetime.date.today().isoformat(),
                                             made["version"], made["minutes"]), "",
          "Command: `scripts/bench/noise_floor.py --shift %s`" % args.shift, "",
          "Every run of docs/RESULTS.md (the same sequences: the real scene's seeds %s, "
          "ScanNet-like rooms %s, box rooms %s, %g cm voxels; `m2f`, clean and `hard` masks; "
          "ground-truth, `slam` and `slam-hard` poses), the full method "
          "mapped as the suite maps it, twice: with the poses as given, and with every pose "
          "moved by (%s) voxels (`panmap-mapper --grid-shift`), so the voxel boundaries fall "
          "elsewhere on the same surfaces while the frames, the masks and the method stay as "
          "they were. Both are scored after the rigid alignment of their trajectory to the "
          "ground truth (`panmap-eval --align-pred`), which removes the shift. Neither map is "
          "better: what differs between them is the noise floor of a comparison of two "
          "methods on these runs." % (args.seeds, args.scannet_like, args.rooms,
                                      100 * args.voxel_size, args.shift), "",
          "It applies to comparisons of two maps: w/o III-B and the Voxblox++-like baseline "
          "(maps of their own), other pose sources, `integrator.vote_stride_px` "
          "(docs/VOTE_STRIDE.md), a repaired map against the map from ground-truth poses "
          "(docs/LOOP_CLOSURE.md). It does not apply to w/o III-C and w/o III-D: the suite "
          "exports them from the full method's own map (`panmap-mapper --export-only --load`), "
          "so they differ from it in the final optimisation alone.", "",
          "Over the %d runs: **mAP50** %s; **mIoU** %s; **mIoU counting absent classes** %s." % (
              len(specs), spread(diffs), spread(miou_diffs), spread(all_diffs)), "",
          "mIoU is over the classes the scene's ground truth has (as docs/RESULTS.md reports "
          "it); *all classes* also counts, with IoU 0, every evaluated class predicted on "
          "ground-truth vertices where the ground truth has none (ScanNet's script, meant for "
          "a whole dataset, applied to one scene); *spurious*: how many such classes.", "",
          "| run | mAP50 given | shifted | difference | mIoU given | shifted | all classes "
          "given | shifted | spurious given / shifted |",
          "|---|---:|---:|---:|---:|---:|---:|---:|---|"] + rows
    md += ["", "## Ground-truth objects whose outcome changed", "",
           "Matched (an object of its class with IoU > 0.5) in one map and not in the other; "
           "cause as docs/RESULTS.md's miss analysis names it, with the best IoU of an object "
           "of its class.", "",
           "| run | GT instance | class | vertices | given | shifted |",
           "|---|---:|---:|---:|---|---|"]
    md += ["| %s | %d | %d | %d | %s | %s |" % c for c in changes] or ["| none | | | | | |"]
    md += ["", "%d changes; %d of them have the best IoU within 0.05 of the 0.5 threshold "
           "in both maps." % (len(changes), near), ""]
    with open(args.out, "w") as f:
        f.write("\n".join(md))
    print("noise_floor: wrote %s in %.1f minutes" % (args.out, (time.time() - start) / 60),
          file=sys.stderr)


if __name__ == "__main__":
    main()
