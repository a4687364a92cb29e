"""The accuracy suite's sequences and runs, shared by accuracy.py (docs/RESULTS.md),
tune_refinement.py and calibrate_confidence.py (docs/TUNING.md).

A sequence is rendered once by panmap-synth (cached in WORK/seq by its parameters), mapped by
panmap-mapper, every method variant exported from the maps, and each scored by panmap-eval.
Three kinds of scenes:
  scannet     a real ScanNet scene's mesh (panmap-synth --scannet DIR), as annotated or with a
              quarter of it left unannotated (--unannotate 0.25), masks painted there or empty;
  scannetlike a ScanNet-like procedural room (--room-style scannet, two laps: revisits);
  room        a procedural box room (the suite before issue 19).
"""
import argparse
import concurrent.futures
import glob
import hashlib
import json
import os
import shutil
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BUILD = os.path.join(ROOT, "build")
SCANNET_LABELS = os.path.join(ROOT, "..", "shared", "data", "scannet-meta",
                              "scannetv2-labels.combined.tsv")

# Method variants: (name, map, optimiser flags). Map A: semantically consistent super-points
# (III-B); map B: spatial-only merging, the same per-frame pipeline otherwise; map V: as B, and
# without the mask edge fill (not in Voxblox++, and it joins objects through their contacts
# when super-points merge by overlap alone: a baseline should not carry it) and without
# mask-only surfaces (Voxblox++ labels geometric segments only).
VARIANTS = [
    ("full", "A", []),
    ("w/o III-B", "B", []),
    ("w/o III-C", "A", ["--no-regularise"]),
    ("w/o III-D", "A", ["--no-refine"]),
    ("w/o III-C & III-D", "A", ["--no-regularise", "--no-refine"]),
    ("Voxblox++-like", "V", ["--no-regularise", "--no-refine"]),
]
REFINED = "full + pose refinement"
# The full method on drifting poses mapped as given (`--tracking off`), beside a "tracked" spec's
# default tracking: what the pose refinement adds (issue 20: never less than without it).
UNTRACKED = "full, poses as given"

# Annotation variants of a real scene: (name, panmap-synth flags).
ANNOTATIONS = [
    ("annotated", []),
    ("25 % unannotated, painted", ["--unannotate", "0.25"]),
    ("25 % unannotated, empty", ["--unannotate", "0.25", "--unannotated-masks", "empty"]),
]


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


def git_commit():
    """The short id of the checkout's HEAD, for a report's header."""
    return subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"],
                          stdout=subprocess.PIPE, text=True).stdout.strip()


def cpu_name():
    """This machine's CPU model, for a report's header."""
    with open("/proc/cpuinfo") as f:
        return next((line.split(":", 1)[1].strip() for line in f
                     if line.startswith("model name")), "unknown CPU")


def write_doc(name, lines, label):
    """Writes docs/NAME from a report's lines and says where on stderr."""
    path = os.path.join(ROOT, "docs", name)
    with open(path, "w") as f:
        f.write("\n".join(lines))
    print("%s: wrote %s" % (label, path), file=sys.stderr)


def mean(values):
    values = [v for v in values if v is not None and v == v]  # missing runs: None or NaN
    return sum(values) / len(values) if values else float("nan")


