#!/usr/bin/env python3
"""Fits the object confidence by measurement: maps the tuning sequences (rooms, scenes and
seeds never reported in docs/RESULTS.md) with the full method, matches every object against the
ground truth (panmap-eval: a match is IoU > 0.5 with a GT object of its class), and fits the
logistic model of OptimiserConfig::Objects (confidence = logistic(bias + area log10(area_m2) +
support log2(support) + share class_share)) to those outcomes. Writes docs/CALIBRATION.md with
the fit and the reliability of the old and new weights on the tuning objects; the values it
prints are the defaults in include/panmap/graph/optimiser.h.
"""
import datetime
import math
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import suite  # noqa: E402  (same folder)
from suite import Spec  # noqa: E402

FEATURES = ["bias", "area", "support", "share"]
# The class share is held at 0: with it the fit gave it a negative weight and a worse log loss
# on scene kinds left out of the fit (the table in docs/CALIBRATION.md shows both).
USED = [True, True, True, False]
L2 = 1e-3  # keeps the fit finite when the tuning objects separate perfectly


def features(evidence):
    return [1.0, math.log10(max(evidence["area_m2"], 1e-4)),
            math.log2(max(evidence["support"], 1e-2)), evidence["class_share"]]


def sigmoid(z):
    return 1.0 / (1.0 + math.exp(-z)) if z > -500 else 0.0


def solve(a, b):
    """Gaussian elimination with partial pivoting (4 unknowns)."""
    n = len(b)
    m = [row[:] + [b[i]] for i, row in enumerate(a)]
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(m[r][c]))
        m[c], m[p] = m[p], m[c]
        for r in range(n):
            if r != c and m[c][c] != 0.0:
                f = m[r][c] / m[c][c]
                m[r] = [x - f * y for x, y in zip(m[r], m[c])]
    return [m[i][n] / m[i][i] for i in range(n)]


def fit(rows, used=None):
    """Logistic regression by Newton's method (IRLS) with a small L2 penalty; features not
    `used` are held at 0."""
    used = used or [True] * len(FEATURES)
    rows = [([v if u else 0.0 for v, u in zip(x, used)], y) for x, y in rows]
    w = [0.0] * len(FEATURES)
    for _ in range(100):
        grad = [-L2 * x for x in w]
        hess = [[L2 if i == j else 0.0 for j in range(len(w))] for i in range(len(w))]
        for x, y in rows:
            p = sigmoid(sum(a * b for a, b in zip(w, x)))
            for i in range(len(w)):
                grad[i] += (y - p) * x[i]
                for j in range(len(w)):
                    hess[i][j] += p * (1 - p) * x[i] * x[j]
        step = solve(hess, grad)
        w = [a + b for a, b in zip(w, step)]
        if max(abs(s) for s in step) < 1e-9:
            break
    return w


def reliability(rows, w, bins=5):
    table = [[0, 0, 0.0] for _ in range(bins)]
    for x, y in rows:
        p = sigmoid(sum(a * b for a, b in zip(w, x)))
        b = min(bins - 1, int(p * bins))
        table[b][0] += 1
        table[b][1] += y
        table[b][2] += p
    return table


def log_loss(rows, w):
    total = 0.0
    for x, y in rows:
        p = min(max(sigmoid(sum(a * b for a, b in zip(w, x))), 1e-9), 1 - 1e-9)
        total -= y * math.log(p) + (1 - y) * math.log(1 - p)
    return total / max(1, len(rows))


