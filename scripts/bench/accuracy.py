#!/usr/bin/env python3
"""panmap's accuracy suite: real ScanNet scene geometry (as annotated, and with a quarter of it
left unannotated, masks painted there or empty), ScanNet-like procedural rooms, and the
procedural box rooms; every method variant (full, the paper's ablations, a Voxblox++-like
baseline), ground-truth and SLAM-like poses, m2f-like and clean masks, scored with panmap-eval
and written as docs/RESULTS.md with the diagnostics that explain each score.

Every number in docs/RESULTS.md comes from this script; rerun it to regenerate the file.
Sequences are cached in the work folder (keyed by their parameters), maps are rebuilt.
"""
import argparse
import datetime
import glob
import json
import os
import shlex
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import suite  # noqa: E402  (same folder)
from suite import REFINED, UNTRACKED, VARIANTS, Spec, mean  # noqa: E402

# Seeds whose numbers are reported. Tuning (tune_refinement.py, calibrate_confidence.py) uses
# other seeds and other rooms, never these.
REPORT_SEEDS = [1, 2]
REPORT_SCANNET_LIKE = [31, 32, 33]
REPORT_ROOMS = [3, 4, 5]
ROOM_SETTINGS = [("gt", "clean"), ("gt", "m2f"), ("slam", "clean"), ("slam", "m2f")]
ROOM_EXTRA = [("slam-hard", "m2f")]
METRICS = [("mAP50", "map50", "pct"), ("mAP75", "map75", "pct"), ("N_TP50", "ntp50", "sum"),
           ("N_TP75", "ntp75", "sum"), ("PQ50", "pq50", "pct"), ("PQ75", "pq75", "pct"),
           ("IoU_LS", "iou_ls", "pct")]
ABLATIONS = ["w/o III-B", "w/o III-C", "w/o III-D"]
JOINED_PARTS_NOTE = (
    " Scenes named SCENE_joined have their stacked same-class parts joined into one instance "
    "(`panmap-synth --join-parts`: a chair's seat and its star base, which an annotation "
    "derived as connected components splits; docs/SIMULATION.md), in the ground truth and in "
    "what the simulated network sees.")


def recording_of(scene_dir):
    """The one .sens recording in a ScanNet scene folder; exits with a one-line reason when
    there is none or more than one."""
    found = sorted(glob.glob(os.path.join(scene_dir, "*.sens")))
    if len(found) != 1:
        sys.exit("accuracy: --recordings: %s holds %d .sens files, not one" % (scene_dir,
                                                                               len(found)))
    return found[0]


def real_specs(dirs, seeds, frames, join_parts=False, recordings=None):
    """recordings: {scene folder: its .sens}, whose frames replace the surveys (the seeds then
    draw the masks' errors and the drift only)."""
    recordings = recordings or {}
    specs = []
    for d in dirs:
        extra = {"join_parts": join_parts, "recording": recordings.get(d)}
        for annotation, _ in suite.ANNOTATIONS:
            for seed in seeds:
                specs.append(Spec("scannet", d, seed, "gt", "m2f", annotation, "all", frames,
                                  **extra))
                specs.append(Spec("scannet", d, seed, "slam", "m2f", annotation, "tracked",
                                  frames, **extra))
                specs.append(Spec("scannet", d, seed, "gt", "clean", annotation, "full", frames,
                                  **extra))
    return specs


def like_specs(rooms, frames):
    specs = []
    for r in rooms:
        for annotation in ["as generated", "empty"]:
            specs.append(Spec("scannetlike", r, r, "gt", "m2f", annotation, "all", frames))
        specs.append(Spec("scannetlike", r, r, "slam", "m2f", "as generated", "tracked",
                          frames))
        specs.append(Spec("scannetlike", r, r, "gt", "clean", "as generated", "full", frames))
    return specs


def weaker_specs(dirs, seeds, rooms, frames_scannet, frames_like, join_parts=False,
                 recordings=None):
    """A weaker network (`hard` masks), ground-truth poses, every variant: how the method and
    each of its parts hold up when the masks are worse than the reported suite's."""
    recordings = recordings or {}
    specs = [Spec("scannet", d, seed, "gt", "hard", "annotated", "all", frames_scannet,
                  join_parts=join_parts, recording=recordings.get(d))
             for d in dirs for seed in seeds]
    specs += [Spec("scannetlike", r, r, "gt", "hard", "as generated", "all", frames_like)
              for r in rooms]
    return specs


def room_specs(rooms, frames):
    specs = []
    for r in rooms:
        for poses, masks in ROOM_SETTINGS:
            specs.append(Spec("room", r, r, poses, masks, "annotated", "all", frames))
        for poses, masks in ROOM_EXTRA:
            specs.append(Spec("room", r, r, poses, masks, "annotated", "all", frames))
    return specs


def pct(v):
    return "-" if v is None or v != v else "%.1f" % (100 * v)


class Rows:
    """Results of one suite (real scenes or ScanNet-like rooms), averaged over seeds per
    (scene, annotation)."""

    def __init__(self, specs, results):
        self.keys = []  # (scene, annotation) in spec order
        self.by = {}    # (scene, annotation, poses, masks) -> [result, ...] over seeds
        self.names = {}  # the same key -> [spec name, ...] in the same order
        for s in specs:
            key = (s.scene(), s.annotation)
            if key not in self.keys:
                self.keys.append(key)
            self.by.setdefault(key + (s.poses, s.masks), []).append(results[s.name()])
            self.names.setdefault(key + (s.poses, s.masks), []).append(s.name())

    def runs(self, key, poses="gt", masks="m2f", variant="full"):
        return [r["results"][variant] for r in self.by.get(key + (poses, masks), [])
                if variant in r["results"]]

    def metric(self, key, name, **kw):
        return mean([e[name] for e in self.runs(key, **kw)])

    def diag(self, key, name, **kw):
        return mean([e["diagnostics"][name] for e in self.runs(key, **kw)])

    def all_mean(self, fn):
        return mean([fn(k) for k in self.keys])


def count(v):
    return "-" if v is None or v != v else "%.1f" % v


