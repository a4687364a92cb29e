#!/usr/bin/env python3
"""Pose refinement on real depth (issue 20): every real sequence in ../shared/data, with drift
injected into its recorded poses, mapped with and without refinement.

For each sequence, drift level (none, light, heavy: panmap-import --drift, docs/SIMULATION.md),
seed and voxel size: the input's and the refined trajectory's ATE against the recorded poses,
two reference-free consistency figures (the mesh surface area of the map: misaligned frames double
surfaces, so the more consistent trajectory gives less area; the map from the recorded poses is
the reference's own figure; and panmap-consistency's photometric residual of the recorded, input
and refined trajectories, which colour judges independently of depth-based tracking), the frames whose correction was accepted / kept at the prediction,
and the tracking stage's median milliseconds per frame. Writes the section between the
refinement markers of docs/RESULTS.md (accuracy.py keeps it when it rewrites the file).

  python3 scripts/bench/refinement.py [--data DIR] [--seeds 1,2,3] [--voxels 0.01,0.02]
"""
import argparse
import concurrent.futures
import glob
import struct
import json
import os
import re
import shutil
import subprocess
import sys
import time

import doc_section  # same folder

import suite

BEGIN = "<!-- refinement:begin (scripts/bench/refinement.py) -->"
END = "<!-- refinement:end -->"
DEFAULT_DATA = "../shared/data"  # as the report names the default --data
MIN_FRAMES = 30  # shorter folders (format fixtures) have no trajectory to speak of
MAX_FRAMES = 0  # --max-frames: frames imported and read per sequence, 0 for all
REFERENCES = {"7scenes": "KinectFusion (7-Scenes' recorded poses)",
              "scannet": "BundleFusion (ScanNet's recorded poses)",
              "scannet-sens": "BundleFusion (ScanNet's recorded poses)",
              "tum": "motion capture (TUM RGB-D ground truth)"}
# Why 7-Scenes' recorded poses are a reference, not the truth: published, not our finding.
SEVEN_SCENES_NOTE = (" 7-Scenes' poses are one choice among several: Brachmann et al. (\"On the "
                     "Limits of Pseudo Ground Truth in Visual Camera Re-localisation\", ICCV "
                     "2021) rebuilt them by structure from motion and found that the KinectFusion "
                     "and the SfM poses rank re-localisation methods differently.")


def sens_frames(path):
    """Frame count in a ScanNet .sens file's header (SensReader's version 4 layout)."""
    with open(path, "rb") as f:
        version, name_bytes = struct.unpack("<IQ", f.read(12))
        if version != 4:
            return 0
        # The name, four 4x4 float matrices, two compression types, four sizes, depth shift.
        f.seek(12 + name_bytes + 4 * 64 + 8 + 16 + 4)
        return struct.unpack("<Q", f.read(8))[0]


def sequences(data_dir):
    """Real sequences under data_dir: (name, path, layout, frames); those with >= MIN_FRAMES
    poses found, the rest skipped. A ScanNet .sens recording counts as it lies there, or as
    the one .sens of a scan's folder."""
    found, skipped = [], []
    for folder in sorted(glob.glob(os.path.join(data_dir, "*"))):
        sens = glob.glob(os.path.join(folder, "*.sens")) if os.path.isdir(folder) else []
        if folder.endswith(".sens") and os.path.isfile(folder):
            layout, frames = "scannet-sens", sens_frames(folder)
        elif not os.path.isdir(folder):
            continue
        elif glob.glob(os.path.join(folder, "frame-*.pose.txt")):
            layout, frames = "7scenes", len(glob.glob(os.path.join(folder, "frame-*.pose.txt")))
        elif os.path.isdir(os.path.join(folder, "pose")):
            layout, frames = "scannet", len(glob.glob(os.path.join(folder, "pose", "*.txt")))
        elif os.path.isfile(os.path.join(folder, "groundtruth.txt")):
            layout, frames = "tum", sum(1 for _ in open(os.path.join(folder, "depth.txt")))
        elif len(sens) == 1:
            layout, frames = "scannet-sens", sens_frames(sens[0])
        else:
            continue
        name = os.path.basename(folder)
        if name.endswith(".sens"):
            name = name[:-len(".sens")]
        (found if frames >= MIN_FRAMES else skipped).append((name, folder, layout, frames))
    return found, skipped


