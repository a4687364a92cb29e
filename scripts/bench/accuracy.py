#!/usr/bin/env python3
"""panmap's accuracy suite: seeded procedural rooms x {gt, slam} poses x {clean, m2f} masks x
method variants (full, the paper's ablations, a Voxblox++-like baseline), scored with
panmap-eval, written as docs/RESULTS.md in the layout of the paper's tables.

Every number in docs/RESULTS.md comes from this script; rerun it to regenerate the file.
Sequences are cached in the work folder (keyed by their parameters), maps are rebuilt.
"""
import argparse
import concurrent.futures
import datetime
import json
import os
import platform
import shutil
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BUILD = os.path.join(ROOT, "build")

# Rooms whose numbers are reported. Rooms used to choose defaults (scripts/bench/tune_refinement.py)
# are different seeds and never appear here.
REPORT_ROOMS = [3, 4, 5]
POSES = ["gt", "slam"]
MASKS = ["clean", "m2f"]
# Variant -> (map, extra optimiser flags). Map A: semantically consistent super-points (III-B);
# map B: spatial-only merging. Both run the same per-frame pipeline otherwise.
VARIANTS = [
    ("full", "A", []),
    ("w/o III-B", "B", []),
    ("w/o III-C", "A", ["--no-regularise"]),
    ("w/o III-D", "A", ["--no-refine"]),
    ("w/o III-C & III-D", "A", ["--no-regularise", "--no-refine"]),
    ("Voxblox++-like", "B", ["--no-regularise", "--no-refine"]),
]
# Extra rows: the full method with pose refinement against the map (issue 8), run where the
# poses drift; and a harder drift setting with the full method only.
REFINED = "full + pose refinement"
EXTRA_SETTINGS = [("slam-hard", "m2f")]
METRICS = [("mAP50", "map50", "pct"), ("mAP75", "map75", "pct"), ("N_TP50", "ntp50", "sum"),
           ("N_TP75", "ntp75", "sum"), ("PQ50", "pq50", "pct"), ("PQ75", "pq75", "pct"),
           ("IoU_LS", "iou_ls", "pct")]


def run(cmd, log=None):
    """Runs a command; raises with its output on failure."""
    result = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if log:
        with open(log, "a") as f:
            f.write("$ " + " ".join(cmd) + "\n" + result.stdout)
    if result.returncode != 0:
        raise RuntimeError("failed (%d): %s\n%s" % (result.returncode, " ".join(cmd),
                                                    result.stdout[-2000:]))
    return result.stdout


def tool(name):
    return os.path.join(BUILD, name)


def sequence(work, room, poses, masks, frames, rate_hz):
    """Renders (or reuses) one sequence; returns its folder."""
    name = "room%d_%s_%s_%df_%gHz" % (room, poses, masks, frames, rate_hz)
    folder = os.path.join(work, "seq", name)
    if os.path.exists(os.path.join(folder, "info.json")):
        return folder
    shutil.rmtree(folder, ignore_errors=True)
    run([tool("panmap-synth"), "--room", str(room), "--seed", str(room), "--frames", str(frames),
         "--rate-hz", str(rate_hz), "--masks", masks, "--poses", poses, "-q", "--out", folder])
    return folder


def evaluate(pred_dir, seq_dir):
    """Scores a mapper output folder against the sequence's ground truth."""
    cmd = [tool("panmap-eval"), "--pred", os.path.join(pred_dir, "mesh_instance.ply"),
           "--gt", os.path.join(seq_dir, "gt", "mesh.ply"),
           "--json", os.path.join(pred_dir, "eval.json")]
    objects = os.path.join(pred_dir, "objects.json")
    if os.path.exists(objects):
        cmd += ["--confidences", objects]
    run(cmd)
    with open(os.path.join(pred_dir, "eval.json")) as f:
        return json.load(f)