def method_table(rows, poses="gt", metric="map50", show=pct):
    heads = ["full"] + [v for v, _, _ in VARIANTS if v != "full"]
    extra = {"gt": ["full, `slam` poses", "full, clean masks"],
             "slam": ["full, poses as given (`--tracking off`)"]}.get(poses, [])
    lines = ["| scene | annotation | " + " | ".join(heads + extra) + " |",
             "|---|---|" + "---:|" * (len(heads) + len(extra))]

    def cells(f):
        return [f(v) for v in heads] + {"gt": [f("slam"), f("clean")],
                                        "slam": [f(UNTRACKED)]}.get(poses, [])

    def value(key, v):
        if v == UNTRACKED:
            return rows.metric(key, metric, poses="slam", variant=UNTRACKED)
        if v == "slam":
            return rows.metric(key, metric, poses="slam")
        if v == "clean":
            return rows.metric(key, metric, masks="clean")
        return rows.metric(key, metric, poses=poses, variant=v)
    for key in rows.keys:
        lines.append("| %s | %s | %s |" % (key[0], key[1], " | ".join(
            show(x) for x in cells(lambda v: value(key, v)))))
    lines.append("| **mean** | | %s |" % " | ".join(
        "**%s**" % show(x) for x in cells(lambda v: rows.all_mean(lambda k: value(k, v)))))
    return "\n".join(lines)


def quality_table(rows):
    lines = ["| scene | annotation | mAP75 | PQ50 | mIoU | IoU_LS | wall IoU (observed) | "
             "floor IoU (observed) | ceiling IoU (observed) | mIoU counting absent classes |",
             "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"]

    def stuff(key, name):
        observed = mean([e["diagnostics"].get(name + "_observed") for e in rows.runs(key)])
        iou = pct(rows.diag(key, name + "_iou"))
        return iou if observed is None or observed != observed else "%s (%.0f)" % (
            iou, 100 * observed)
    for key in rows.keys:
        lines.append("| %s | %s | %s |" % (key[0], key[1], " | ".join([pct(x) for x in [
            rows.metric(key, "map75"), rows.metric(key, "pq50"),
            rows.metric(key, "miou_gt_classes"), rows.metric(key, "iou_ls")]] + [
            stuff(key, c) for c in ("wall", "floor", "ceiling")] + [
            pct(rows.metric(key, "miou"))])))
    return "\n".join(lines)


def largest(rows, key):
    """The largest super-point of the first seed's run: size and class mix."""
    runs = rows.runs(key)
    if not runs:
        return "-"
    lg = runs[0]["diagnostics"]["largest_superpoint"]
    mix = ", ".join("%s %.0f %%" % (m["name"], 100 * m["share"]) for m in lg["class_mix"][:3])
    return "%d vertices: %s" % (lg["vertices"], mix)


def bridge_reaches(rows, key=None, **kw):
    """Reach (metres) of every bridging super-point in the runs of one key, or of all keys."""
    keys = rows.keys if key is None else [key]
    return [b["reach_m"] for k in keys for e in rows.runs(k, **kw)
            for b in e["diagnostics"]["bridges"] if "reach_m" in b]


def checkable_objects(e):
    """Objects of a run's diagnostics that lie mostly on annotated GT (panmap-eval's
    num_checkable_objects; counted from its object list for results written before it)."""
    d = e["diagnostics"]
    if "num_checkable_objects" in d:
        return d["num_checkable_objects"]
    return sum(1 for o in d["objects"] if not o["unverifiable"])


def checkable_per_thing(rows, key):
    """Objects on annotated GT per GT thing, the mean over the full method's runs."""
    return mean([checkable_objects(e) / e["diagnostics"]["num_gt_things"]
                 for e in rows.runs(key) if e["diagnostics"]["num_gt_things"]])


def diagnostics_table(rows):
    lines = ["| scene | annotation | purity | bridging super-points (counting boundaries) | "
             "worst 2nd class | farthest reach of a bridge | "
             "largest super-point (seed 1) | objects on annotated GT (all) / GT things | "
             "confidence >= 0.5: precision | GT things covered |",
             "|---|---|---:|---:|---:|---:|---|---:|---:|---:|"]
    for key in rows.keys:
        runs = rows.runs(key)
        objects = mean([e["diagnostics"]["num_objects"] for e in runs])
        checkable = mean([checkable_objects(e) for e in runs])
        things = mean([e["diagnostics"]["num_gt_things"] for e in runs])
        reach = bridge_reaches(rows, key)
        lines.append("| %s | %s | %.3f | %.1f (%.1f) | %.2f | %s | %s | %.0f (%.0f) / %.0f | %s | "
                     "%s |" % (
            key[0], key[1], rows.diag(key, "superpoint_purity"),
            rows.diag(key, "num_bridging_superpoints"),
            rows.diag(key, "num_bridging_superpoints_with_boundaries"),
            rows.diag(key, "worst_second_class_share"),
            "%.1f cm" % (100 * max(reach)) if reach else "-", largest(rows, key), checkable,
            objects, things,
            pct(rows.diag(key, "confident_precision")), pct(rows.diag(key, "confident_recall"))))
    return "\n".join(lines)


def bridge_note(rows):
    """What the bridging count leaves out, with the clean-mask runs as the evidence."""
    clean = [rows.diag(k, "num_bridging_superpoints_with_boundaries", masks="clean")
             for k in rows.keys if rows.runs(k, masks="clean")]
    clean_banded = [rows.diag(k, "num_bridging_superpoints", masks="clean")
                    for k in rows.keys if rows.runs(k, masks="clean")]
    evidence = ""
    if clean:
        evidence = (" With clean masks (ground-truth labels) and ground-truth poses the count "
                    "with every vertex is %.1f-%.1f per scene and %.1f-%.1f beyond the band: "
                    "with labels that cannot be wrong, what the band removes is resolution at "
                    "class boundaries (a small object's neighbouring GT vertices transfer to "
                    "its super-point: pictures, mirrors, papers, books)." % (
                        min(clean), max(clean), min(clean_banded), max(clean_banded)))
    full, spatial = bridge_reaches(rows), bridge_reaches(rows, variant="w/o III-B")
    reach = (" A bridge's reach is how far it extends past the boundary between its two "
             "classes, on the side it extends less (for each class, the farthest of its "
             "vertices in the super-point from the other class; the smaller of the two): a "
             "super-point that chains classes reaches far into both, one that took a few "
             "centimetres of a neighbour's surface reaches that far, however large a share "
             "those centimetres are of a small object's super-point.")
    if full:
        reach += (" The full method's %d bridges over every run reach %.1f-%.1f cm" % (
            len(full), 100 * min(full), 100 * max(full)))
        reach += ("; with spatial-only merging (w/o III-B) %d bridges reach %.1f-%.1f cm." % (
            len(spatial), 100 * min(spatial), 100 * max(spatial)) if spatial else ".")
    return ("A bridging super-point has two GT classes each above 10 % of its vertices, counting "
            "only GT vertices farther than 1.5 voxels (3 cm) from an annotated vertex of another "
            "class: the voxel a class boundary crosses can take either class, and the "
            "nearest-vertex label transfer moves labels by up to half a voxel more. In brackets, "
            "the count with every vertex." + evidence + reach + " `panmap-eval "
            "--boundary-band` sets the band; `include/panmap/eval/diagnostics.h` defines it. "
            "Objects are counted against the GT things where they lie mostly on annotated "
            "ground truth (in brackets, every object of `objects.json`): where part of a scene "
            "is unannotated and the network labels it, the objects found there are the scene's "
            "real objects, which no annotated thing stands for, not fragments; the confidence "
            "checks leave them out the same way.")


