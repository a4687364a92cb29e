#!/usr/bin/env python3
"""A scene larger than the shipped one through the real-scene path: a multi-room procedural
floor (`panmap-synth --building`) written as a ScanNet scene folder of the current release
(to_scannet_layout.py), rendered with `panmap-synth --scannet` as the accuracy suite renders
a downloaded scene (m2f masks unless --masks adds others, ground-truth poses, 5 Hz, the
whole survey walked: --cover-walk), mapped with every method variant at 2 cm and scored as
the suite scores (suite.py). Once with the default survey stops (one per 6 m2 of free floor
beyond 10), once with 10 stops whatever the floor (`--area-per-stop 0`, the rule before
2026-12-06) and once with one per 3 m2.
Writes docs/LARGE_FLOOR.md; about 25 minutes on 2 cores with the defaults.

  scripts/bench/large_floor.py [--building 7] [--rooms 4] [--area 150] [--seed 1]
                               [--stops-area 6,3,0] [--annotations annotated,empty]
                               [--masks m2f[,clean]] [--config FILE]
                               [--work build/large_floor] [--jobs 2] [--out docs/LARGE_FLOOR.md]
                               [--report-only]
"""
import argparse
import collections
import concurrent.futures
import datetime
import json
import os
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import suite  # noqa: E402  (same folder)

ANNOTATIONS = {"annotated": "annotated", "painted": "25 % unannotated, painted",
               "empty": "25 % unannotated, empty"}
VARIANTS = ["full", "w/o III-B", "w/o III-C", "w/o III-D", "Voxblox++-like"]


def scene_dir(args):
    return os.path.join(args.work, "scenes", "scene%04d_00" % (900 + args.building))


def make_scene(args):
    """Renders the floor's ground truth once and writes it as a ScanNet scene folder."""
    scene = scene_dir(args)
    if os.path.exists(os.path.join(scene, os.path.basename(scene) + ".aggregation.json")):
        return scene
    floor = os.path.join(args.work, "floor")
    suite.run([suite.tool("panmap-synth"), "-q", "--building", str(args.building),
               "--building-rooms", str(args.rooms), "--building-area", str(args.area),
               "--room-style", "scannet", "--frames", "1", "--poses", "gt", "--out", floor])
    suite.run([sys.executable, os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                            "to_scannet_layout.py"),
               os.path.join(floor, "gt", "mesh.ply"), scene, os.path.basename(scene),
               suite.SCANNET_LABELS])
    return scene


def run_one(args, scene, stops_area, annotation, masks):
    """Renders, maps (every variant) and scores the floor with one stop rule, annotation and
    mask preset."""
    spec = suite.Spec("scannet", scene, args.seed, "gt", masks, ANNOTATIONS[annotation], "all",
                      600)
    seq = os.path.join(args.work, "seq", "%s_stops%g" % (spec.name(), stops_area))
    if not os.path.exists(os.path.join(seq, "info.json")):
        suite.run([suite.tool("panmap-synth"), "-q", "--out", seq] + spec.synth_args() +
                  ["--area-per-stop", "%g" % stops_area])
    suite.map_sequence(args.work, seq, spec, 0.02, args.config, variants=VARIANTS)
    os.remove(os.path.join(seq, "sequence.lcmlog"))  # 0.5-1.3 GB each; the scores are kept
    os.rename(os.path.join(seq, "info.json"), os.path.join(seq, "info.json.done"))
    return row(args, stops_area, annotation, masks)


# Where map_sequence leaves each variant's scores (runs/SEQUENCE/FOLDER/eval.json).
FOLDERS = {"full": "A", "w/o III-B": "wo_III-B", "w/o III-C": "wo_III-C",
           "w/o III-D": "wo_III-D", "Voxblox++-like": "V"}


