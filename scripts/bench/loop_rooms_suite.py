#!/usr/bin/env python3
"""Loop-closure repair on several rendered rooms and seeds (issue 22), as one table.

Runs scripts/bench/loop_rooms.sh for every ROOM:SEED pair with the given drift, then writes
a section of docs/LOOP_CLOSURE.md (between its loop-suite markers): per run, mAP50, surface
distance to the ground-truth mesh and occupancy agreement of the ground-truth-pose map and
of the repaired one, the GT objects matched by each, and every GT object whose outcome
differs between the two, with its best IoU. About 2.5 minutes per run on 2 cores.

With --reintegrate-also each run is also repaired by re-integration only (the pixel labels of
the first mapping, `panmap-mapper --repair-reintegrate-only`) and the section written is
another one (between its loop-reintegration markers): the map from ground-truth poses, the
repair that maps the frames again and the re-integration side by side, with the correction's
largest move, and every GT object whose outcome differs between the two repairs: what mapping
the frames again buys over the cheaper re-integration. --report-only writes either section
from the run folders loop_rooms.sh left, without running anything.

With --ids the section written is the one between the loop-ids markers: per run, the ids the
repair kept (its report line: instances and super-points, by count and by share of the depth
samples) and, from the drifted and repaired maps' graphs (`object_ids.py`), the objects that
keep the id of their counterpart, the graph's super-points that keep an id with the share of
their voxels, the drifted graph's edges between those super-points that the repaired graph
has, and of the edges kept and of those lost, how many the map from ground-truth poses has
too. --ids --report-only writes it from the run folders (a run from before loop_rooms.sh wrote
the ground-truth-pose graph gets it from that map's file, `panmap-mapper --export-only`).

  python3 scripts/bench/loop_rooms_suite.py [--runs 3:3,3:4,3:5,4:3,5:3] [--poses heavy]
                                            [--reintegrate-also | --ids] [--report-only]
                                            [--out docs/LOOP_CLOSURE.md] [--no-write]

A run is ROOM:SEED, or ROOM:SEED:STYLE:FRAMES for loop_rooms.sh's --style and --frames.
"""
import argparse
import datetime
import json
import os
import re
import subprocess
import sys
import tempfile
import time

import doc_section  # same folder
import object_ids  # same folder

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BEGIN = "<!-- loop-suite:begin (scripts/bench/loop_rooms_suite.py) -->"
END = "<!-- loop-suite:end -->"
BEGIN_REINTEGRATION = ("<!-- loop-reintegration:begin (scripts/bench/loop_rooms_suite.py "
                       "--reintegrate-also) -->")
END_REINTEGRATION = "<!-- loop-reintegration:end -->"
BEGIN_IDS = "<!-- loop-ids:begin (scripts/bench/loop_rooms_suite.py --ids) -->"
END_IDS = "<!-- loop-ids:end -->"
IDS = re.compile(r"ids kept: (\d+) of (\d+) instances \(([0-9]+) % of the surface\), (\d+) of "
                 r"(\d+) super-points \(([0-9]+) %\)")
REPAIR = re.compile(r"in ([0-9.]+) s, largest move ([0-9.]+) m")
LINE = re.compile(r"^(gt_poses|drifted|repaired): mAP50 ([0-9.]+);(?: purity [0-9.]+;)? "
                  r"mean ([0-9.]+) cm.*agree on ([0-9.]+) % of")


def work_folder(room, seed, poses):
    """The folder loop_rooms.sh maps a run in."""
    return os.path.join(ROOT, "build", "loop_rooms", "room%s-seed%s-%s" % (room, seed, poses))