CAUSES = ["unobserved", "partly observed", "wrong class", "unlabelled", "merged", "split"]


def miss_table(rows):
    """GT thing instances of every run (GT poses, m2f masks; all seeds), by what became of
    them at IoU 0.5 under each method variant (panmap-eval's MissCause)."""
    heads = ["full"] + [v for v, _, _ in VARIANTS if v != "full"]
    lines = ["| method | GT things | matched | " + " | ".join(CAUSES) + " |",
             "|---|---:|---:|" + "---:|" * len(CAUSES)]
    for variant in heads:
        counts = {}
        for key in rows.keys:
            for e in rows.runs(key, variant=variant):
                for t in e["diagnostics"]["gt_things"]:
                    cause = t.get("cause", "?")
                    counts[cause] = counts.get(cause, 0) + 1
        total = sum(counts.values())
        lines.append("| %s | %d | %d | %s |" % (variant, total, counts.get("matched", 0),
                                              " | ".join(str(counts.get(c, 0)) for c in CAUSES)))
    return "\n".join(lines)


def regularisation_reach(rows, masks="m2f"):
    """What III-C could and did change at IoU 0.5: GT things paired across the full method and
    w/o III-C (same run, same GT instance)."""
    total = wrong = fixed = broken = 0
    left_scored = left_unscored = 0  # still missed for a wrong class with III-C
    changed = []  # the GT things whose outcome III-C changed, named
    for key in rows.keys:
        names = rows.names.get(key + ("gt", masks), [])
        for k, (full, without) in enumerate(zip(rows.runs(key, masks=masks),
                                                rows.runs(key, masks=masks,
                                                          variant="w/o III-C"))):
            after = {t["instance_id"]: t for t in full["diagnostics"]["gt_things"]}
            scored = {c["class_id"]: c["name"] for c in full.get("classes", [])}
            for t in after.values():
                if t.get("cause") == "wrong class":
                    if t.get("class_id") in scored:
                        left_scored += 1
                    else:
                        left_unscored += 1
            for t in without["diagnostics"]["gt_things"]:
                total += 1
                now_t = after.get(t["instance_id"], {})
                was, now = t.get("cause"), now_t.get("cause")
                wrong += was == "wrong class"
                fixed += was != "matched" and now == "matched"
                broken += was == "matched" and now != "matched"
                if (was == "matched") != (now == "matched"):
                    cls = t.get("class_id")
                    changed.append("`%s` GT %d (%s): %s at IoU %.2f -> %s at %.2f" % (
                        names[k] if k < len(names) else key[0], t["instance_id"],
                        scored.get(cls, "class %s, not one of the scored classes" % cls),
                        was, t.get("best_iou", 0.0), now, now_t.get("best_iou", 0.0)))
    return ("III-C's reach: without it, %d of the %d GT things are missed for a wrong class, "
            "the cause a change of class addresses directly; III-C turned %d missed "
            "GT things into matches and %d matched ones into misses%s. With it, %d stay "
            "missed for a wrong class, %d of them of a class mAP50 scores (the other %d of "
            "classes outside the evaluated ones, which no change of class can turn into "
            "mAP50)." % (
                wrong, total, fixed, broken,
                (" (without -> with III-C, each with its IoU with the object that overlaps it most: %s)"
                 % "; ".join(changed)) if changed else "",
                left_scored + left_unscored, left_scored, left_unscored))


def regularisation_effect(rows, work, masks="m2f"):
    """Where III-C changes a class, against the ground truth: the full method's and the w/o
    III-C maps are one map labelled twice (same mesh vertices), so the vertices whose class
    differs are exactly III-C's changes; each is given the class of the nearest ground-truth
    vertex within 3 cm."""
    from surface_distance import nearest, read_ply_vertices
    reach_m = 0.03
    counts = {"changed": 0, "vertices": 0, "void": 0, "off": 0, "right": 0, "wrong": 0,
              "neither": 0}
    for key in rows.keys:
        for name in rows.names.get(key + ("gt", masks), []):
            run_dir = os.path.join(work, "runs", name)
            gt_path = os.path.join(work, "seq", name, "gt", "mesh.ply")
            paths = [os.path.join(run_dir, f, "mesh_semantic.ply") for f in ("A", "wo_III-C")]
            if not all(os.path.exists(p) for p in paths + [gt_path]):
                return ""
            (names, full), (_, without) = (read_ply_vertices(p) for p in paths)
            if len(full) != len(without):
                return ""
            ix, iy, iz, ic = (names.index(n) for n in ("x", "y", "z", "semantic"))
            changed = [(a, b[ic]) for a, b in zip(full, without) if a[ic] != b[ic]]
            counts["vertices"] += len(full)
            counts["changed"] += len(changed)
            if not changed:
                continue
            gt_names, gt = read_ply_vertices(gt_path)
            gx, gy, gz, gc = (gt_names.index(n) for n in ("x", "y", "z", "semantic"))
            found = nearest([(a[ix], a[iy], a[iz]) for a, _ in changed],
                            [(g[gx], g[gy], g[gz]) for g in gt], cap=reach_m)
            for (a, was), (at, _) in zip(changed, found):
                truth = None if at is None else gt[at][gc]
                if truth is None:
                    counts["off"] += 1
                elif truth == 0:
                    counts["void"] += 1
                elif truth == a[ic]:
                    counts["right"] += 1
                elif truth == was:
                    counts["wrong"] += 1
                else:
                    counts["neither"] += 1
    if not counts["vertices"]:
        return ""
    share = lambda n: 100.0 * n / max(counts["changed"], 1)  # noqa: E731
    return ("Where III-C acts (ground-truth poses, `%s` masks, every seed; the full method's "
            "and the w/o III-C maps are one map labelled twice, so the mesh vertices whose "
            "class differs are III-C's changes, each given the class of the nearest "
            "ground-truth vertex within 3 cm): %d of %d vertices (%.2f %%) change class; "
            "%.0f %% of them lie on ground truth without a class (unannotated clutter, which "
            "no score counts) and %.0f %% off the ground truth; of the rest, III-C gives the "
            "ground truth's class to %d, takes it away from %d, and %d are wrong either way." % (
                masks, counts["changed"], counts["vertices"],
                100.0 * counts["changed"] / counts["vertices"], share(counts["void"]),
                share(counts["off"]), counts["right"], counts["wrong"], counts["neither"]))