def ate(traj, reference, fits=()):
    """RMSE ATE of traj against reference, metres; fits: panmap-eval's --fit-scale and
    --fit-camera-offset flags. With fits, also the fitted scale and |offset| (m)."""
    out = suite.run([suite.tool("panmap-eval"), "--traj", traj, "--gt-traj", reference] +
                    list(fits))
    m = re.search(r"ATE \[m\]\s+rmse ([0-9.]+)", out)
    if not m:
        raise RuntimeError("no ATE in panmap-eval output:\n" + out)
    if not fits:
        return float(m.group(1))
    scale = re.search(r"scale\s+([0-9.]+)\s+\(fitted\)", out)
    offset = re.search(r"\(\|d\| ([0-9.]+), fitted\)", out)
    return (float(m.group(1)), float(scale.group(1)) if scale else 1.0,
            float(offset.group(1)) if offset else 0.0)


# Alignments of a trajectory to an independent reference (name, panmap-eval flags): the rigid
# fit of the ATE, a similarity (the reference's scale need not be the sensor's), and either with
# a constant camera offset (the reference may be of another camera of the rig).
ALIGNMENTS = [("rigid", []), ("similarity", ["--fit-scale"]),
              ("rigid + camera offset", ["--fit-camera-offset"]),
              ("similarity + camera offset", ["--fit-scale", "--fit-camera-offset"])]


# Pose refinement settings: name -> (--tracking, extra panmap-mapper arguments). `auto` is the
# default: the depth check decides whether the poses are corrected. `per_frame` and `filter`
# force refinement past it (tracking on; tracking.correction per_frame or filter).
# `calibrated` is the default with the depth calibration panmap-calibrate-depth learns from
# the same log (calibration_path()), which auto trusts.
CORRECTIONS = {"auto": ("auto", []),
               "per_frame": ("on", []),
               "filter": ("on", ["--config",
                                 os.path.join(suite.ROOT, "configs", "drift_filter.yaml")]),
               "calibrated": ("auto", [])}
# Frames mapped at their given pose before tracking starts (tracking.warmup_frames).
WARMUP_FRAMES = 5


def calibration_path(work, tag):
    return os.path.join(work, tag + ".depth_calibration.json")


def map_run(log, out_dir, voxel, tracking, extra=()):
    suite.run([suite.tool("panmap-mapper"), "--log", log, "--out", out_dir, "--voxel-size",
               str(voxel), "--geometry-only", "--no-snapshots", "--tracking", tracking] +
              list(extra), log=os.path.join(out_dir + ".log"))
    with open(os.path.join(out_dir, "report.json")) as f:
        report = json.load(f)
    for name in ("map.panmap", "mesh_semantic.ply", "mesh_instance.ply", "mesh_superpoint.ply",
                 "occupancy.bt"):
        path = os.path.join(out_dir, name)
        if os.path.exists(path):
            os.remove(path)
    return report


def photometric(folder, trajectories):
    """panmap-consistency's median |grey-level residual| of each trajectory, all scored on the
    same pixels."""
    out = suite.run([suite.tool("panmap-consistency"), "--data", folder, "--max-frames",
                     str(MAX_FRAMES)] + [a for t in trajectories for a in ("--traj", t)])
    values = []
    for t in trajectories:
        m = re.search(re.escape(t) + r": median \|residual\| ([0-9.]+)", out)
        if not m:
            raise RuntimeError("no photometric figure for %s in:\n%s" % (t, out))
        values.append(float(m.group(1)))
    return values