def run_one(room, seed, poses, style=None, frames=None, reintegrate_also=False):
    """Runs loop_rooms.sh once; returns its figures per map and the work folder."""
    cmd = ["bash", "scripts/bench/loop_rooms.sh", "--room", str(room), "--seed", str(seed),
           "--poses", poses]
    if style:
        cmd += ["--style", style]
    if frames:
        cmd += ["--frames", str(frames)]
    if reintegrate_also:
        cmd.append("--reintegrate-also")
    out = subprocess.run(cmd, cwd=ROOT, check=True, capture_output=True, text=True).stdout
    figures = {}
    repair = ""
    for line in out.splitlines():
        m = LINE.match(line)
        if m:
            figures[m.group(1)] = {"map50": float(m.group(2)), "surface_cm": float(m.group(3)),
                                   "occupancy": float(m.group(4))}
        elif line.startswith("repair:"):
            repair = line
    if set(figures) != {"gt_poses", "drifted", "repaired"}:
        sys.exit("loop_rooms_suite: loop_rooms.sh printed no figures for room %s seed %s:\n%s"
                 % (room, seed, out))
    return figures, repair, work_folder(room, seed, poses)


def read_json(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError) as e:
        sys.exit("loop_rooms_suite: cannot read %s: %s" % (path, e))


def gt_things(path):
    return {t["instance_id"]: t for t in read_json(path)["diagnostics"]["gt_things"]}


def repair_of(work, name):
    """(seconds, largest move in m) of the one repair in a map's report.json."""
    repairs = read_json(os.path.join(work, name, "report.json"))["corrections"]["repairs"]
    m = REPAIR.search(repairs[0]) if len(repairs) == 1 else None
    if not m:
        sys.exit("loop_rooms_suite: %s/%s made no single repair: %s" % (work, name, repairs))
    return float(m.group(1)), float(m.group(2))


def generated_by(args, flag, minutes):
    """How a section was made: the command, the date, the commit and where the runs came from."""
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT,
                          capture_output=True, text=True).stdout.strip()
    return ("Generated by `python3 scripts/bench/loop_rooms_suite.py --runs %s --poses %s %s%s` "
            "on %s at commit `%s`%s (do not edit by hand)"
            % (args.runs, args.poses, flag, " --report-only" if args.report_only else "",
               datetime.date.today().isoformat(), head,
               " from the runs loop_rooms.sh left in build/loop_rooms" if args.report_only
               else " in %.1f minutes" % minutes))


def reintegration_section(args, pairs, minutes):
    """The table of ground-truth poses / mapped again / re-integrated, from the run folders."""
    rows, changes = [], []
    totals = [0, 0, 0, 0]
    for room, seed, style, frames in pairs:
        work = work_folder(room, seed, args.poses)
        things = [gt_things(os.path.join(work, m, "eval.json"))
                  for m in ("gt_poses", "repaired", "reintegrated")]
        map50 = [100 * read_json(os.path.join(work, m, "eval.json"))["map50"]
                 for m in ("gt_poses", "repaired", "reintegrated")]
        matched = [sum(t["cause"] == "matched" for t in m.values()) for m in things]
        iou = [sum(t["best_same_class_iou"] for t in m.values()) / len(m) for m in things]
        for i in range(3):
            totals[i] += matched[i]
        totals[3] += len(things[0])
        remap_s, move_m = repair_of(work, "repaired")
        reintegration_s, _ = repair_of(work, "reintegrated")
        info = read_json(os.path.join(work, "drift_seq", "info.json"))
        rows.append("| %s | %s | %s | %d | %.2f | %.3f | %.1f / %.1f / %.1f | %d / %d / %d of %d "
                    "| %.3f / %.3f / %.3f | %.2f / %.2f |" % (
                        room, style or "boxes", seed, info["frames"],
                        100 * info["measured"]["input_ate_rmse_m"], move_m, *map50, *matched,
                        len(things[0]), *iou, remap_s, reintegration_s))
        rep, rei = things[1], things[2]
        for k in sorted(rep):
            if k in rei and rep[k]["cause"] != rei[k]["cause"]:
                changes.append("| %s | %s | %d | %d | %d | %s %.2f | %s %.2f |" % (
                    room, seed, k, rep[k]["class_id"], rep[k]["vertices"], rep[k]["cause"],
                    rep[k]["best_same_class_iou"], rei[k]["cause"],
                    rei[k]["best_same_class_iou"]))
    return "\n".join([
        BEGIN_REINTEGRATION,
        "### Mapping the frames again against re-integrating them",
        "",
        generated_by(args, "--reintegrate-also", minutes) + ": each run of "
        "`scripts/bench/loop_rooms.sh --reintegrate-also` repaired twice from one frame store, "
        "by mapping the frames again (the default) and by re-integration only "
        "(`--repair-reintegrate-only`: each frame votes again for the super-points association "
        "gave it under the drifted poses). Per run: input ATE of the drifted poses, the "
        "correction's largest move of a camera, then for the map from ground-truth poses / "
        "mapped again / re-integrated: mAP50, GT things matched (IoU > 0.5), mean best IoU of a "
        "GT thing with an object of its class; repair seconds mapped again / re-integrated.",
        "",
        "| room | style | seed | frames | input ATE cm | largest move m | mAP50 | GT things "
        "matched | mean best IoU | repair s |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|",
    ] + rows + [
        "",
        "GT things matched over all runs: %d from ground-truth poses, %d mapped again, %d "
        "re-integrated, of %d. Every GT thing whose outcome differs between the two repairs "
        "(cause as `panmap-eval` names it, best IoU with an object of its class):"
        % tuple(totals),
        "",
        "| room | seed | GT thing | class | vertices | mapped again | re-integrated |",
        "|---|---|---:|---:|---:|---|---|",
    ] + (changes or ["| - | - | - | - | - | - | - |"]) + [END_REINTEGRATION])