def main():
    args, dirs = suite.tuning_args(__doc__.split("\n\n")[0], "CALIBRATION.md")
    start = time.time()
    # The full method as a user runs it: ground-truth poses, and SLAM poses refined by default.
    specs = []
    for poses in ["gt", "slam"]:
        for spec in suite.tuning_specs(dirs, poses=(poses,)):
            specs.append(Spec(spec.kind, spec.source, spec.seed, spec.poses, spec.masks,
                              spec.annotation, "full", spec.frames, spec.rate_hz))
    results = suite.run_all(args.work, specs, args.voxel_size, args.jobs, args.keep_logs,
                            label="calibrate", reuse_maps=args.reuse_maps)
    rows, old, kinds, skipped = [], [], [], 0
    for spec in specs:
        for o in results[spec.name()]["results"]["full"]["diagnostics"]["objects"]:
            if o["unverifiable"] or not o.get("evidence"):
                skipped += 1
                continue
            rows.append((features(o["evidence"]), 1 if o["matched"] else 0))
            old.append(o["confidence"])
            kinds.append(spec.kind)
    w = fit(rows, USED)

    def held_out(used):
        """Log loss on each kind of scene (real, ScanNet-like, box) fitted without it."""
        total = 0.0
        for kind in sorted(set(kinds)):
            train = [r for r, k in zip(rows, kinds) if k != kind]
            test = [r for r, k in zip(rows, kinds) if k == kind]
            total += log_loss(test, fit(train, used)) * len(test)
        return total / max(1, len(rows))
    choices = [("area, support, share", [True, True, True, True]),
               ("area, support (used)", USED), ("area", [True, True, False, False]),
               ("support", [True, False, True, False])]
    before = [[0, 0, 0.0] for _ in range(5)]
    for (x, y), c in zip(rows, old):
        b = min(4, int(c * 5))
        before[b][0] += 1
        before[b][1] += y
        before[b][2] += c
    after = reliability(rows, w)

    def table(t):
        lines = ["| confidence | objects | mean confidence | matched share |",
                 "|---|---:|---:|---:|"]
        for k, (n, m, c) in enumerate(t):
            lines.append("| %.1f-%.1f | %d | %s | %s |" % (
                k / 5, (k + 1) / 5, n, "%.2f" % (c / n) if n else "-",
                "%.2f" % (m / n) if n else "-"))
        return "\n".join(lines)
    minutes = (time.time() - start) / 60
    md = ["# Calibration record: object confidence", "",
          "Generated by `scripts/bench/calibrate_confidence.py` on %s in %.1f minutes (do not "
          "edit by hand)." % (datetime.date.today().isoformat(), minutes), "",
          "Tuning sequences (never reported in docs/RESULTS.md): %s; real scenes with seeds %s "
          "in their three annotation variants, ScanNet-like rooms %s, box rooms %s; `m2f` "
          "masks; ground-truth poses and `slam` poses with the default tracking; %g cm voxels. "
          "Each object of the full method is matched against the ground truth by panmap-eval "
          "(IoU > 0.5 with a GT object of its class); %d objects, %d of them matching; %d lying "
          "mostly on unannotated ground truth were left out." % (
              ", ".join(os.path.basename(d) for d in dirs) or "no real scene",
              ", ".join(map(str, suite.TUNING_SCANNET_SEEDS)),
              ", ".join(map(str, suite.TUNING_SCANNET_LIKE)),
              ", ".join(map(str, suite.TUNING_ROOMS)), 100 * args.voxel_size, len(rows),
              sum(y for _, y in rows), skipped), "",
          "Model: confidence = 1 / (1 + exp(-(bias + area * log10(area_m2) + support * "
          "log2(support) + share * class_share))), the evidence panmap writes with each object "
          "(`objects.json`: surface area in the map, score-weighted observations as its class "
          "per voxel, share of its observations that said its class), fitted by logistic "
          "regression (Newton's method, L2 %g)." % L2, "",
          "## Fitted weights", "", "| weight | value |", "|---|---:|"]
    md += ["| %s | %.4f |" % (name, value) for name, value in zip(FEATURES, w)]
    md += ["", "Log loss by the features fitted, on the tuning objects and on each kind of "
           "scene (real ScanNet, ScanNet-like, box rooms) when fitted without it:", "",
           "| features | log loss | left-out kind |", "|---|---:|---:|"]
    for name, used in choices:
        md.append("| %s | %.3f | %.3f |" % (name, log_loss(rows, fit(rows, used)),
                                            held_out(used)))
    md += ["", "A constant model has log loss %.3f." % log_loss(rows, [math.log(
        (sum(y for _, y in rows) + 0.5) / (len(rows) - sum(y for _, y in rows) + 0.5)),
        0.0, 0.0, 0.0]), "",
           "## Reliability on the tuning objects", "", "With the weights the maps were made "
           "with:", "", table(before), "", "With the fitted weights:", "", table(after), "",
           "As YAML (`objects` section):", "", "```yaml",
           "   confidence_bias: %.4f\n   confidence_area: %.4f\n   confidence_support: %.4f\n"
           "   confidence_share: %.4f" % tuple(w), "```", ""]
    with open(args.out, "w") as f:
        f.write("\n".join(md))
    print("\n".join(md[-8:]))
    print("calibrate: wrote %s" % args.out, file=sys.stderr)


if __name__ == "__main__":
    main()