def network_gap(rows):
    """What the network's errors cost the full method at IoU 0.5: GT things of the rows with a
    clean-mask run, paired across the `m2f` and the clean-mask run of the same seed."""
    lost, gained, total = {}, 0, 0
    for key in rows.keys:
        for noisy, clean in zip(rows.runs(key), rows.runs(key, masks="clean")):
            cause = {t["instance_id"]: t.get("cause") for t in noisy["diagnostics"]["gt_things"]}
            for t in clean["diagnostics"]["gt_things"]:
                now = cause.get(t["instance_id"])
                total += t.get("cause") == "matched"
                if t.get("cause") == "matched" and now != "matched":
                    lost[now] = lost.get(now, 0) + 1
                gained += t.get("cause") != "matched" and now == "matched"
    if not total:
        return ""
    return ("What the network's errors cost (full method, ground-truth poses): of the %d GT "
            "things matched with clean masks, %d are missed with `m2f` masks (%s), and %d "
            "missed with clean masks are matched with `m2f`." % (
                total, sum(lost.values()),
                ", ".join("%d %s" % (n, c) for c, n in sorted(lost.items(),
                                                              key=lambda kv: (-kv[1], kv[0])))
                or "none", gained))


def headroom_note(rows):
    """How far above the baseline any method can get: clean masks bound the full method."""
    keys = [k for k in rows.keys if rows.runs(k, masks="clean")]
    if not keys:
        return ""
    gap = mean([rows.metric(k, "map50", masks="clean") -
                rows.metric(k, "map50", variant="Voxblox++-like") for k in keys])
    return ("Headroom: on the scenes with a clean-mask run, clean masks (the network's errors "
            "removed) score %.1f mAP50 above the Voxblox++-like baseline with `m2f` masks, on "
            "the mean; the full method with `m2f` masks is %.1f above it there. Where the "
            "headroom is below 25, the +25 check cannot pass without a weaker baseline." % (
                100 * gap, 100 * mean([rows.metric(k, "map50") -
                                       rows.metric(k, "map50", variant="Voxblox++-like")
                                       for k in keys])))


def ceiling_note(rows):
    """Rows where an ablation check fails while the full method already scores what clean
    masks score: no part of the method shows a gain above that ceiling, and the clean-mask
    run's misses say what sets it."""
    def misses(runs):
        counts = {}
        for e in runs:
            for t in e["diagnostics"]["gt_things"]:
                cause = t.get("cause", "?")
                if cause != "matched":
                    counts[cause] = counts.get(cause, 0) + 1
        return ", ".join("%d %s" % (n, c) for c, n in sorted(counts.items())) or "none"
    notes = []
    for key in rows.keys:
        clean = rows.metric(key, "map50", masks="clean")
        full = rows.metric(key, "map50")
        if clean != clean or full < clean - 1e-9:
            continue
        failing = [ab for ab in ABLATIONS
                   if full - rows.metric(key, "map50", variant=ab) < 0.015]
        if not failing:
            continue
        notes.append("%s, %s (%s): full %.1f, clean masks %.1f; missed with clean masks: %s; "
                     "with `m2f` masks: %s" % (
                         key[0], key[1], ", ".join(failing), 100 * full, 100 * clean,
                         misses(rows.runs(key, masks="clean")), misses(rows.runs(key))))
    if not notes:
        return ""
    return ("Ablation checks that fail at the ceiling: on these rows the full method with `m2f` "
            "masks scores at least what it scores with clean masks (the network's errors "
            "removed), the most any part of the method could be expected to reach, so "
            "switching a part off cannot show a gain there; the clean-mask misses (GT poses, "
            "every seed) are what sets that ceiling. " + "; ".join(notes) + ".")


def pose_gap_note(rows):
    """Rows where `slam` poses score more than 2 points below ground-truth poses: every GT thing
    whose outcome differs between the two runs of a seed, with its best IoU both ways. A few
    objects near the IoU 0.5 line move a class average by much; a pose problem moves many."""
    notes, changed, near = [], 0, 0
    for key in rows.keys:
        if not rows.metric(key, "map50", poses="slam") - rows.metric(key, "map50") < -0.02:
            continue
        gt_runs = dict(zip(rows.names.get(key + ("gt", "m2f"), []),
                           rows.by.get(key + ("gt", "m2f"), [])))
        items = []
        for name, run in zip(rows.names.get(key + ("slam", "m2f"), []),
                             rows.by.get(key + ("slam", "m2f"), [])):
            base = gt_runs.get(name.replace("_slam_", "_gt_"))
            if not base or "full" not in base["results"] or "full" not in run["results"]:
                continue
            before = {t["instance_id"]: t
                      for t in base["results"]["full"]["diagnostics"]["gt_things"]}
            things = run["results"]["full"]["diagnostics"]["gt_things"]
            per_class = {}
            for t in things:
                per_class[t.get("class_id")] = per_class.get(t.get("class_id"), 0) + 1
            for t in things:
                b = before.get(t["instance_id"])
                if b is None or b.get("cause") == t.get("cause"):
                    continue
                iou_b, iou_t = b.get("best_same_class_iou", 0.0), t.get("best_same_class_iou", 0.0)
                changed += 1
                near += abs(iou_b - 0.5) <= 0.05 and abs(iou_t - 0.5) <= 0.05
                items.append("GT %d (class %d, one of %d, %d vertices) %s %.2f -> %s %.2f" % (
                    t["instance_id"], t.get("class_id", 0), per_class[t.get("class_id")],
                    t.get("vertices", 0), b.get("cause"), iou_b, t.get("cause"), iou_t))
        notes.append("%s, %s: %.1f against %.1f; %s" % (
            key[0], key[1], 100 * rows.metric(key, "map50", poses="slam"),
            100 * rows.metric(key, "map50"), "; ".join(items) or "no GT thing changed outcome"))
    if not notes:
        return ""
    return ("Pose checks that fail, object by object (the full method, ground-truth poses -> "
            "`slam` poses with the default tracking, the same seed; best IoU with an object of "
            "the GT thing's class): " + "; ".join(notes) + ". %d of these %d changes have the "
            "best IoU within 0.05 of the 0.5 line both times. mAP50 averages the classes' AP, so "
            "one object of a class with few GT things (one of N) moves it by several points." % (
                near, changed))


