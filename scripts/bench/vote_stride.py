#!/usr/bin/env python3
"""Label votes at coarse voxels (issue 23): the whole accuracy suite at 5 cm, once with every
labelled pixel voting (integrator.vote_stride_px: 1, the default) and once with the automatic
stride (0: floor(voxel x fx / (2 x max depth)), 3 for the suite's 525 px cameras), compared
run by run, and the integration time of both on real 7-Scenes frames; writes
docs/VOTE_STRIDE.md. About 50-80 minutes on 2 cores (two accuracy suites at 5 cm).

  scripts/bench/vote_stride.py [--voxel-size 0.05] [--work DIR] [--report-only] [--runs 3]

Each suite's own report (every table of docs/RESULTS.md at this voxel size) is left in
WORK/NAME/RESULTS.md.
"""
import argparse
import datetime
import json
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import suite  # noqa: E402  (same folder)
from suite import VARIANTS, mean  # noqa: E402

SETTINGS = [("every", 1), ("automatic", 0)]  # work folder name, integrator.vote_stride_px
TOLERANCE = 0.5  # mAP50 points per scene, issue 23


def config_text(stride):
    return "%%YAML:1.0\n---\nintegrator:\n   vote_stride_px: %d\n" % stride


def run_suite(work, name, stride, voxel, report_only):
    folder = os.path.join(work, name)
    os.makedirs(folder, exist_ok=True)
    config = os.path.join(folder, "config.yaml")
    if not report_only:
        with open(config, "w") as f:
            f.write(config_text(stride))
    cmd = [sys.executable, os.path.join(suite.ROOT, "scripts", "bench", "accuracy.py"),
           "--voxel-size", str(voxel), "--config", config, "--work", folder,
           "--out", os.path.join(folder, "RESULTS.md")]
    if report_only:
        cmd.append("--report-only")
    print("vote_stride: %s (%s)" % (name, " ".join(cmd[1:])), file=sys.stderr, flush=True)
    subprocess.run(cmd, check=True)
    with open(os.path.join(folder, "results.json")) as f:
        stored = json.load(f)
    with open(config) as f:
        used = re.search(r"vote_stride_px:\s*(-?\d+)", f.read())
    return stored, int(used.group(1)) if used else stride


ANNOTATION_TAGS = {"ann": "as annotated", "u25p": "25 % unannotated, painted",
                   "u25e": "25 % unannotated, empty", "empty": "clutter masks empty"}