def reference_graph(work):
    """The graph JSON of the run's map from ground-truth poses, written from its map file when
    the run predates loop_rooms.sh writing it."""
    path = os.path.join(work, "gt_poses", "graph.json")
    if not os.path.exists(path):
        with tempfile.TemporaryDirectory() as out:
            subprocess.run([os.path.join(ROOT, "build", "panmap-mapper"), "-q", "--no-snapshots",
                            "--export-only", "--load",
                            os.path.join(work, "gt_poses", "map.panmap"), "--graph-json", path,
                            "--out", out], cwd=ROOT, check=True, capture_output=True)
    return object_ids.load(path)


def edge_fates(work, before, repaired):
    """object_ids.edges_in_reference() of a run against its ground-truth-pose map."""
    partner = object_ids.partners(
        object_ids.mesh_superpoints(os.path.join(work, "repaired", "mesh_superpoint.ply"), 0.02),
        object_ids.mesh_superpoints(os.path.join(work, "gt_poses", "mesh_superpoint.ply"), 0.02))
    return object_ids.edges_in_reference(before, repaired, reference_graph(work), partner)


def ids_section(args, pairs, minutes):
    """The table of ids kept through each repair, from the run folders."""
    rows = []
    totals = {"kept": [0, 0], "lost": [0, 0]}  # edges in the reference, edges judged
    for room, seed, style, frames in pairs:
        work = work_folder(room, seed, args.poses)
        repairs = read_json(os.path.join(work, "repaired", "report.json"))["corrections"]["repairs"]
        m = IDS.search(repairs[0]) if len(repairs) == 1 else None
        if not m:
            sys.exit("loop_rooms_suite: %s/repaired counted no ids: %s" % (work, repairs))
        before = object_ids.load(os.path.join(work, "drifted", "graph.json"))
        repaired = object_ids.load(os.path.join(work, "repaired", "graph.json"))
        objects = object_ids.compare(object_ids.objects(before, 100),
                                     object_ids.objects(repaired, 100), 0.3)
        vertices, kept, share, edges, kept_edges = object_ids.superpoint_ids(before, repaired)
        info = read_json(os.path.join(work, "drift_seq", "info.json"))
        fates = edge_fates(work, before, repaired)
        def judged(fate):  # edges of this fate whose two ends have distinct partners
            return fates[(fate, "in reference")] + fates[(fate, "not in reference")]
        for fate in ("kept", "lost"):
            totals[fate][0] += fates[(fate, "in reference")]
            totals[fate][1] += judged(fate)
        rows.append("| %s | %s | %s | %.2f | %s of %s (%s %%) | %d of %d | %s of %s (%s %%) | "
                    "%d of %d (%.1f %%) | %d of %d | %d of %d | %d of %d |" % (
                        room, style or "boxes", seed,
                        100 * info["measured"]["input_ate_rmse_m"], m.group(1), m.group(2),
                        m.group(3), objects[1], objects[0], m.group(4), m.group(5), m.group(6),
                        kept, vertices, 100 * share, kept_edges, edges,
                        fates[("kept", "in reference")], judged("kept"),
                        fates[("lost", "in reference")], judged("lost")))
    return "\n".join([
        BEGIN_IDS,
        "### Ids kept through a repair",
        "",
        generated_by(args, "--ids", minutes) + ". Per run of `scripts/bench/loop_rooms.sh`: "
        "input ATE of the drifted poses; the repair's own count of the instances and "
        "super-points that took an old id, with the share of the depth samples that found the "
        "same id in both maps; then, from the graphs of the drifted and the repaired map "
        "(`object_ids.py`, super-points that own surface): repaired objects of at least 100 "
        "voxels that keep the id of their counterpart (same class within 30 cm), of those with "
        "one; graph vertices that keep an id, with the share of the graph's voxels they hold; "
        "the drifted graph's edges between those super-points that the repaired graph has; "
        "then, of those edges the repair kept and of those it lost, how many the graph of the "
        "map from ground-truth poses has too (each repaired super-point paired with the "
        "ground-truth-pose super-point that holds most of its mesh vertices, compared by 2 cm "
        "cell; counted where the two ends have distinct partners).",
        "",
        "| room | style | seed | input ATE cm | instances kept (repair) | objects kept "
        "| super-points kept (repair) | graph vertices kept | edges between them kept "
        "| kept edges the GT-pose graph has | lost edges the GT-pose graph has |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ] + rows + [
        "",
        "Over every run: the map from ground-truth poses has %d of the %d edges the repair kept "
        "(%.0f %%) and %d of the %d it lost (%.0f %%). The edges a repair drops are mostly "
        "co-observations that only the drifted poses made: a mask's pixels fell on a "
        "neighbour's surface where the drift had put it."
        % (totals["kept"][0], totals["kept"][1],
           100.0 * totals["kept"][0] / max(1, totals["kept"][1]),
           totals["lost"][0], totals["lost"][1],
           100.0 * totals["lost"][0] / max(1, totals["lost"][1])),
        END_IDS])