def bridge_list(rows):
    """Every bridging super-point of the full method (ground-truth poses, `m2f` masks): the run,
    its GT objects (panmap-eval's `gt_instances`, what trace_object.py --instance follows; the
    class mix where a results file predates them) and its reach."""
    items = []
    for key in rows.keys:
        for name, run in zip(rows.names.get(key + ("gt", "m2f"), []),
                             rows.by.get(key + ("gt", "m2f"), [])):
            full = run["results"].get("full")
            for b in (full or {}).get("diagnostics", {}).get("bridges", []):
                names = {c["class_id"]: c["name"] for c in b.get("classes", [])}
                if b.get("gt_instances"):
                    # A stuff class counts as one object, instance 0: named by its class.
                    parts = ", ".join("%s%s %d" % (
                        "GT %d " % p["instance"] if p["instance"] else "",
                        names.get(p["class_id"], "class %d" % p["class_id"]), p["vertices"])
                        for p in b["gt_instances"])
                else:
                    parts = ", ".join("%s %.0f %%" % (c["name"], 100 * c["share"])
                                      for c in b.get("classes", []))
                item = "`%s` super-point %d: %d vertices, %s; reach %.1f cm" % (
                    name, b["superpoint"], b["vertices"], parts, 100 * b.get("reach_m", 0.0))
                to_map = b.get("map_distance_m") or []
                if len(to_map) == 2 and None not in to_map:
                    item += "; median distance to the map %.1f / %.1f cm" % (
                        100 * to_map[0], 100 * to_map[1])
                items.append(item)
    if not items:
        return ""
    return ("Bridging super-points of the full method, run by run (ground-truth poses, `m2f` "
            "masks; vertices beyond the band by GT object, or by class; the median distance "
            "from the GT vertices of each of its two classes, the larger first, to the nearest "
            "mapped vertex: about half a voxel on surface the map observed, more on surface it "
            "never resolved, which the 5 cm label transfer labels from the nearest mapped "
            "surface): " + "; ".join(items) +
            ". docs/MAPPING.md (III-B) says how such bridges arise: the main suite's of "
            "2026-12-02 (docs/RESULTS.md) traced vote by vote.")


def acceptance(rows):
    """Issue 19's acceptance lines per (scene, annotation) and as the mean."""
    points = lambda v: "%.1f" % (100 * v)  # noqa: E731
    plain = lambda v: "%.2f" % v  # noqa: E731
    checks = [
        ("full >= 65 mAP50", lambda k: rows.metric(k, "map50"), points, lambda v: v >= 0.65),
        ("full - Voxblox++-like >= 25", lambda k: rows.metric(k, "map50") -
         rows.metric(k, "map50", variant="Voxblox++-like"), points, lambda v: v >= 0.25),
        ("`slam` - GT poses within 2", lambda k: rows.metric(k, "map50", poses="slam") -
         rows.metric(k, "map50"), points, lambda v: v >= -0.02),
    ]
    for ab in ABLATIONS:
        checks.append(("full - %s >= 1.5" % ab, lambda k, ab=ab: rows.metric(k, "map50") -
                       rows.metric(k, "map50", variant=ab), points, lambda v: v >= 0.015))
    for ab in ABLATIONS:
        checks.append(("`slam` poses: full - %s >= 1.5" % ab, lambda k, ab=ab: rows.metric(
            k, "map50", poses="slam") - rows.metric(k, "map50", poses="slam", variant=ab),
            points, lambda v: v >= 0.015))
    checks += [
        ("super-point purity >= 0.9", lambda k: rows.diag(k, "superpoint_purity"), plain,
         lambda v: v >= 0.9),
        ("super-points > 10 % of two classes (beyond 1.5 voxels of a boundary): none",
         lambda k: rows.diag(
            k, "num_bridging_superpoints"), plain, lambda v: v == 0),
        ("objects on annotated GT / GT things <= 2", lambda k: checkable_per_thing(rows, k),
         plain, lambda v: v <= 2.0),
        ("confidence >= 0.5: >= 70 % match", lambda k: rows.diag(k, "confident_precision"),
         points, lambda v: v >= 0.7),
        ("confidence >= 0.5: cover >= 50 % of GT things",
         lambda k: rows.diag(k, "confident_recall"), points, lambda v: v >= 0.5),
        ("clean masks >= 75 mAP50", lambda k: rows.metric(k, "map50", masks="clean"), points,
         lambda v: v >= 0.75),
        ("issue 20: `slam` poses, default tracking - `--tracking off` >= 0",
         lambda k: rows.metric(k, "map50", poses="slam") -
         rows.metric(k, "map50", poses="slam", variant=UNTRACKED), points, lambda v: v >= 0.0),
    ]
    lines = ["| check | " + " | ".join("%s, %s" % k for k in rows.keys) + " | mean |",
             "|---|" + "---:|" * (len(rows.keys) + 1)]
    for name, value, fmt, ok in checks:
        cells = []
        for v in [value(k) for k in rows.keys] + [rows.all_mean(value)]:
            cells.append("-" if v != v else "%s %s" % (fmt(v), "yes" if ok(v) else "**no**"))
        lines.append("| %s | %s |" % (name, " | ".join(cells)))
    return "\n".join(lines)


def reliability(rows_list):
    """Pooled over the full method's runs (GT poses, m2f masks) of the given suites."""
    bins = {}
    for rows in rows_list:
        for key in rows.keys:
            for e in rows.runs(key):
                for b in e["diagnostics"]["reliability"]:
                    acc = bins.setdefault((b["low"], b["high"]), [0, 0, 0.0])
                    acc[0] += b["count"]
                    acc[1] += b["matched"]
                    acc[2] += b["mean_confidence"] * b["count"]
    lines = ["| confidence | objects | mean confidence | share matching a GT object (IoU > 0.5) |",
             "|---|---:|---:|---:|"]
    for (low, high), (count, matched, conf) in sorted(bins.items()):
        lines.append("| %.1f-%.1f | %d | %s | %s |" % (
            low, high, count, "%.2f" % (conf / count) if count else "-",
            "%.2f" % (matched / count) if count else "-"))
    return "\n".join(lines)