class Spec:
    """One sequence: what panmap-synth renders, and which runs it gets.

    kind: scannet | scannetlike | room; source: scene folder or room seed; seed: trajectory,
    noise, drift and unannotation seed; poses: gt | slam | slam-hard; masks: clean | m2f | hard;
    annotation: a name of ANNOTATIONS (scannet) or of the room's own ("as generated", "empty");
    runs: "all" (every variant with the poses as given, plus the full method with pose
    refinement when poses drift), "tracked" (every variant, each with the default tracking:
    drifting poses refined against the map) or "full" (the full method only, default
    tracking). join_parts (scannet): `panmap-synth --join-parts`, the scene named
    SCENE_joined. recording (scannet): the scan's own recording (a .sens file) whose depth,
    colour and poses replace the survey (`panmap-synth --recording`), every `every`th frame;
    frames and rate_hz then do not apply.
    """

    def __init__(self, kind, source, seed, poses, masks, annotation="annotated", runs="all",
                 frames=450, rate_hz=5.0, join_parts=False, recording=None, every=6):
        self.kind, self.source, self.seed = kind, source, seed
        self.poses, self.masks, self.annotation, self.runs = poses, masks, annotation, runs
        self.frames, self.rate_hz = frames, rate_hz
        self.join_parts = join_parts and kind == "scannet"
        self.recording = recording if kind == "scannet" else None
        self.every = every

    def scene(self):
        if self.kind == "scannet":
            name = os.path.basename(os.path.normpath(self.source))
            return name + "_joined" if self.join_parts else name
        return "%s%d" % ("sl" if self.kind == "scannetlike" else "room", self.source)

    def name(self):
        ann = {"annotated": "ann", "as generated": "ann", "empty": "empty",
               "25 % unannotated, painted": "u25p", "25 % unannotated, empty": "u25e"}
        length = "rec%d" % self.every if self.recording else "%df" % self.frames
        return "%s_s%d_%s_%s_%s_%s" % (self.scene(), self.seed, ann[self.annotation], self.poses,
                                       self.masks, length)

    def synth_args(self):
        args = ["--seed", str(self.seed), "--masks", self.masks, "--poses", self.poses]
        if self.recording:
            args += ["--recording", self.recording, "--every", str(self.every)]
        else:
            args += ["--frames", str(self.frames), "--rate-hz", str(self.rate_hz)]
        if self.kind == "scannet" and self.recording:
            args += ["--scannet", self.source, "--scannet-labels", SCANNET_LABELS]
            args += dict(ANNOTATIONS)[self.annotation]
            if self.join_parts:
                args.append("--join-parts")
        elif self.kind == "scannet":
            # A real scene's size is not known in advance: the survey walks all of it, with
            # `frames` the least (scene0470's walk takes 111 and 129 frames at 5 Hz, so its
            # sequences are as before; a 150 m2 floor of four rooms took 1,504).
            args += ["--scannet", self.source, "--scannet-labels", SCANNET_LABELS, "--cover-walk"]
            args += dict(ANNOTATIONS)[self.annotation]
            if self.join_parts:
                args.append("--join-parts")
        else:
            args += ["--room", str(self.source)]
            if self.kind == "scannetlike":
                args += ["--room-style", "scannet", "--laps", "2"]
                if self.annotation == "empty":
                    args += ["--unannotated-masks", "empty"]
        return args


def render(work, spec):
    """Renders (or reuses) one sequence; returns its folder."""
    folder = os.path.join(work, "seq", spec.name())
    if os.path.exists(os.path.join(folder, "info.json")):
        return folder
    shutil.rmtree(folder, ignore_errors=True)
    run([tool("panmap-synth"), "-q", "--out", folder] + spec.synth_args())
    return folder


# Diagnostics leave GT vertices within 1.5 voxels of another class out of the count of
# super-points that span two classes: the voxel a boundary crosses takes either class, and the
# nearest-vertex label transfer moves labels by up to half a voxel more (panmap-eval --help).
BOUNDARY_BAND_VOXELS = 1.5


def evaluate(pred_dir, seq_dir, voxel_m=0.02, trajectory=None):
    """Scores a mapper output folder against the sequence's ground truth (eval.json).

    trajectory: the poses the map was built with (trajectory.txt), when they are not the
    ground truth. A map from estimated poses lives in the estimate's world frame, which differs
    from the ground truth's by a rigid transform no mapper can observe (the first poses' drift
    fixes it): the mesh is moved by the trajectory's ATE alignment before scoring, as ATE itself
    is (panmap-eval --align-pred)."""
    cmd = [tool("panmap-eval"), "--pred", os.path.join(pred_dir, "mesh_instance.ply"),
           "--gt", os.path.join(seq_dir, "gt", "mesh.ply"),
           "--boundary-band", "%g" % (BOUNDARY_BAND_VOXELS * voxel_m),
           "--json", os.path.join(pred_dir, "eval.json")]
    if trajectory:
        cmd += ["--traj", trajectory, "--gt-traj",
                os.path.join(seq_dir, "gt", "trajectory_gt.txt"), "--align-pred"]
    objects = os.path.join(pred_dir, "objects.json")
    if os.path.exists(objects):
        cmd += ["--confidences", objects]
    run(cmd)
    with open(os.path.join(pred_dir, "eval.json")) as f:
        result = json.load(f)
    # The evidence behind each object's confidence, for calibration.
    if os.path.exists(objects):
        with open(objects) as f:
            evidence = {o["id"]: o.get("evidence") for o in json.load(f)["objects"]}
        for o in result["diagnostics"]["objects"]:
            o["evidence"] = evidence.get(o["id"])
    return result