def map_sequence(work, seq_dir, voxel_m, extra_mapper_flags, config):
    """Maps one sequence twice (A, B), exports every variant, evaluates them."""
    name = os.path.basename(seq_dir)
    out = os.path.join(work, "runs", name)
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    log = os.path.join(out, "commands.log")
    base = [tool("panmap-mapper"), "-q", "--voxel-size", str(voxel_m), "--threads", "1",
            "--no-snapshots", "--tracking", "off"] + extra_mapper_flags
    if config:
        base += ["--config", config]
    log_path = os.path.join(seq_dir, "sequence.lcmlog")
    with open(os.path.join(seq_dir, "info.json")) as f:
        info = json.load(f)
    drifting = info["poses"]["preset"] != "gt"
    only_full = (info["poses"]["preset"], info["masks"]["preset"]) in EXTRA_SETTINGS
    results = {}
    trajectory = {}
    if drifting:
        refined = os.path.join(out, "A_refined")
        run(base[:-2] + ["--tracking", "auto", "--log", log_path, "--out", refined], log)
        results[REFINED] = evaluate(refined, seq_dir)
        for name, traj in (("input", os.path.join(seq_dir, "gt", "trajectory_input.txt")),
                           ("refined", os.path.join(refined, "trajectory.txt"))):
            target = os.path.join(out, "ate_%s.json" % name)
            run([tool("panmap-eval"), "--traj", traj, "--gt-traj",
                 os.path.join(seq_dir, "gt", "trajectory_gt.txt"), "--json", target], log)
            with open(target) as f:
                trajectory[name] = json.load(f)["trajectory"]["ate_m"]["rmse"]
    run(base + ["--log", log_path, "--out", os.path.join(out, "A")], log)
    if not only_full:
        run(base + ["--log", log_path, "--spatial-only", "--no-regularise", "--no-refine",
                    "--out", os.path.join(out, "B")], log)
    for variant, source, flags in VARIANTS:
        if only_full and variant != "full":
            continue
        folder = os.path.join(out, variant.replace("/", "").replace(" ", "_").replace("&", "and"))
        if source == "A" and not flags:
            folder = os.path.join(out, "A")
        elif source == "B" and flags:
            folder = os.path.join(out, "B")
        else:
            cmd = [tool("panmap-mapper"), "-q", "--no-snapshots", "--export-only",
                   "--load", os.path.join(out, source, "map.panmap"), "--out", folder] + flags
            if config:
                cmd += ["--config", config]
            run(cmd, log)
        results[variant] = evaluate(folder, seq_dir)
    with open(os.path.join(out, "A", "report.json")) as f:
        report = json.load(f)
    return {"results": results, "input_ate_m": info["measured"]["input_ate_rmse_m"],
            "trajectory_ate_m": trajectory,
            "coverage": info["coverage"]["fraction_seen_from_3_views"],
            "total_ms": report["timings"]["total"]["median_ms"]}


def job(args, room, poses, masks):
    start = time.time()
    seq = sequence(args.work, room, poses, masks, args.frames, args.rate_hz)
    out = map_sequence(args.work, seq, args.voxel_size, [], args.config)
    if not args.keep_logs:
        os.remove(os.path.join(seq, "sequence.lcmlog"))
        os.rename(os.path.join(seq, "info.json"), os.path.join(seq, "info.json.done"))
    print("accuracy: room %d, %s poses, %s masks: full mAP50 %.1f (%.0f s)" %
          (room, poses, masks, 100 * (out["results"]["full"]["map50"] or 0), time.time() - start),
          file=sys.stderr, flush=True)
    return out


def mean(values):
    values = [v for v in values if v is not None]
    return sum(values) / len(values) if values else float("nan")