def weaker_table(rows):
    """mAP50 of every variant, PQ50 and objects of the full method and w/o III-C, with `hard`
    masks and ground-truth poses."""
    heads = ["full"] + [v for v, _, _ in VARIANTS if v != "full"]
    lines = ["| scene | annotation | " + " | ".join(heads) + " | PQ50: full / w/o III-C | "
             "objects: full / w/o III-C |",
             "|---|---|" + "---:|" * (len(heads) + 2)]

    def objects(key):
        full, without = (rows.runs(key, masks="hard", variant=v) for v in ("full", "w/o III-C"))
        return "%.0f / %.0f (%.0f GT)" % (
            mean([e["diagnostics"]["num_objects"] for e in full]),
            mean([e["diagnostics"]["num_objects"] for e in without]),
            mean([e["diagnostics"]["num_gt_things"] for e in full]))
    for key in rows.keys:
        lines.append("| %s | %s | %s | %s / %s | %s |" % (
            key[0], key[1], " | ".join(pct(rows.metric(key, "map50", masks="hard", variant=v))
                                       for v in heads),
            pct(rows.metric(key, "pq50", masks="hard")),
            pct(rows.metric(key, "pq50", masks="hard", variant="w/o III-C")),
            objects(key)))
    lines.append("| **mean** | | %s | %s / %s | |" % (
        " | ".join("**%s**" % pct(rows.all_mean(
            lambda k, v=v: rows.metric(k, "map50", masks="hard", variant=v))) for v in heads),
        pct(rows.all_mean(lambda k: rows.metric(k, "pq50", masks="hard"))),
        pct(rows.all_mean(lambda k: rows.metric(k, "pq50", masks="hard", variant="w/o III-C")))))
    return "\n".join(lines)


def room_table(results, specs, poses, masks):
    keyed = [results[s.name()] for s in specs if (s.poses, s.masks) == (poses, masks)]
    lines = ["| Method | " + " | ".join(m[0] for m in METRICS) + " |",
             "|---|" + "---:|" * len(METRICS)]
    for variant in [v for v, _, _ in VARIANTS] + [REFINED]:
        if not all(variant in k["results"] for k in keyed):
            continue
        cells = []
        for _, key, kind in METRICS:
            values = [k["results"][variant][key] for k in keyed]
            cells.append("%d" % sum(v or 0 for v in values) if kind == "sum" else
                         "%.1f" % (100 * mean(values)))
        lines.append("| %s | %s |" % (variant, " | ".join(cells)))
    return "\n".join(lines)


def room_section(results, specs):
    md = []
    titles = {"gt": "Ground-truth poses", "slam": "SLAM-like (`slam`) poses",
              "slam-hard": "Harder drift (`slam-hard`) poses"}
    for poses, masks in ROOM_SETTINGS + ROOM_EXTRA:
        keyed = [(s, results[s.name()]) for s in specs if (s.poses, s.masks) == (poses, masks)]
        if not keyed:
            continue
        md += ["### %s, %s masks" % (titles[poses], masks), ""]
        if poses != "gt":
            md += ["ATE (RMSE after rigid alignment, mean over rooms): input %.2f cm, refined "
                   "against the map %.2f cm (%s)." % (
                       100 * mean([k["trajectory_ate_m"]["input"] for _, k in keyed]),
                       100 * mean([k["trajectory_ate_m"]["refined"] for _, k in keyed]),
                       ", ".join("room %d: %.2f -> %.2f" % (
                           s.source, 100 * k["trajectory_ate_m"]["input"],
                           100 * k["trajectory_ate_m"]["refined"]) for s, k in keyed)), ""]
        md += [room_table(results, specs, poses, masks), ""]
    return md


def depth_check_note(work, specs):
    """What auto tracking's depth check decided on every sequence with drifting poses, read
    from each full run's report.json (empty when none has one)."""
    checks = []
    for spec in specs:
        if spec.poses == "gt":
            continue
        for folder in ("A_refined", "A"):  # box rooms: A maps the poses as given
            path = os.path.join(work, "runs", spec.name(), folder, "report.json")
            if os.path.exists(path):
                with open(path) as f:
                    check = json.load(f).get("depth_check")
                if check:
                    checks.append(check)
                break
    if not checks:
        return []
    verdicts = {}
    for c in checks:
        verdicts[c["verdict"]] = verdicts.get(c["verdict"], 0) + 1
    patterns = [c["pattern_mm"] for c in checks if c.get("pattern_mm") is not None]
    return ["Depth check of the default tracking (docs/MAPPING.md, \"Depth check\": the fixed "
            "depth error pattern measured over the first 30 alignments, limit %.1f mm), on the "
            "%d sequences with SLAM-like poses: %s; pattern %.2f-%.2f mm." % (
                checks[0]["limit_mm"], len(checks),
                ", ".join("%s %d" % (v, n) for v, n in sorted(verdicts.items())),
                min(patterns), max(patterns)) if patterns else
            "Depth check of the default tracking: %d sequences, no pattern measured." % len(checks),
            ""]


def resumed_note(results):
    """How many sequences a resumed run took from an earlier run's saved results."""
    n = sum(1 for r in results.values() if r.get("resumed"))
    return (" (%d of %d sequences as an earlier run with the same binaries saved them)" % (
        n, len(results))) if n else ""