def trajectory_ate(seq_dir, trajectory, target, log):
    run([tool("panmap-eval"), "--traj", trajectory, "--gt-traj",
         os.path.join(seq_dir, "gt", "trajectory_gt.txt"), "--json", target], log)
    with open(target) as f:
        return json.load(f)["trajectory"]["ate_m"]["rmse"]


def drop_map(folder):
    """Removes an exported map file (the source map it was loaded from stays): re-exports
    of every variant of every sequence would otherwise fill tens of GB."""
    path = os.path.join(folder, "map.panmap")
    if os.path.exists(path):
        os.remove(path)


def map_sequence(work, seq_dir, spec, voxel_m, config="", variants=None):
    """Maps one sequence (maps A and B as the variants need), exports every variant and
    evaluates it. Returns {"results": {variant: eval}, "input_ate_m", "refined_ate_m", ...}."""
    out = os.path.join(work, "runs", os.path.basename(seq_dir))
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    log = os.path.join(out, "commands.log")
    base = [tool("panmap-mapper"), "-q", "--voxel-size", str(voxel_m), "--threads", "1",
            "--no-snapshots"]
    extra = ["--config", config] if config else []
    log_path = os.path.join(seq_dir, "sequence.lcmlog")
    with open(os.path.join(seq_dir, "info.json")) as f:
        info = json.load(f)
    drifting = spec.poses != "gt"

    def built_with(map_dir):
        return os.path.join(map_dir, "trajectory.txt") if drifting else None
    results, ate = {}, {}
    if spec.runs == "full":
        # The full method as a user runs it: default tracking (refines drifting poses).
        run(base + extra + ["--log", log_path, "--out", os.path.join(out, "A")], log)
        results["full"] = evaluate(os.path.join(out, "A"), seq_dir, voxel_m,
                                   built_with(os.path.join(out, "A")))
        if drifting:
            ate["refined"] = trajectory_ate(seq_dir, os.path.join(out, "A", "trajectory.txt"),
                                            os.path.join(out, "ate_refined.json"), log)
    else:
        wanted = [v for v in VARIANTS if variants is None or v[0] in variants]
        if drifting and spec.runs == "all":
            refined = os.path.join(out, "A_refined")
            run(base + extra + ["--tracking", "auto", "--log", log_path, "--out", refined], log)
            results[REFINED] = evaluate(refined, seq_dir, voxel_m, built_with(refined))
            ate["refined"] = trajectory_ate(seq_dir, os.path.join(refined, "trajectory.txt"),
                                            os.path.join(out, "ate_refined.json"), log)
        tracking = "auto" if spec.runs == "tracked" else "off"
        fixed = base + extra + ["--tracking", tracking, "--log", log_path]
        if any(v[1] == "A" for v in wanted):
            run(fixed + ["--out", os.path.join(out, "A")], log)
        if any(v[1] == "B" for v in wanted):
            run(fixed + ["--spatial-only", "--no-regularise", "--no-refine",
                         "--out", os.path.join(out, "B")], log)
        if any(v[1] == "V" for v in wanted):
            run(fixed + ["--spatial-only", "--no-mask-edge-fill", "--no-mask-only-surfaces",
                         "--pair-interior-px", "0",
                         "--no-regularise", "--no-refine", "--out", os.path.join(out, "V")], log)
        if drifting and spec.runs == "tracked":
            ate["refined"] = trajectory_ate(seq_dir, os.path.join(out, "A", "trajectory.txt"),
                                            os.path.join(out, "ate_refined.json"), log)
            untracked = os.path.join(out, "A_untracked")
            run(base + extra + ["--tracking", "off", "--log", log_path, "--out", untracked], log)
            results[UNTRACKED] = evaluate(untracked, seq_dir, voxel_m, built_with(untracked))
            drop_map(untracked)
        for variant, source, flags in wanted:
            folder = os.path.join(out, variant.replace("/", "").replace(" ", "_")
                                  .replace("&", "and").replace("+", "p"))
            if source == "A" and not flags:
                folder = os.path.join(out, "A")
            elif source == "V":
                folder = os.path.join(out, "V")
            else:
                run([tool("panmap-mapper"), "-q", "--no-snapshots", "--export-only", "--load",
                     os.path.join(out, source, "map.panmap"), "--out", folder] + flags + extra,
                    log)
            results[variant] = evaluate(folder, seq_dir, voxel_m,
                                        built_with(os.path.join(out, source)))
            if folder not in (os.path.join(out, "A"), os.path.join(out, "B"),
                              os.path.join(out, "V")):
                drop_map(folder)
    if drifting:
        ate["input"] = trajectory_ate(seq_dir, os.path.join(seq_dir, "gt", "trajectory_input.txt"),
                                      os.path.join(out, "ate_input.json"), log)
    with open(os.path.join(out, "A" if os.path.exists(os.path.join(out, "A")) else "A_refined",
                           "report.json")) as f:
        report = json.load(f)
    return {"results": results, "input_ate_m": info["measured"]["input_ate_rmse_m"],
            "trajectory_ate_m": ate, "coverage": info["coverage"]["fraction_seen_from_3_views"],
            "unannotated": info.get("unannotation", {}).get("fraction"),
            "total_ms": report["timings"]["total"]["median_ms"]}