def row(args, stops_area, annotation, masks):
    """One table row from what a run left on disk (None when it has not run)."""
    spec = suite.Spec("scannet", scene_dir(args), args.seed, "gt", masks,
                      ANNOTATIONS[annotation], "all", 600)
    name = "%s_stops%g" % (spec.name(), stops_area)
    info_path = os.path.join(args.work, "seq", name, "info.json.done")
    if not os.path.exists(info_path):
        return None
    with open(info_path) as f:
        info = json.load(f)
    results = {}
    for v in VARIANTS:
        with open(os.path.join(args.work, "runs", name, FOLDERS[v], "eval.json")) as f:
            results[v] = json.load(f)
    full = results["full"]
    return {"stops_area": stops_area, "annotation": annotation, "masks": masks,
            "frames": info["frames"],
            "stops": info["trajectory"]["stops"],
            "free_area_m2": info["trajectory"]["free_area_m2"],
            "walk_m": info["trajectory"]["walk_length_m"],
            "seen3": info["coverage"]["seen_from_3_views"],
            "things": info["coverage"]["thing_instances"],
            "map50": {v: 100 * (results[v]["map50"] or 0) for v in VARIANTS},
            "pq50": 100 * (full["pq50"] or 0), "miou": 100 * (full["miou_gt_classes"] or 0),
            "objects": full["diagnostics"]["num_objects"],
            "gt_things": full["diagnostics"]["num_gt_things"],
            "misses": dict(collections.Counter(
                g["cause"] for g in full["diagnostics"]["gt_things"]))}