def code_version():
    """The commit the maps are made with, and whether tracked files other than the reports
    differed from it."""
    commit = subprocess.run(["git", "-C", suite.ROOT, "rev-parse", "--short", "HEAD"],
                            stdout=subprocess.PIPE, text=True).stdout.strip() or "unknown"
    status = subprocess.run(["git", "-C", suite.ROOT, "status", "--porcelain",
                             "--untracked-files=no", "--", ".", ":!docs"],
                            stdout=subprocess.PIPE, text=True).stdout
    return "`%s`%s" % (commit, " (with local changes)" if status.strip() else "")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scannet", nargs="*", default=None, metavar="DIR",
                        help="ScanNet scene folders (default: every ../shared/data/scannet-gt/"
                             "scene*); give none to skip real scenes")
    parser.add_argument("--scannet-like", default=",".join(map(str, REPORT_SCANNET_LIKE)),
                        help="ScanNet-like procedural room seeds ('' to skip)")
    parser.add_argument("--rooms", default=",".join(map(str, REPORT_ROOMS)),
                        help="procedural box room seeds ('' to skip)")
    parser.add_argument("--seeds", default=",".join(map(str, REPORT_SEEDS)),
                        help="sequence seeds of each real scene")
    parser.add_argument("--frames-scannet", type=int, default=600)
    parser.add_argument("--frames-like", type=int, default=600)
    parser.add_argument("--frames-room", type=int, default=450)
    parser.add_argument("--rate-hz", type=float, default=5.0)
    parser.add_argument("--voxel-size", type=float, default=0.02)
    parser.add_argument("--config", default="", help="YAML config for every mapper run")
    parser.add_argument("--work", default=os.path.join(suite.BUILD, "accuracy"),
                        help="folder for sequences and maps (default build/accuracy)")
    parser.add_argument("--out", default=os.path.join(suite.ROOT, "docs", "RESULTS.md"))
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 2)
    parser.add_argument("--join-parts", action="store_true",
                        help="real scenes with their stacked same-class parts joined "
                             "(panmap-synth --join-parts): the scene named SCENE_joined")
    parser.add_argument("--recordings", action="store_true",
                        help="map each --scannet scene's own recording (the one .sens in its "
                             "folder, every 6th frame: 5 Hz) with masks simulated from its "
                             "annotation (panmap-synth --recording) instead of rendered surveys")
    parser.add_argument("--keep-logs", action="store_true",
                        help="keep the rendered logs (150 MB each) for reruns")
    parser.add_argument("--resume", action="store_true",
                        help="take each sequence's result that an earlier run saved with the "
                             "same binaries and options (WORK/runs/NAME/result.json) instead "
                             "of mapping it again: a run cut short goes on where it stopped")
    parser.add_argument("--report-only", action="store_true",
                        help="map nothing: rewrite the report from WORK/results.json of an "
                             "earlier run with the same options")
    args = parser.parse_args()
    dirs = suite.scene_dirs(args.scannet)
    seeds = [int(s) for s in args.seeds.split(",") if s]
    like = [int(s) for s in args.scannet_like.split(",") if s]
    rooms = [int(s) for s in args.rooms.split(",") if s]
    if args.config:
        args.config = os.path.abspath(args.config)
    start = time.time()
    recordings = {d: recording_of(d) for d in dirs} if args.recordings else {}
    real = real_specs(dirs, seeds, args.frames_scannet, args.join_parts, recordings)
    likes = like_specs(like, args.frames_like)
    boxes = room_specs(rooms, args.frames_room)
    weaker = weaker_specs(dirs, seeds, like, args.frames_scannet, args.frames_like,
                          args.join_parts, recordings)
    saved = os.path.join(args.work, "results.json")
    if args.report_only:
        try:
            with open(saved) as f:
                stored = json.load(f)
            results, minutes, version = stored["results"], stored["minutes"], stored["version"]
        except (OSError, ValueError, KeyError) as e:
            sys.exit("accuracy: cannot read %s (%s): run without --report-only" % (saved, e))
        missing = [s.name() for s in real + likes + boxes + weaker if s.name() not in results]
        if missing:
            sys.exit("accuracy: %s holds no run of %s: run without --report-only" % (
                saved, missing[0]))
    else:
        version = code_version()  # before mapping: what the maps were made with
        results = suite.run_all(args.work, real + likes + boxes + weaker, args.voxel_size,
                                args.jobs, args.keep_logs, args.config, label="accuracy",
                                resume=args.resume)
        minutes = (time.time() - start) / 60
        with open(saved, "w") as f:
            json.dump({"results": results, "minutes": minutes, "version": version}, f,
                      indent=1)

    cpu = "unknown"
    with open("/proc/cpuinfo") as f:
        for line in f:
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    md = ["# Accuracy", "",
          "Generated by `scripts/bench/accuracy.sh` (do not edit by hand) on %s, maps of "
          "commit %s, %s, %d cores, in %.1f minutes%s." % (
              datetime.date.today().isoformat(), version, cpu, os.cpu_count(), minutes,
              resumed_note(results)), "",
          "Command: `scripts/bench/accuracy.sh %s`" % " ".join(
              shlex.quote(a) for a in sys.argv[1:] if a not in ("--report-only", "--resume")),
          "",
          "Metrics from `panmap-eval` (ScanNet's `evaluate_semantic_instance` matching, the 18 "
          "ScanNet classes, label transfer within 5 cm), in percent: mAP and PQ are class "
          "averages, then means over seeds and scenes; diagnostics (super-point purity, "
          "bridging super-points, objects per GT thing instance, confidence precision and "
          "coverage) are defined in `include/panmap/eval/diagnostics.h`. Maps at %g cm voxels. "
          "Seeds, rooms and scenes used to choose defaults (docs/TUNING.md) are never the ones "
          "reported here." % (100 * args.voxel_size), "",
          "Variants: **full** = the mask edge fill (a mask's pixels outside every surface vote "
          "with its surfaces, docs/MAPPING.md), semantically consistent super-points (III-B), "
          "the super-point graph's co-observations counted 2 px inside each mask's outline "
          "(docs/MAPPING.md, step 6), "
          "graph regularisation (III-C), instance refinement (III-D), objects (fragments "
          "folded, calibrated confidences); **w/o III-B** = spatial-only super-point merging; "
          "**w/o "
          "III-C** = no semantic regularisation; **w/o III-D** = no instance refinement; "
          "**Voxblox++-like** = spatial-only merging and frame-count labels, no mask edge "
          "fill, co-observations counted on every pixel, no graph optimisation (same object "
          "output stage). These map the poses as given "
          "(`--tracking off`); **full, `slam` poses** maps SLAM-like poses with the default "
          "tracking (`auto`: each pose refined against the map); **full, poses as given** maps "
          "the same SLAM-like poses with `--tracking off`, so that the two show what the pose "
          "refinement adds (issue 20: never less than without it).", ""] + depth_check_note(
              args.work, real + likes + boxes + weaker) + [

          "A map built from drifting poses lives in the world frame of its trajectory, which "
          "differs from the ground truth's by a rigid transform no mapper can observe (the "
          "drift of the first poses fixes it). Before scoring, such a mesh is moved by the "
          "rigid alignment of the trajectory it was built with to the ground-truth trajectory: "
          "the alignment ATE itself applies (`panmap-eval --align-pred`). Errors inside the "
          "map (doubled surfaces, bent walls) are not removed by it.", ""]
    for title, specs, intro in [
            ("Real ScanNet scene geometry", real,
             ("`panmap-synth --scannet DIR --recording SCENE.sens --every 6` maps each scan's "
              "own recording: its real depth, colour and poses (every 6th frame, 5 Hz), with "
              "`m2f` masks simulated from the annotated reconstruction rendered at each "
              "recorded pose (seeds %s draw the masks' errors and the drift; docs/SIMULATION.md, "
              "\"Recorded frames with simulated masks\")." % ", ".join(map(str, seeds))
              if recordings else
              "`panmap-synth --scannet DIR` renders the scene's reconstructed mesh along a "
              "survey (%d frames at %g Hz, seeds %s): depth noise, `m2f` masks, SLAM drift as "
              "docs/SIMULATION.md describes." % (args.frames_scannet, args.rate_hz,
                                                  ", ".join(map(str, seeds)))) +
             " Each scene as annotated, and with 25 %% of its "
             "vertices left unannotated (`--unannotate 0.25`: whole objects and clutter "
             "patches), the simulated network painting those surfaces (`painted`) or leaving "
             "them without a mask (`empty`).%s" % (
                 JOINED_PARTS_NOTE if args.join_parts else "")),
            ("ScanNet-like procedural rooms", likes,
             "`panmap-synth --room S --room-style scannet --laps 2` (rooms %s, %d frames at "
             "%g Hz): 30-60 instances of 24-27 classes, small objects on furniture, clutter "
             "touching furniture and walls, unannotated clutter (class 0), a survey that "
             "passes every area twice. `empty`: no mask on the unannotated clutter." % (
                 ", ".join(map(str, like)), args.frames_like, args.rate_hz))]:
        if not specs:
            continue
        rows = Rows(specs, results)
        md += ["## %s" % title, "", intro, "",
               "### mAP50 per method (ground-truth poses, `m2f` masks unless said)", "",
               method_table(rows), "",
               "### mAP50 per method (`slam` poses, each variant with the default tracking)", "",
               method_table(rows, "slam"), "",
               "### mIoU per method (ground-truth poses, `m2f` masks unless said)", "",
               "Semantic regularisation (III-C) changes classes, not instances: its effect "
               "shows here more than in mAP50. The mean is over the classes the scene's "
               "ground truth has (`miou_gt_classes` of panmap-eval); a class predicted where "
               "the ground truth has none is counted apart, below, its vertices still "
               "counting against the class they belong to. ScanNet's script gives such a "
               "class IoU 0 over a whole dataset, where every class is present; in one scene "
               "of six classes, a few stray vertices of a seventh take a seventh of the mean, "
               "and moving the voxel grid by a fraction of a voxel moves that per-scene figure "
               "far more than the mean over the ground truth's classes (docs/NOISE_FLOOR.md). "
               "The Quality table keeps it.", "",
               method_table(rows, metric="miou_gt_classes"), "",
               "Spurious classes per run (evaluated classes predicted on ground-truth "
               "vertices where the ground truth has none):", "",
               method_table(rows, metric="spurious_classes", show=count), "",
               "### Quality of the full method", "",
               "In brackets after each stuff class's IoU, the percentage of its ground-truth "
               "vertices the map observed at all (a predicted vertex within the label "
               "transfer's 5 cm): vertices never observed count against the IoU as missed, so "
               "an IoU close to that share is a surface the survey never looked at (the "
               "ceilings of the ScanNet-like rooms, seen from head height), not a labelling "
               "error.", "",
               quality_table(rows), "", "### Diagnostics of the full method", "",
               bridge_note(rows), "", diagnostics_table(rows), "",
               "### Why GT objects are missed (ground-truth poses, `m2f` masks, every seed)", "",
               "Each GT thing instance is matched (an object of its class with IoU > 0.5) or "
               "missed for the first cause that holds: **unobserved**, at most half of its "
               "surface found a mapped vertex within 5 cm (the trajectory did not see it: no "
               "labelling can match it); **partly observed**, more than half of it was seen and "
               "the best object of its class would match had the rest been seen and mapped as "
               "the part seen was (its IoU over the share seen is above 0.5: the survey's "
               "coverage, not the labelling, is short); **wrong class**, at most half of it "
               "carries its class "
               "and more of the rest another class (what semantic regularisation, III-C, can "
               "fix); **unlabelled**, the same but more of the rest carries no class; **merged**, one object of its "
               "class holds most of it but is too large (spans neighbours: III-B and III-D's "
               "domain); **split**, its class covers most of it but no single object more than "
               "half (fragments: III-D's domain). Defined in "
               "`include/panmap/eval/diagnostics.h` (`MissCause`).", "",
               miss_table(rows), "", regularisation_reach(rows), "",
               regularisation_effect(rows, args.work), "", network_gap(rows), "",
               "### Acceptance (issue 19)", "", acceptance(rows), "", headroom_note(rows), "",
               ceiling_note(rows), ""]
        pose_gaps = pose_gap_note(rows)
        if pose_gaps:
            md += [pose_gaps, ""]
        bridges = bridge_list(rows)
        if bridges:
            md += [bridges, ""]
    suites = [Rows(s, results) for s in (real, likes) if s]
    if suites:
        md += ["## Confidence reliability", "",
               "Objects of the full method (ground-truth poses, `m2f` masks) over every real "
               "scene and ScanNet-like room above, by reported confidence; objects lying mostly "
               "on unannotated ground truth cannot be checked and are left out.", "",
               reliability(suites), ""]
    if weaker:
        rows = Rows(weaker, results)
        md += ["## A weaker network (`hard` masks)", "",
               "The real scene as annotated (seeds %s) and the ScanNet-like rooms, ground-truth "
               "poses, masks from the `hard` preset of docs/SIMULATION.md instead of `m2f` (more "
               "missed objects, twice the class confusion, wider boundary errors, more merged "
               "and split masks and false positives; set before any tuning, as `m2f` was). Not "
               "tuned on: the question is whether the method and each of its parts hold up "
               "when the network is worse than the one the defaults were chosen with." % (
                   ", ".join(map(str, seeds))), "",
               weaker_table(rows), "", regularisation_reach(rows, masks="hard"), "",
               regularisation_effect(rows, args.work, masks="hard"), ""]
    if boxes:
        md += ["## Procedural box rooms", "",
               "`panmap-synth` box rooms %s (room seed = sequence seed), %d frames at %g Hz: "
               "the suite before real geometry; all variants map the poses as given, **%s** "
               "refines SLAM poses against the map." % (
                   ", ".join(map(str, rooms)), args.frames_room, args.rate_hz, REFINED), ""]
        md += room_section(results, boxes)
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    # The pose refinement section belongs to scripts/bench/refinement.py: kept as it was.
    kept = ""
    if os.path.exists(args.out):
        text = open(args.out).read()
        begin, end = "<!-- refinement:begin", "<!-- refinement:end -->"
        if begin in text and end in text:
            kept = "\n" + text[text.index(begin):text.index(end) + len(end)] + "\n"
    with open(args.out, "w") as f:
        f.write("\n".join(md) + kept)
    print("accuracy: wrote %s in %.1f minutes" % (args.out, minutes), file=sys.stderr)


if __name__ == "__main__":
    main()