def reexport(work, spec, config=""):
    """The full method's result of a spec mapped before (runs/NAME/A/map.panmap): only the
    final optimisation and the outputs are redone, then scored. None when there is no map."""
    seq_dir = os.path.join(work, "seq", spec.name())
    out = os.path.join(work, "runs", spec.name())
    if spec.runs != "full" or not os.path.exists(os.path.join(out, "A", "map.panmap")):
        return None
    folder = os.path.join(out, "A")
    run([tool("panmap-mapper"), "-q", "--no-snapshots", "--export-only", "--load",
         os.path.join(folder, "map.panmap"), "--out", folder] +
        (["--config", config] if config else []), os.path.join(out, "commands.log"))
    trajectory = os.path.join(folder, "trajectory.txt") if spec.poses != "gt" else None
    return {"results": {"full": evaluate(folder, seq_dir, trajectory=trajectory)}}


def _file_digest(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def binary_digests():
    """The SHA-256 of the binaries that render, map and score a sequence."""
    return {name: _file_digest(tool(name))
            for name in ("panmap-synth", "panmap-mapper", "panmap-eval")}


def run_key(spec, voxel_m, config, variants, binaries):
    """What a sequence's result depends on: the binaries that render, map and score it
    (binary_digests(); the runs are deterministic), the sequence's parameters and the mapping
    options. A result saved under the same key is the result a new run would give."""
    parts = {"spec": spec.name(), "synth_args": spec.synth_args(), "runs": spec.runs,
             "voxel_m": voxel_m, "variants": sorted(variants) if variants else None,
             "config": _file_digest(config) if config else None, "binaries": binaries}
    return hashlib.sha256(json.dumps(parts, sort_keys=True).encode()).hexdigest()


def saved_result(work, spec, key):
    """The result an earlier run saved for spec under key (runs/NAME/result.json), or None."""
    try:
        with open(os.path.join(work, "runs", spec.name(), "result.json")) as f:
            saved = json.load(f)
    except (OSError, ValueError):
        return None
    return saved.get("result") if saved.get("key") == key else None


def run_all(work, specs, voxel_m, jobs, keep_logs, config="", variants=None, label="suite",
            reuse_maps=False, resume=False):
    """Renders and maps every spec (jobs at a time). Returns {spec.name(): result}. With
    reuse_maps, a spec of the full method mapped before is only re-exported (reexport). Each
    mapped spec's result is saved beside its runs (runs/NAME/result.json, with run_key); with
    resume, a spec whose saved result has the same key is not mapped again: a run cut short
    (a full disk, a killed job) goes on where it stopped."""
    binaries = binary_digests()  # once: what this run maps with

    def announce(spec, out, how):
        full = out["results"].get("full") or out["results"].get(REFINED)
        print("%s: %s: %sfull mAP50 %.1f" % (label, spec.name(), how,
                                             100 * (full["map50"] or 0)),
              file=sys.stderr, flush=True)

    def job(spec):
        key = run_key(spec, voxel_m, config, variants, binaries)
        if resume:
            out = saved_result(work, spec, key)
            if out is not None:
                announce(spec, out, "saved by an earlier run, ")
                return dict(out, resumed=True)
        out = reexport(work, spec, config) if reuse_maps else None
        if out is not None:
            announce(spec, out, "re-exported, ")
            return out
        seq = render(work, spec)
        out = map_sequence(work, seq, spec, voxel_m, config, variants)
        if not keep_logs:
            os.remove(os.path.join(seq, "sequence.lcmlog"))
            os.rename(os.path.join(seq, "info.json"), os.path.join(seq, "info.json.done"))
        with open(os.path.join(work, "runs", spec.name(), "result.json"), "w") as f:
            json.dump({"key": key, "result": out}, f)
        announce(spec, out, "")
        return out
    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        futures = {s.name(): pool.submit(job, s) for s in specs}
        return {name: f.result() for name, f in futures.items()}


def tuning_args(description, out_name):
    """Parses the options the tuning scripts share; returns (args, ScanNet scene folders)."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--scannet", nargs="*", default=None, metavar="DIR",
                        help="ScanNet scene folders (default: every ../shared/data/scannet-gt/"
                             "scene*)")
    parser.add_argument("--work", default=os.path.join(BUILD, "tuning"))
    parser.add_argument("--out", default=os.path.join(ROOT, "docs", out_name))
    parser.add_argument("--voxel-size", type=float, default=0.02)
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 2)
    parser.add_argument("--keep-logs", action="store_true")
    parser.add_argument("--reuse-maps", action="store_true",
                        help="keep the maps of an earlier run in --work and map only the "
                             "sequences without one (re-run only what follows the mapping)")
    args = parser.parse_args()
    return args, scene_dirs(args.scannet)


def scene_dirs(given):
    """The ScanNet scene folders to use: those given (None: every scene in
    ../shared/data/scannet-gt), as absolute paths; exits with a one-line reason on a missing
    one."""
    dirs = [os.path.abspath(d) for d in (given if given is not None else sorted(
        glob.glob(os.path.join(ROOT, "..", "shared", "data", "scannet-gt", "scene*"))))]
    for d in dirs:
        if not os.path.isdir(d):
            sys.exit("%s: %s is not a folder" % (os.path.basename(sys.argv[0]), d))
    return dirs


# Sequences that choose defaults (tune_refinement.py, calibrate_confidence.py): other rooms
# and other seeds than docs/RESULTS.md reports, never those.
TUNING_SCANNET_SEEDS = [11, 12, 13, 14]
TUNING_SCANNET_LIKE = [21, 22, 23, 24]
TUNING_ROOMS = [6, 7]


def tuning_specs(scannet_dirs, poses=("gt", "slam"), frames_scannet=600, frames_like=600,
                 frames_room=450):
    """The tuning sequences: each real scene in its three annotation variants (seeds 11-14),
    ScanNet-like rooms 21-24 and box rooms 6, 7; m2f masks, the given poses; every variant
    mapped so that the ablations can be re-exported."""
    specs = []
    for p in poses:
        for d in scannet_dirs:
            for annotation, _ in ANNOTATIONS:
                for seed in TUNING_SCANNET_SEEDS:
                    specs.append(Spec("scannet", d, seed, p, "m2f", annotation, "all",
                                      frames_scannet))
        for r in TUNING_SCANNET_LIKE:
            specs.append(Spec("scannetlike", r, r, p, "m2f", "as generated", "all", frames_like))
        for r in TUNING_ROOMS:
            specs.append(Spec("room", r, r, p, "m2f", "annotated", "all", frames_room))
    return specs