def one(work, name, folder, drift, seed, voxel, correction):
    """Maps with tracking auto (the poses are flagged slam) and the correction model, and with
    tracking off; returns the row."""
    tag = "%s_%s_s%d" % (name, drift, seed)
    log = os.path.join(work, tag + ".lcmlog")  # written by one_import()
    reference = os.path.join(work, tag + ".reference.txt")
    base = os.path.join(work, "%s_%gcm_%s" % (tag, voxel * 100, correction))
    mode, extra = CORRECTIONS[correction]
    extra = list(extra)
    if correction == "calibrated":
        extra += ["--depth-calibration", calibration_path(work, tag)]
    refined = map_run(log, base + "_auto", voxel, mode, extra)
    raw = map_run(log, base + "_off", voxel, "off")
    check = refined["depth_check"]
    corrected = check["poses_corrected"]
    kept = refined["frames_integrated"] - WARMUP_FRAMES - corrected
    photo = photometric(folder, [reference, os.path.join(work, tag + ".input.txt"),
                                 os.path.join(base + "_auto", "trajectory.txt")])
    return {
        "sequence": name, "drift": drift, "seed": seed, "voxel_m": voxel,
        "correction": correction,
        "input_ate_m": ate(os.path.join(work, tag + ".input.txt"), reference),
        "refined_ate_m": ate(os.path.join(base + "_auto", "trajectory.txt"), reference),
        "input_area_m2": raw["mesh"]["area_m2"], "refined_area_m2": refined["mesh"]["area_m2"],
        "corrected": corrected, "kept": kept,
        "limit_mm": check["limit_mm"],
        "depth_check": ("calibration" if correction == "calibrated" else
                        "-" if mode == "on" else
                        "%s, %.2f mm" % (check["verdict"], check["pattern_mm"] or 0.0)),
        "photometric_reference": photo[0], "photometric_input": photo[1],
        "photometric_refined": photo[2],
        "tracking_ms": refined["timings"].get("tracking", {}).get("median_ms", 0.0),
    }


def add_independent(rows, work, references):
    """With references {sequence: TUM file} (poses that owe nothing to depth tracking, e.g. the
    SfM poses of Brachmann et al. for 7-Scenes), each row's input, refined and recorded
    trajectories' ATE against them (rigid fit; the trajectories of WORK)."""
    for r in rows:
        ref = references.get(r["sequence"])
        if not ref:
            continue
        tag = "%s_%s_s%d" % (r["sequence"], r["drift"], r["seed"])
        base = os.path.join(work, "%s_%gcm_%s" % (tag, r["voxel_m"] * 100, r["correction"]))
        r["independent_recorded_m"] = ate(os.path.join(work, tag + ".reference.txt"), ref)
        r["independent_input_m"] = ate(os.path.join(work, tag + ".input.txt"), ref)
        r["independent_refined_m"] = ate(os.path.join(base + "_auto", "trajectory.txt"), ref)
        # Each alignment: [recorded, input, refined] of (ATE m, scale, |offset| m).
        r["independent_fits"] = {
            name: [ate(t, ref, fits) for t in (os.path.join(work, tag + ".reference.txt"),
                                                os.path.join(work, tag + ".input.txt"),
                                                os.path.join(base + "_auto", "trajectory.txt"))]
            for name, fits in ALIGNMENTS[1:]}


def verdict(row):
    """The issue's acceptance line for the row."""
    i, r = row["input_ate_m"], row["refined_ate_m"]
    if row["drift"] == "none":
        return r <= i + 0.002, "<= input + 0.2 cm"
    if row["drift"] == "light":
        return r <= 0.7 * i, "<= 0.7 x input"
    return r <= 0.4 * i, "<= 0.4 x input"


def limits(rows):
    """The depth check's limit the rows were mapped with (rows of before it was recorded: the
    1 mm it was then)."""
    values = sorted({r.get("limit_mm", 1.0) for r in rows if r["correction"] == "auto"})
    return " / ".join("%g mm" % v for v in values) or "its limit"


