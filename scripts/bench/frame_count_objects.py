#!/usr/bin/env python3
"""How far a planner can trust the objects a mapper reports before, or without, an optimiser's
answer: from the maps `scripts/bench/accuracy.sh --keep-logs` left (full method, ground-truth
poses, `m2f` masks), exports each map's frame-count objects (`panmap-mapper --load MAP
--export-only --no-optimise`: what a live mapper publishes with no panmap-optimizer on the bus,
and for objects made since its last answer), scores them with panmap-eval, and writes their
reliability beside the optimised objects' into docs/CALIBRATION.md (its frame-count section).
"""
import argparse
import datetime
import json
import os
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import doc_section  # noqa: E402  (same folder)
import suite  # noqa: E402

BEGIN = "<!-- frame-count:begin (scripts/bench/frame_count_objects.py) -->"
END = "<!-- frame-count:end -->"


def runs_of(work):
    """The full method's runs with ground-truth poses and m2f masks that kept their map."""
    root = os.path.join(work, "runs")
    names = sorted(n for n in os.listdir(root) if "_gt_m2f_" in n) if os.path.isdir(root) else []
    return [n for n in names if os.path.exists(os.path.join(root, n, "A", "map.panmap"))
            and os.path.isdir(os.path.join(work, "seq", n, "gt"))]


def export_and_score(work, name, voxel_m):
    out = os.path.join(work, "frame_count", name)
    os.makedirs(out, exist_ok=True)
    suite.run([suite.tool("panmap-mapper"), "-q", "--voxel-size", "%g" % voxel_m, "--threads", "1",
               "--no-snapshots", "--load", os.path.join(work, "runs", name, "A", "map.panmap"),
               "--export-only", "--no-optimise", "--out", out],
              os.path.join(out, "commands.log"))
    return suite.evaluate(out, os.path.join(work, "seq", name), voxel_m)


def pooled(results):
    """Counts over runs: objects, GT things, confident objects and the right ones, GT things
    covered by a confident match, mean mAP50, reliability bins."""
    acc = {"runs": len(results), "objects": 0, "gt": 0, "confident": 0, "right": 0.0,
           "covered": 0.0, "map50": 0.0, "bins": {}}
    for r in results:
        d = r["diagnostics"]
        acc["objects"] += d["num_objects"]
        acc["gt"] += d["num_gt_things"]
        acc["confident"] += d["confident_objects"]
        acc["right"] += d["confident_precision"] * d["confident_objects"]
        acc["covered"] += d["confident_recall"] * d["num_gt_things"]
        acc["map50"] += r["map50"] * 100.0 / len(results)
        for b in d["reliability"]:
            bin_ = acc["bins"].setdefault((b["low"], b["high"]), [0, 0, 0.0])
            bin_[0] += b["count"]
            bin_[1] += b["matched"]
            bin_[2] += b["mean_confidence"] * b["count"]
    return acc


def reliability_table(acc):
    lines = ["| confidence | objects | mean confidence | matched share |", "|---|---:|---:|---:|"]
    for (low, high), (count, matched, conf) in sorted(acc["bins"].items()):
        lines.append("| %.1f-%.1f | %d | %s | %s |" % (
            low, high, count, "%.2f" % (conf / count) if count else "-",
            "%.2f" % (matched / count) if count else "-"))
    return "\n".join(lines)


def calibration_error(acc):
    """Expected calibration error over the bins: sum |mean confidence - matched share| weighted
    by the bin's share of the objects."""
    total = sum(c for c, _, _ in acc["bins"].values())
    return sum(abs(conf / c - m / c) * c for c, m, conf in acc["bins"].values() if c) / total


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--work", default=os.path.join(suite.ROOT, "build", "accuracy"),
                        help="accuracy.sh's work folder (its runs kept their maps)")
    parser.add_argument("--voxel-size", type=float, default=0.02)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--out", default=os.path.join(suite.ROOT, "docs", "CALIBRATION.md"))
    args = parser.parse_args()
    names = runs_of(args.work)
    if not names:
        sys.exit("frame_count_objects.py: no run of the full method with ground-truth poses and "
                 "m2f masks under %s/runs (run scripts/bench/accuracy.sh first)" % args.work)
    start = time.time()
    with ThreadPoolExecutor(args.jobs) as pool:
        frame_count = list(pool.map(
            lambda n: export_and_score(args.work, n, args.voxel_size), names))
    optimised = []
    for n in names:
        with open(os.path.join(args.work, "runs", n, "A", "eval.json")) as f:
            optimised.append(json.load(f))
    fc, opt = pooled(frame_count), pooled(optimised)
    commit = subprocess.run(["git", "-C", suite.ROOT, "rev-parse", "--short", "HEAD"],
                            capture_output=True, text=True).stdout.strip()

    def row(label, a):
        return "| %s | %d | %.2f | %d | %.1f | %.1f | %.1f | %.3f |" % (
            label, a["objects"], a["objects"] / a["gt"], a["confident"],
            100.0 * a["right"] / a["confident"] if a["confident"] else float("nan"),
            100.0 * a["covered"] / a["gt"], a["map50"], calibration_error(a))

    section = "\n".join([
        BEGIN,
        "## Objects without the optimiser's answer",
        "",
        "Generated by `python3 scripts/bench/frame_count_objects.py` on %s at commit `%s` in "
        "%.1f minutes (do not edit by hand), from the maps of `scripts/bench/accuracy.sh "
        "--keep-logs` (the full method, ground-truth poses, `m2f` masks; %d runs: %s)." % (
            datetime.date.today().isoformat(), commit, (time.time() - start) / 60.0,
            len(names), ", ".join(names)),
        "",
        "A mapper reports frame-count objects where no optimiser has answered: with no "
        "`panmap-optimizer` on the bus, before its first answer, for objects made since its "
        "last one, and when `finish` times out. Each map exported again with `--export-only "
        "--no-optimise` gives those objects; they are scored by the model above from the same "
        "evidence (`ObjectScoring`: surface area, and the class scores of their super-points "
        "in the mapper's graph), and are not folded: fragments stay, with low confidences.",
        "",
        "| objects | count | per GT thing | confidence >= 0.5 | of those matching (%) | GT "
        "things they cover (%) | mAP50 | calibration error |",
        "|---|---:|---:|---:|---:|---:|---:|---:|",
        row("optimised (final outputs)", opt),
        row("frame-count (no answer)", fc),
        "",
        "Calibration error: the objects' share-weighted mean over the bins below of |mean "
        "confidence - matched share|. Frame-count objects by reported confidence:",
        "",
        reliability_table(fc),
        END])
    doc_section.splice(args.out, section, BEGIN, END)
    print(section)


if __name__ == "__main__":
    main()