def integration_ms(voxel, config, threads, runs, data):
    """Median over `runs` runs of panmap-bench-mapping's median integration time per frame."""
    times = []
    for _ in range(runs):
        out = os.path.join(os.path.dirname(config), "bench.json")
        subprocess.run([suite.tool("panmap-bench-mapping"), "--data", data, "--config", config,
                        "--voxel-size", str(voxel), "--threads", str(threads),
                        "--outputs-every", "0", "--json", out],
                       check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        with open(out) as f:
            times.append(json.load(f)["stages"]["integration"]["median_ms"])
    return sorted(times)[len(times) // 2]


def scene_of(run_name):
    """The scene and annotation of a run: what docs/RESULTS.md gives a row."""
    match = re.match(r"^(.*?)_s\d+_([a-z0-9]+)_", run_name)
    if not match:
        return run_name
    return "%s, %s" % (match.group(1), ANNOTATION_TAGS.get(match.group(2), match.group(2)))


def score(result, variant, key="map50"):
    value = result["results"].get(variant, {}).get(key)
    return None if value is None else 100.0 * value


def fmt(x):
    return "-" if x is None else "%.1f" % x


def cpu_name():
    with open("/proc/cpuinfo") as f:
        for line in f:
            if line.startswith("model name"):
                return " ".join(line.split(":", 1)[1].split()[:2])
    return "unknown"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--voxel-size", type=float, default=0.05)
    parser.add_argument("--work", default=os.path.join(suite.BUILD, "vote_stride"))
    parser.add_argument("--out", default=os.path.join(suite.ROOT, "docs", "VOTE_STRIDE.md"))
    parser.add_argument("--report-only", action="store_true",
                        help="map nothing: compare the results.json of an earlier run")
    parser.add_argument("--runs", type=int, default=3, help="timing runs per setting")
    parser.add_argument("--data", default=os.path.join(suite.ROOT, "..", "shared", "data",
                                                       "7scenes-200"),
                        help="real frames to time integration on")
    args = parser.parse_args()
    stored = {}
    for name, stride in SETTINGS:
        stored[name] = run_suite(args.work, name, stride, args.voxel_size, args.report_only)
    (a, stride_a), (b, stride_b) = stored["every"], stored["automatic"]
    print("vote_stride: timing integration on %s" % args.data, file=sys.stderr, flush=True)
    speed = {}
    for name, stride in SETTINGS:
        config = os.path.join(args.work, name, "bench.yaml")
        with open(config, "w") as f:
            f.write(config_text(stride))
        speed[name] = [integration_ms(args.voxel_size, config, t, args.runs, args.data)
                       for t in (1, 2)]
    runs = [r for r in a["results"] if r in b["results"]]
    if not runs:
        sys.exit("vote_stride: the two suites share no run")

    lines = [
        "# Label votes at coarse voxels",
        "",
        "Generated by `scripts/bench/vote_stride.py` (do not edit by hand) on %s; maps of %s "
        "(every pixel) and %s (automatic), %.1f + %.1f minutes." % (
            datetime.date.today().isoformat(), a["version"], b["version"], a["minutes"],
            b["minutes"]),
        "",
        "The accuracy suite of docs/RESULTS.md (same scenes, seeds, variants and scoring) at "
        "%g cm voxels, mapped twice: **every**, `integrator.vote_stride_px: %d` (every "
        "labelled pixel votes in its point's voxel); **auto**, `vote_stride_px: %d` (%s). "
        "Issue 23 allows the coarse-voxel votes if mAP50 stays within %.1f points on every "
        "scene. Each suite's full report: `%s/{every,automatic}/RESULTS.md`." % (
            100 * args.voxel_size, stride_a, stride_b,
            "automatic: floor(voxel x fx / (2 x max depth)), 3 for these 525 px cameras"
            if stride_b == 0 else "what automatic gives for these 525 px cameras at 5 cm",
            TOLERANCE, os.path.relpath(args.work, suite.ROOT)),
        "",
        "## Integration time",
        "",
        "`panmap-bench-mapping --data %s --voxel-size %g --outputs-every 0` with "
        "`vote_stride_px` 1 and 0 (automatic: 4 for 7-Scenes' 585 px focal length): median per frame of the integration stage (TSDF, colour and label votes), median of "
        "%d runs, on this machine (%s, %d cores)." % (
            os.path.relpath(args.data, suite.ROOT), args.voxel_size, args.runs, cpu_name(),
            os.cpu_count() or 0),
        "",
        "| threads | every pixel votes, ms | automatic stride, ms | ratio |",
        "|---:|---:|---:|---:|",
    ] + ["| %d | %.2f | %.2f | %.2fx |" % (t, speed["every"][i], speed["automatic"][i],
                                          speed["every"][i] / speed["automatic"][i])
         for i, t in enumerate((1, 2))] + [
        "",
        "## Per scene and annotation (mean over its runs: seeds, poses, masks)",
        "",
        "| scene | runs | full mAP50: every / auto | difference | all variants: mean "
        "difference | largest run difference (full) | full mIoU: every / auto |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    scenes = []
    for r in runs:
        if scene_of(r) not in scenes:
            scenes.append(scene_of(r))
    verdicts = []
    for scene in scenes:
        mine = [r for r in runs if scene_of(r) == scene]
        full_a = mean([score(a["results"][r], "full") for r in mine])
        full_b = mean([score(b["results"][r], "full") for r in mine])
        diffs = []
        for r in mine:
            for v, _, _ in VARIANTS:
                x, y = score(a["results"][r], v), score(b["results"][r], v)
                if x is not None and y is not None:
                    diffs.append(y - x)
        run_diffs = [score(b["results"][r], "full") - score(a["results"][r], "full")
                     for r in mine]
        worst = max(run_diffs, key=abs)
        miou_a = mean([score(a["results"][r], "full", "miou_gt_classes") for r in mine])
        miou_b = mean([score(b["results"][r], "full", "miou_gt_classes") for r in mine])
        verdicts.append((scene, full_b - full_a))
        lines.append("| %s | %d | %s / %s | %+.1f | %+.1f | %+.1f | %s / %s |" % (
            scene, len(mine), fmt(full_a), fmt(full_b), full_b - full_a, mean(diffs), worst,
            fmt(miou_a), fmt(miou_b)))
    all_a = mean([score(a["results"][r], "full") for r in runs])
    all_b = mean([score(b["results"][r], "full") for r in runs])
    lines += ["| **all** | %d | %s / %s | %+.1f | | | |" % (len(runs), fmt(all_a), fmt(all_b),
                                                            all_b - all_a), ""]
    failing = [s for s, d in verdicts if abs(d) > TOLERANCE]
    lines.append("Within %.1f mAP50 points on every scene: %s." % (
        TOLERANCE, "yes" if not failing else "**no** (%s)" % ", ".join(
            "%s %+.1f" % (s, d) for s, d in verdicts if s in failing)))
    lines += ["", "## Ground-truth objects whose outcome changed (full method)", "",
              "Outcome as docs/RESULTS.md's miss analysis names it; best IoU with an object of "
              "its class, every / auto.", "",
              "| run | GT instance | class | vertices | every | auto | best IoU |",
              "|---|---:|---:|---:|---|---|---|"]
    near, flips, lost, gained = 0, 0, 0, 0
    for r in runs:
        things = [{t["instance_id"]: t for t in x["results"][r]["results"]["full"].get(
            "diagnostics", {}).get("gt_things", [])} for x in (a, b)]
        for iid, t in sorted(things[0].items()):
            u = things[1].get(iid)
            if u is None or u["cause"] == t["cause"]:
                continue
            flips += 1
            iou = (t["best_same_class_iou"], u["best_same_class_iou"])
            near += all(abs(v - 0.5) <= 0.05 for v in iou)
            lost += t["cause"] == "matched"
            gained += u["cause"] == "matched"
            lines.append("| %s | %d | %d | %d | %s | %s | %.2f / %.2f |" % (
                r, iid, t["class_id"], t["vertices"], t["cause"], u["cause"], iou[0], iou[1]))
    lines += ["", "%d changes over %d runs: %d matches lost, %d gained; %d of the changes have "
              "the best IoU within 0.05 of the 0.5 threshold both times." % (
                  flips, len(runs), lost, gained, near)]
    lines += ["", "## Per run (full method, mAP50)", "",
              "| run | every | auto | difference |", "|---|---:|---:|---:|"]
    for r in runs:
        x, y = score(a["results"][r], "full"), score(b["results"][r], "full")
        lines.append("| %s | %s | %s | %+.1f |" % (r, fmt(x), fmt(y), y - x))
    with open(args.out, "w") as f:
        f.write("\n".join(lines) + "\n")
    print("vote_stride: wrote %s" % args.out, file=sys.stderr)


if __name__ == "__main__":
    main()