def data_label(data_dir):
    """How the report names the data folder: DEFAULT_DATA for the default one."""
    default = os.path.join(suite.ROOT, "..", "shared", "data")
    return DEFAULT_DATA if os.path.abspath(data_dir) == os.path.abspath(default) else data_dir


def render(rows, skipped, layouts, seconds, data=DEFAULT_DATA):
    md = [BEGIN, "## Pose refinement on real depth", "",
          "`python3 scripts/bench/refinement.py%s` (%.1f min on this machine): every real "
          "sequence in `%s` with at least %d frames, its recorded poses replaced by "
          "`panmap-import --drift LEVEL --seed N` (none; light: 1 %%/m, 0.5 deg/m; heavy: 3x), "
          "mapped geometry-only (the poses are flagged SLAM) four ways: `auto`, the default "
          "(`tracking: auto`: the first 30 aligned frames judge the depth; a fixed depth error "
          "pattern above %s integrates them again at their given poses and keeps every later "
          "pose as given, column *depth check*, docs/MAPPING.md); `per_frame`, refinement forced past that check (`--tracking "
          "on`), each aligned pose used as it is; `filter`, forced with "
          "`configs/drift_filter.yaml`, a smooth drift estimate; `calibrated`, the default with "
          "the depth sensor's calibration that `panmap-calibrate-depth --first N/2` learnt from "
          "the same drifted log, its second half only, with no poses but the log's own refined "
          "by tracking (auto trusts a calibrated sensor), docs/MAPPING.md; and with `--tracking "
          "off`. ATE is against the recorded poses, **which are themselves "
          "estimates**: %s.%s Corrected / kept: frames integrated at a corrected pose / at the "
          "given or predicted one (after the 5 warm-up frames). ms: median of the tracking "
          "stage per frame, runs two at a time on 2 cores." % (
              ("" if data == DEFAULT_DATA else " --data " + data) +
              (" --max-frames %d" % MAX_FRAMES if MAX_FRAMES else ""), seconds / 60.0, data,
              MIN_FRAMES, limits(rows),
              "; ".join("%s: %s" % (n, REFERENCES.get(l, l)) for n, l in layouts),
              SEVEN_SCENES_NOTE if any(l == "7scenes" for _, l in layouts) else ""), "",
          "Two reference-free figures judge a trajectory without trusting the recorded one. "
          "**Area**: the mesh surface area of its map (misaligned frames double surfaces, so less "
          "is more consistent; *reference map* is the map from the recorded poses). "
          "**Photometric**: `panmap-consistency`, the median grey-level difference between each "
          "frame's textured pixels and where the trajectory's poses carry them in the frames 1, 3, "
          "10 and 30 later (after a per-pair exposure offset), every trajectory of a row scored on "
          "the same pixels; lower is more consistent. Colour plays no part in depth-based "
          "tracking, ours or the recorded poses' (KinectFusion tracks depth only), so it judges "
          "the directions along a surface that depth alignment cannot see. Its floor is not 0: "
          "7-Scenes colour is not registered to depth (treated as registered), and appearance "
          "changes with viewpoint.", ""]
    if skipped:
        md += ["Skipped (fewer than %d frames): %s." % (
            MIN_FRAMES, ", ".join("%s (%d)" % (s[0], s[3]) for s in skipped)), ""]
    for correction in sorted({r["correction"] for r in rows}):
        photo_rows = [r for r in rows
                      if r["correction"] == correction and "photometric_refined" in r]
        if not photo_rows:
            continue
        better = sum(1 for r in photo_rows
                     if r["photometric_refined"] < r["photometric_reference"])
        inputs = sum(1 for r in photo_rows if r["photometric_refined"] < r["photometric_input"])
        diff = [r["photometric_refined"] - r["photometric_reference"] for r in photo_rows]
        md += ["Photometric consistency, `%s`: the refined trajectory is more consistent than "
               "the recorded poses in %d of %d rows and than its own input in %d of %d (refined "
               "- recorded: %+.2f to %+.2f grey levels)." % (
                   correction, better, len(photo_rows), inputs, len(photo_rows), min(diff),
                   max(diff)), ""]
    independent = any("independent_refined_m" in r for r in rows)
    if independent:
        md += ["**Independent reference** (column *vs independent*): ATE after a rigid fit against "
               "poses that owe nothing to depth tracking, given with `--independent "
               "SEQUENCE=TUM`: for 7scenes-200 the structure-from-motion poses of Brachmann et "
               "al. (`pgt/sfm/7scenes/redkitchen_train.txt` of "
               "github.com/tsattler/visloc_pseudo_gt_limitations, `scripts/bench/"
               "colmap_poses_to_tum.py FILE sfm.txt --select seq-01/ --stride 3`), which are "
               "poses of the colour camera (the others: of the depth camera; a constant offset "
               "no rigid fit removes, the same for every trajectory): recorded / input / "
               "refined, cm.", ""]
    md += ["| sequence | voxel | drift | seed | correction | input ATE cm | refined ATE cm | "
           "target | %sarea m2: reference map / input / refined | photometric: recorded / input "
           "/ refined | depth check | corrected / kept | ms |" % (
               "vs independent | " if independent else ""),
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|" + ("---|" if independent else "")]
    reference_area = {(r["sequence"], r["voxel_m"]): r["input_area_m2"]
                      for r in rows if r["drift"] == "none"}
    for r in rows:
        ok, target = verdict(r)
        extra = ""
        if independent:
            extra = ("%.2f / %.2f / %.2f | " % (r["independent_recorded_m"] * 100,
                                                r["independent_input_m"] * 100,
                                                r["independent_refined_m"] * 100)
                     if "independent_refined_m" in r else "- | ")
        md.append("| %s | %g cm | %s | %s | %s | %.2f | %.2f | %s %s | %s%.2f / %.2f / %.2f | "
                  "%.2f / %.2f / %.2f | %s | %d / %d | %.1f |" % (
                      r["sequence"], r["voxel_m"] * 100, r["drift"],
                      "-" if r["drift"] == "none" else r["seed"], r["correction"],
                      r["input_ate_m"] * 100,
                      r["refined_ate_m"] * 100, target, "yes" if ok else "**no**", extra,
                      reference_area.get((r["sequence"], r["voxel_m"]), float("nan")),
                      r["input_area_m2"], r["refined_area_m2"],
                      r.get("photometric_reference", float("nan")),
                      r.get("photometric_input", float("nan")),
                      r.get("photometric_refined", float("nan")), r.get("depth_check", "-"),
                      r["corrected"], r["kept"],
                      r["tracking_ms"]))
    fitted = [r for r in rows if "independent_fits" in r]
    if fitted:
        md += ["", "### Against the independent reference, aligned four ways", "",
               "The rigid fit above cannot remove a scale difference (the reference's structure "
               "from motion is scaled to metres by its own choice, the depth sensor by its "
               "calibration) or a lever arm between the depth camera the trajectories track and "
               "the colour camera the reference poses. The same trajectories, aligned each way "
               "(`panmap-eval --fit-scale`, `--fit-camera-offset`): ATE recorded / input / "
               "refined, cm. Counts in the order of the columns below:"]
        def independent(r, name, which):
            """ATE of the row's recorded (0), input (1) or refined (2) trajectory, metres."""
            if name == "rigid":
                return r[("independent_recorded_m", "independent_input_m",
                          "independent_refined_m")[which]]
            return r["independent_fits"][name][which][0]

        for correction in sorted({r["correction"] for r in fitted}):
            rows_of = [r for r in fitted if r["correction"] == correction]
            counts, drifted = [], []
            for name, _ in ALIGNMENTS:
                still = [r for r in rows_of if r["drift"] == "none"]
                moved = [r for r in rows_of if r["drift"] != "none"]
                counts.append("%s %d of %d" % (name, sum(
                    1 for r in still if independent(r, name, 2) < independent(r, name, 0)),
                    len(still)))
                drifted.append("%d of %d" % (sum(
                    1 for r in moved if independent(r, name, 2) < independent(r, name, 1)),
                    len(moved)))
            md.append("- `%s`: no drift, refined closer than recorded: %s; drift injected, refined "
                      "closer than its input: %s;" % (correction, ", ".join(counts),
                                                      ", ".join(drifted)))
        # The recorded poses are the same in every row: their fit says what the alignments
        # absorb.
        recorded = fitted[0]["independent_fits"]
        md += ["", "Fitted to the recorded poses: scale %.3f (similarity), camera offset %.1f cm "
               "(rigid + offset), scale %.3f with offset %.1f cm (similarity + offset). The "
               "Kinect v1's two cameras are about 2.5 cm apart, so the offset fit absorbs more "
               "than a lever arm (colour-to-depth timing, the reference's own errors): no "
               "alignment makes this reference exact to the centimetre, and a ranking that "
               "holds under all four is what it can say." % (
                   recorded["similarity"][0][1], recorded["rigid + camera offset"][0][2] * 100,
                   recorded["similarity + camera offset"][0][1],
                   recorded["similarity + camera offset"][0][2] * 100), "",
               "| sequence | voxel | drift | seed | correction | " +
               " | ".join(name for name, _ in ALIGNMENTS) + " |",
               "|---|---|---|---|---|" + "---:|" * len(ALIGNMENTS)]
        for r in fitted:
            cells = ["%.2f / %.2f / %.2f" % tuple(independent(r, name, w) * 100 for w in range(3))
                     for name, _ in ALIGNMENTS]
            md.append("| %s | %g cm | %s | %s | %s | %s |" % (
                r["sequence"], r["voxel_m"] * 100, r["drift"],
                "-" if r["drift"] == "none" else r["seed"], r["correction"], " | ".join(cells)))
    md += ["", END]
    return "\n".join(md)


def splice(path, section):
    """Replaces the refinement section of path (or appends it)."""
    doc_section.splice(path, section, BEGIN, END)


def independent_files(pairs):
    out = {}
    for pair in pairs:
        name, sep, path = pair.partition("=")
        if not sep or not os.path.isfile(path):
            sys.exit("refinement: --independent wants SEQUENCE=FILE of an existing file: " + pair)
        out[name] = os.path.abspath(path)
    return out


def main():
    global MAX_FRAMES
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--data", default=os.path.join(suite.ROOT, "..", "shared", "data"))
    parser.add_argument("--seeds", default="1,2,3")
    parser.add_argument("--voxels", default="0.01,0.02")
    parser.add_argument("--drifts", default="none,light,heavy")
    parser.add_argument("--max-frames", type=int, default=0,
                        help="import at most this many frames of each sequence (0: all; a "
                             "ScanNet scan has thousands at 30 Hz)")
    parser.add_argument("--corrections", default="auto,per_frame,filter,calibrated")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--work", default=os.path.join(suite.BUILD, "refinement"))
    parser.add_argument("--out", default=os.path.join(suite.ROOT, "docs", "RESULTS.md"))
    parser.add_argument("--independent", action="append", default=[], metavar="SEQUENCE=TUM",
                        help="also score against poses that owe nothing to depth tracking "
                             "(repeatable)")
    parser.add_argument("--report-only", action="store_true",
                        help="map nothing: rewrite the section from WORK/results.json")
    args = parser.parse_args()
    if args.report_only:
        with open(os.path.join(args.work, "results.json")) as f:
            saved = json.load(f)
        MAX_FRAMES = saved.get("max_frames", 0)
        found, skipped = sequences(args.data)
        add_independent(saved["rows"], args.work, independent_files(args.independent))
        splice(args.out, render(saved["rows"], skipped, [(f[0], f[2]) for f in found],
                                saved["seconds"], data_label(args.data)))
        print("refinement: rewrote %s from %s" % (args.out, args.work), file=sys.stderr)
        return
    suite.run(["cmake", "--build", suite.BUILD, "--target", "panmap-import", "panmap-mapper",
               "panmap-eval", "panmap-consistency", "panmap-calibrate-depth"])
    found, skipped = sequences(args.data)
    if not found:
        sys.exit("refinement: no real sequence with >= %d frames under %s" % (MIN_FRAMES,
                                                                           args.data))
    MAX_FRAMES = args.max_frames
    if MAX_FRAMES:
        found = [(n, f, l, min(c, MAX_FRAMES)) for n, f, l, c in found]
    if os.path.isdir(args.work):
        shutil.rmtree(args.work)
    os.makedirs(args.work)
    seeds = [int(s) for s in args.seeds.split(",")]
    voxels = [float(v) for v in args.voxels.split(",")]
    jobs = []
    for name, folder, _, _ in found:
        for voxel in voxels:
            for drift in args.drifts.split(","):
                for seed in ([seeds[0]] if drift == "none" else seeds):
                    for correction in args.corrections.split(","):
                        jobs.append((name, drift, seed, voxel, correction))
    folders = {name: folder for name, folder, _, _ in found}
    start = time.time()
    # Imports first (one per sequence, drift and seed), so parallel maps never race on a log.
    imports = sorted({j[:3] for j in jobs})
    frames = {name: count for name, _, _, count in found}
    calibrate = "calibrated" in args.corrections.split(",")
    with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
        list(pool.map(lambda j: one_import(args.work, j[0], folders[j[0]], *j[1:],
                                           calibrate_from=frames[j[0]] // 2 if calibrate
                                           else None), imports))
    rows = []
    with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
        futures = [pool.submit(one, args.work, j[0], folders[j[0]], *j[1:]) for j in jobs]
        for n, future in enumerate(futures):
            rows.append(future.result())
            r = rows[-1]
            print("refinement: %d/%d %s %s seed %d %g cm %s: ATE %.2f -> %.2f cm, area %.2f -> %.2f"
                  ", photometric %.2f (reference %.2f) -> %.2f"
                  % (n + 1, len(jobs), r["sequence"], r["drift"], r["seed"], r["voxel_m"] * 100,
                     r["correction"],
                     r["input_ate_m"] * 100, r["refined_ate_m"] * 100, r["input_area_m2"],
                     r["refined_area_m2"], r["photometric_input"], r["photometric_reference"],
                     r["photometric_refined"]), file=sys.stderr)
    seconds = time.time() - start
    add_independent(rows, args.work, independent_files(args.independent))
    with open(os.path.join(args.work, "results.json"), "w") as f:
        json.dump({"rows": rows, "seconds": seconds, "max_frames": MAX_FRAMES}, f, indent=1)
    section = render(rows, skipped, [(f[0], f[2]) for f in found], seconds, data_label(args.data))
    splice(args.out, section)
    print(section)
    print("refinement: wrote %s" % args.out, file=sys.stderr)


def one_import(work, name, folder, drift, seed, calibrate_from=None):
    """Imports the sequence with drift; with calibrate_from, also learns the depth calibration
    from the log's frames from that index on (one thread: imports run two at a time)."""
    tag = "%s_%s_s%d" % (name, drift, seed)
    log = os.path.join(work, tag + ".lcmlog")
    # Frames without a recorded pose (TUM's motion capture can start late or drop out) have
    # no place in an ATE against it: left out, as TUM's own tools leave them.
    suite.run([suite.tool("panmap-import"), "-q", folder, log, "--drift",
               "gt" if drift == "none" else drift, "--seed", str(seed), "--invalid-poses", "skip",
               "--max-frames", str(MAX_FRAMES)])
    if calibrate_from is not None:
        suite.run([suite.tool("panmap-calibrate-depth"), "-q", "--log", log, "--out",
                   calibration_path(work, tag), "--first", str(calibrate_from), "--threads", "1"],
                  log=os.path.join(work, tag + ".calibration.log"))


if __name__ == "__main__":
    main()