def table(rows_by_variant, rooms):
    lines = ["| Method | " + " | ".join(m[0] for m in METRICS) + " |",
             "|---|" + "---:|" * len(METRICS)]
    for variant in [v for v, _, _ in VARIANTS] + [REFINED]:
        if variant not in rows_by_variant:
            continue
        cells = []
        for _, key, kind in METRICS:
            values = [rows_by_variant[variant][r][key] for r in rooms]
            if kind == "sum":
                cells.append("%d" % sum(v or 0 for v in values))
            else:
                cells.append("%.1f" % (100 * mean(values)))
        lines.append("| %s | %s |" % (variant, " | ".join(cells)))
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--work", default=os.path.join(BUILD, "accuracy"),
                        help="folder for sequences and maps (default build/accuracy)")
    parser.add_argument("--out", default=os.path.join(ROOT, "docs", "RESULTS.md"))
    parser.add_argument("--rooms", default=",".join(map(str, REPORT_ROOMS)))
    parser.add_argument("--frames", type=int, default=450)
    parser.add_argument("--rate-hz", type=float, default=5.0)
    parser.add_argument("--voxel-size", type=float, default=0.02)
    parser.add_argument("--config", default="", help="YAML config for every mapper run")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 2)
    parser.add_argument("--keep-logs", action="store_true",
                        help="keep the rendered logs (150 MB each) for reruns")
    args = parser.parse_args()
    rooms = [int(r) for r in args.rooms.split(",")]
    if args.config:
        args.config = os.path.abspath(args.config)
    start = time.time()
    settings = [(p, m) for p in POSES for m in MASKS]
    all_settings = settings + EXTRA_SETTINGS
    futures = {}
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        for room in rooms:
            for poses, masks in all_settings:
                futures[(room, poses, masks)] = pool.submit(job, args, room, poses, masks)
        results = {key: f.result() for key, f in futures.items()}
    minutes = (time.time() - start) / 60

    commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"],
                            stdout=subprocess.PIPE, text=True).stdout.strip() or "unknown"
    dirty = subprocess.run(["git", "-C", ROOT, "status", "--porcelain", "--untracked-files=no"],
                           stdout=subprocess.PIPE, text=True).stdout.strip()
    cpu = "unknown"
    with open("/proc/cpuinfo") as f:
        for line in f:
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    md = ["# Accuracy", "",
          "Generated by `scripts/bench/accuracy.sh` (do not edit by hand) on %s, commit `%s`%s, "
          "%s, %d cores, in %.1f minutes." % (datetime.date.today().isoformat(), commit,
                                               " (with local changes)" if dirty else "", cpu,
                                               os.cpu_count(), minutes), "",
          "Command: `scripts/bench/accuracy.sh %s`" % " ".join(sys.argv[1:]), "",
          "Sequences: `panmap-synth` procedural rooms %s (room seed = sequence seed), %d frames "
          "at %g Hz (a %.0f s survey), 640x480 with depth noise; maps at %g cm voxels. "
          "Metrics from `panmap-eval` (ScanNet's `evaluate_semantic_instance` matching, the 18 "
          "ScanNet classes, label transfer within 5 cm): mAP and PQ are class averages over "
          "the rooms' mean, N_TP is summed over classes and rooms, all in percent except N_TP. "
          "Rooms used to choose defaults (docs/TUNING.md) are other seeds." %
          (", ".join(map(str, rooms)), args.frames, args.rate_hz, args.frames / args.rate_hz,
           100 * args.voxel_size), "",
          "Variants: **full** = semantically consistent super-points (III-B), graph "
          "regularisation (III-C) and instance refinement (III-D); **w/o III-B** = spatial-only "
          "super-point merging; **w/o III-C** = no semantic regularisation; **w/o III-D** = no "
          "instance refinement; **Voxblox++-like** = spatial-only merging and frame-count labels, "
          "no graph optimisation. All of these map the poses as given (`--tracking off`). "
          "**%s** (not in the paper) = the full method refining each SLAM pose against the map "
          "before integrating it (`--tracking auto`, the default for poses flagged as SLAM)." %
          REFINED, ""]
    for poses, masks in all_settings:
        keyed = [results[(r, poses, masks)] for r in rooms]
        rows = {v: {r: results[(r, poses, masks)]["results"][v] for r in rooms}
                for v in keyed[0]["results"]}
        title = {"gt": "Ground-truth poses", "slam": "SLAM-like (`slam`) poses",
                 "slam-hard": "Harder drift (`slam-hard`) poses"}[poses]
        md += ["## %s, %s masks" % (title, masks), ""]
        if poses != "gt":
            md += ["ATE (RMSE after rigid alignment, mean over rooms): input %.2f cm, refined "
                   "against the map %.2f cm (%s)." % (
                       100 * mean([k["trajectory_ate_m"]["input"] for k in keyed]),
                       100 * mean([k["trajectory_ate_m"]["refined"] for k in keyed]),
                       ", ".join("room %d: %.2f -> %.2f" % (
                           r, 100 * k["trajectory_ate_m"]["input"],
                           100 * k["trajectory_ate_m"]["refined"]) for r, k in zip(rooms, keyed))),
                   ""]
        md += [table(rows, rooms), ""]
    # Drift: how much of the gap to ground-truth poses the refinement recovers.
    md += ["## Pose refinement: the gap to ground-truth poses", "",
           "mAP50 of the full method (m2f masks, mean over rooms); recovered = (refined - "
           "drifting) / (ground truth - drifting).", "",
           "| Poses | ground truth | drifting, as given | refined against the map | recovered |",
           "|---|---:|---:|---:|---:|"]
    gt_map = mean([results[(r, "gt", "m2f")]["results"]["full"]["map50"] for r in rooms])
    for poses in ["slam", "slam-hard"]:
        raw = mean([results[(r, poses, "m2f")]["results"]["full"]["map50"] for r in rooms])
        ref = mean([results[(r, poses, "m2f")]["results"][REFINED]["map50"] for r in rooms])
        gap = gt_map - raw
        md.append("| %s | %.1f | %.1f | %.1f | %s |" % (
            poses, 100 * gt_map, 100 * raw, 100 * ref,
            "%.0f %%" % (100 * (ref - raw) / gap) if gap > 1e-9 else "-"))
    md.append("")
    md += ["## Per room (full method, mAP50 / PQ50)", "",
           "| Room | " + " | ".join("%s, %s" % s for s in settings) + " | coverage | ms/frame |",
           "|---|" + "---:|" * (len(settings) + 2)]
    for r in rooms:
        cells = ["%.1f / %.1f" % (100 * (results[(r, p, m)]["results"]["full"]["map50"] or 0),
                                  100 * (results[(r, p, m)]["results"]["full"]["pq50"] or 0))
                 for p, m in settings]
        first = results[(r,) + settings[0]]
        md.append("| %d | %s | %.2f | %.1f |" % (r, " | ".join(cells), first["coverage"],
                                                  first["total_ms"]))
    md.append("")
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    with open(args.out, "w") as f:
        f.write("\n".join(md))
    with open(os.path.join(args.work, "results.json"), "w") as f:
        json.dump({"%d_%s_%s" % k: v for k, v in results.items()}, f, indent=1)
    print("accuracy: wrote %s in %.1f minutes" % (args.out, minutes), file=sys.stderr)


if __name__ == "__main__":
    main()