def write_section(path, section, begin, end):
    doc_section.splice(path, section, begin, end)
    print("loop_rooms_suite: wrote %s" % path, file=sys.stderr)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--runs", default="3:3,3:4,3:5,4:3,5:3", help="ROOM:SEED pairs")
    ap.add_argument("--poses", default="heavy", help="drift preset of panmap-synth")
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "LOOP_CLOSURE.md"))
    ap.add_argument("--no-write", action="store_true", help="print the section only")
    ap.add_argument("--reintegrate-also", action="store_true",
                    help="also repair by re-integration only and write that comparison instead")
    ap.add_argument("--ids", action="store_true",
                    help="write the table of ids kept through each repair instead")
    ap.add_argument("--report-only", action="store_true",
                    help="with --reintegrate-also or --ids: write the section from the run "
                         "folders only")
    args = ap.parse_args()
    pairs = [p.split(":") for p in args.runs.split(",") if p]
    if not pairs or any(len(p) not in (2, 4) for p in pairs):
        sys.exit("loop_rooms_suite: --runs takes ROOM:SEED or ROOM:SEED:STYLE:FRAMES, separated "
                 "by commas")
    pairs = [(p[0], p[1], p[2] if len(p) == 4 else None, p[3] if len(p) == 4 else None)
             for p in pairs]
    if args.report_only and not (args.reintegrate_also or args.ids):
        sys.exit("loop_rooms_suite: --report-only needs --reintegrate-also or --ids")
    if args.reintegrate_also and args.ids:
        sys.exit("loop_rooms_suite: --reintegrate-also and --ids write two different sections")
    start = time.time()
    if args.ids:
        if not args.report_only:
            for i, (room, seed, style, frames) in enumerate(pairs):
                print("loop_rooms_suite: run %d/%d, room %s seed %s (%.0f s so far)"
                      % (i + 1, len(pairs), room, seed, time.time() - start), file=sys.stderr)
                run_one(room, seed, args.poses, style, frames)
        section = ids_section(args, pairs, (time.time() - start) / 60)
        print(section)
        if not args.no_write:
            write_section(args.out, section, BEGIN_IDS, END_IDS)
        return
    if args.reintegrate_also:
        if not args.report_only:
            for i, (room, seed, style, frames) in enumerate(pairs):
                print("loop_rooms_suite: run %d/%d, room %s seed %s (%.0f s so far)"
                      % (i + 1, len(pairs), room, seed, time.time() - start), file=sys.stderr)
                run_one(room, seed, args.poses, style, frames, reintegrate_also=True)
        section = reintegration_section(args, pairs, (time.time() - start) / 60)
        print(section)
        if not args.no_write:
            write_section(args.out, section, BEGIN_REINTEGRATION, END_REINTEGRATION)
        return
    rows, changes = [], []
    matched_total = [0, 0]
    for i, (room, seed, style, frames) in enumerate(pairs):
        print("loop_rooms_suite: run %d/%d, room %s seed %s (%.0f s so far)"
              % (i + 1, len(pairs), room, seed, time.time() - start), file=sys.stderr)
        figures, repair, work = run_one(room, seed, args.poses, style, frames)
        gt = gt_things(os.path.join(work, "gt_poses", "eval.json"))
        rep = gt_things(os.path.join(work, "repaired", "eval.json"))
        matched = [sum(t["cause"] == "matched" for t in m.values()) for m in (gt, rep)]
        matched_total[0] += matched[0]
        matched_total[1] += matched[1]
        seconds = re.search(r"in ([0-9.]+) s", repair)
        a, b = figures["gt_poses"], figures["repaired"]
        rows.append("| %s | %s | %.1f / %.1f | %+.1f | %.2f / %.2f | %.2f %% | %d / %d | %s |"
                    % (room, seed, a["map50"], b["map50"], b["map50"] - a["map50"],
                       a["surface_cm"], b["surface_cm"], b["occupancy"], matched[0],
                       matched[1], seconds.group(1) if seconds else "-"))
        for k in sorted(gt):
            if k in rep and gt[k]["cause"] != rep[k]["cause"]:
                changes.append("| %s | %s | %d | %d | %d | %.2f | %s %.3f | %s %.3f |" % (
                    room, seed, k, gt[k]["class_id"], gt[k]["vertices"],
                    gt[k]["observed_share"], gt[k]["cause"], gt[k]["best_same_class_iou"],
                    rep[k]["cause"], rep[k]["best_same_class_iou"]))
    diffs = [float(r.split("|")[4]) for r in rows]
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT,
                          capture_output=True, text=True).stdout.strip()
    section = "\n".join([
        BEGIN,
        "### Several rooms and seeds",
        "",
        "Generated by `python3 scripts/bench/loop_rooms_suite.py --runs %s --poses %s` on %s at "
        "commit `%s` in %.1f minutes (do not edit by hand): `scripts/bench/loop_rooms.sh` for "
        "each box room and seed, `%s` drift, the repair mapping the stored frames again. mAP50, "
        "mean surface distance to the ground-truth mesh and GT things matched (IoU > 0.5) for "
        "the map from ground-truth poses / the repaired map; occupancy: cells known in both "
        "that agree with the ground-truth-pose map."
        % (args.runs, args.poses, datetime.date.today().isoformat(), head,
           (time.time() - start) / 60, args.poses),
        "",
        "| room | seed | mAP50 GT poses / repaired | difference | surface cm | occupancy "
        "| GT things matched | repair s |",
        "|---|---|---:|---:|---:|---:|---:|---:|",
    ] + rows + [
        "",
        "Mean difference %+.1f mAP50 (%.1f to %+.1f); GT things matched over all runs: %d "
        "from ground-truth poses, %d after the repair. Every GT thing whose outcome differs "
        "(cause as `panmap-eval` names it, best IoU with an object of its class):"
        % (sum(diffs) / len(diffs), min(diffs), max(diffs), matched_total[0],
           matched_total[1]),
        "",
        "| room | seed | GT thing | class | vertices | observed | GT poses | repaired |",
        "|---|---|---:|---:|---:|---:|---|---|",
    ] + (changes or ["| - | - | - | - | - | - | - | - |"]) + [END])
    print(section)
    if not args.no_write:
        write_section(args.out, section, BEGIN, END)


if __name__ == "__main__":
    main()