def report(args, rows, meta):
    def rule(a):
        return "10 stops (`--area-per-stop 0`)" if a == 0 else "one per %g m2 (default)" % a \
            if a == 6 else "one per %g m2" % a
    lines = [
        "# A larger scene through the real-scene path", "",
        "Generated by `scripts/bench/large_floor.py` (do not edit by hand) on %s, maps of commit "
        "`%s`, %s, %d cores, in %.1f minutes." % (
            meta["date"], meta["commit"], meta["cpu"], meta["cores"], meta["minutes"]), "",
        "Command: `%s`" % meta["command"], "",
        "The shipped real scene (scene0470) has 2.7 m2 of floor to walk at 0.3 m from its "
        "surfaces; real ScanNet scenes reach 50-100 m2 and several rooms. This floor "
        "(`panmap-synth --building %d --building-rooms %d --building-area %g --room-style "
        "scannet`: ScanNet-like rooms off a corridor, doors open) is written as a ScanNet scene "
        "folder (`to_scannet_layout.py`: ScanNet ids in labels.ply, raw categories in the "
        "aggregation) and goes the way a downloaded scene goes in `accuracy.sh --scannet`: "
        "rendered along a survey of the mesh (seed %d, 5 Hz, masks of the row's preset, "
        "ground-truth poses, "
        "every frame the walk needs: `--cover-walk`), mapped at 2 cm with every variant, scored "
        "by panmap-eval. What changes between rows is how many stops the survey spreads over "
        "the free floor (docs/SIMULATION.md, \"Trajectories\")." % (
            args.building, args.rooms, args.area, args.seed), "",
        "| survey stops | annotation | masks | stops | free floor m2 | walk m | frames | things "
        "seen from 3 views | full | w/o III-B | w/o III-C | w/o III-D | Voxblox++-like | full - "
        "Voxblox++-like | PQ50 | mIoU | objects / GT things | GT things missed unobserved / "
        "partly observed / other |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        m = r["misses"]
        other = sum(v for k, v in m.items() if k not in ("matched", "unobserved",
                                                         "partly observed"))
        lines.append(
            "| %s | %s | `%s` | %d | %.0f | %.0f | %d | %d of %d | %s | %.1f | %.1f | %.1f | "
            "%d / %d | %d / %d / %d |" % (
                rule(r["stops_area"]), ANNOTATIONS[r["annotation"]], r.get("masks", "m2f"),
                r["stops"],
                r["free_area_m2"], r["walk_m"], r["frames"], r["seen3"], r["things"],
                " | ".join("%.1f" % r["map50"][v] for v in VARIANTS),
                r["map50"]["full"] - r["map50"]["Voxblox++-like"], r["pq50"], r["miou"],
                r["objects"], r["gt_things"], m.get("unobserved", 0),
                m.get("partly observed", 0), other))
    lines += ["", "Columns full to Voxblox++-like: mAP50. A GT thing is **unobserved** when at "
              "most half of its surface found a mapped vertex within 5 cm (docs/RESULTS.md, "
              "\"Why GT objects are missed\"): no labelling can match it, so the rows with "
              "fewer stops measure the survey more than the mapping. A row with `clean` masks maps "
              "the same survey without the network's errors (docs/SIMULATION.md): what the "
              "method reaches when the masks are right, the ceiling for its `m2f` row.", ""]
    return lines


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--building", type=int, default=7, help="building seed")
    parser.add_argument("--rooms", type=int, default=4)
    parser.add_argument("--area", type=float, default=150.0, help="floor area, m2, at least")
    parser.add_argument("--seed", type=int, default=1, help="survey, noise and mask seed")
    parser.add_argument("--stops-area", default="6,3,0",
                        help="panmap-synth --area-per-stop values, comma-separated")
    parser.add_argument("--annotations", default="annotated,empty",
                        help="annotated, painted, empty (25 %% unannotated), comma-separated")
    parser.add_argument("--masks", default="m2f",
                        help="mask presets (m2f, clean, hard), comma-separated: clean masks "
                             "show what the network's errors cost")
    parser.add_argument("--config", default="",
                        help="YAML config for every mapper run (panmap-mapper --config)")
    parser.add_argument("--work", default=os.path.join(suite.BUILD, "large_floor"))
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--out", default=os.path.join(suite.ROOT, "docs", "LARGE_FLOOR.md"))
    parser.add_argument("--report-only", action="store_true",
                        help="write the report from the runs WORK holds, mapping nothing")
    args = parser.parse_args()
    if args.config:
        if not os.path.isfile(args.config):
            sys.exit("large_floor: no config file '%s'" % args.config)
        args.config = os.path.abspath(args.config)
    annotations = [a for a in args.annotations.split(",") if a]
    for a in annotations:
        if a not in ANNOTATIONS:
            sys.exit("large_floor: unknown annotation '%s' (annotated, painted, empty)" % a)
    start = time.time()
    masks = [m for m in args.masks.split(",") if m]
    for m in masks:
        if m not in ("m2f", "clean", "hard"):
            sys.exit("large_floor: unknown mask preset '%s' (m2f, clean, hard)" % m)
    jobs = [(float(s), a, m) for s in args.stops_area.split(",") for a in annotations
            for m in masks]
    if args.report_only:
        rows = [r for r in (row(args, s, a, m) for s, a, m in jobs) if r is not None]
        if not rows:
            sys.exit("large_floor: no runs in %s to report" % args.work)
    else:
        subprocess.run(["cmake", "--build", suite.BUILD, "--target", "panmap-synth",
                        "panmap-mapper", "panmap-eval"], check=True, stdout=subprocess.DEVNULL)
        scene = make_scene(args)
        with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
            futures = [pool.submit(run_one, args, scene, s, a, m) for s, a, m in jobs]
            rows = []
            for f in futures:
                rows.append(f.result())
                r = rows[-1]
                print("large_floor: %g m2 a stop, %s, %s masks: %d stops, full mAP50 %.1f, "
                      "Voxblox++-like %.1f" % (r["stops_area"], r["annotation"], r["masks"],
                                               r["stops"],
                                               r["map50"]["full"], r["map50"]["Voxblox++-like"]),
                      file=sys.stderr, flush=True)
    meta_path = os.path.join(args.work, "meta.json")
    if args.report_only:
        with open(meta_path) as f:
            meta = json.load(f)
    else:
        meta = {"date": datetime.date.today().isoformat(), "commit": suite.git_commit(),
                "cpu": suite.cpu_name(), "cores": os.cpu_count() or 0,
                "minutes": (time.time() - start) / 60.0,
                "command": ("scripts/bench/large_floor.py " + " ".join(sys.argv[1:])).strip()}
        with open(meta_path, "w") as f:
            json.dump(meta, f)
    lines = report(args, rows, meta)
    with open(args.out, "w") as f:
        f.write("\n".join(lines))
    print("large_floor: wrote %s" % args.out, file=sys.stderr)


if __name__ == "__main__":
    main()
