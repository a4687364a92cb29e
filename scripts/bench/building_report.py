#!/usr/bin/env python3
"""Writes the "Building" section of docs/PERFORMANCE.md (between its markers) and an SVG plot
of memory against observed surface from panmap-bench-building --json files."""
import argparse
import datetime
import json
import platform
import re

BEGIN = "<!-- building:begin"
END = "<!-- building:end -->"
MIB = 1024.0 * 1024.0


def svg_plot(runs, path):
    """Mapping memory and map size (MiB) against observed surface (m2), one pair per run."""
    w, h, left, right, top, bottom = 720, 420, 70, 190, 20, 50
    xmax = max(s["observed_surface_m2"] for r in runs for s in r["samples"]) or 1.0
    ymax = max(max(s["mapping_bytes"], s["map_bytes"]) for r in runs for s in r["samples"]) / MIB
    ymax = ymax or 1.0

    def px(x, y):
        return (left + (w - left - right) * x / xmax, h - bottom - (h - top - bottom) * y / ymax)

    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" '
           'font-family="sans-serif" font-size="12">',
           f'<rect width="{w}" height="{h}" fill="white"/>']
    for k in range(6):  # grid and tick labels
        x, y = xmax * k / 5, ymax * k / 5
        gx, _ = px(x, 0)
        _, gy = px(0, y)
        out.append(f'<line x1="{gx:.1f}" y1="{top}" x2="{gx:.1f}" y2="{h - bottom}" stroke="#ddd"/>')
        out.append(f'<line x1="{left}" y1="{gy:.1f}" x2="{w - right}" y2="{gy:.1f}" stroke="#ddd"/>')
        out.append(f'<text x="{gx:.1f}" y="{h - bottom + 16}" text-anchor="middle">{x:.0f}</text>')
        out.append(f'<text x="{left - 6}" y="{gy + 4:.1f}" text-anchor="end">{y:.0f}</text>')
    out.append(f'<text x="{(left + w - right) / 2}" y="{h - 12}" text-anchor="middle">'
               'observed surface, m2</text>')
    out.append(f'<text x="16" y="{(top + h - bottom) / 2}" text-anchor="middle" '
               f'transform="rotate(-90 16 {(top + h - bottom) / 2})">MiB</text>')
    colours = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd"]
    legend_y = top + 10
    for i, run in enumerate(runs):
        c = colours[i % len(colours)]
        cm = run["voxel_size_m"] * 100
        for key, dash, label in (("mapping_bytes", "", f"{cm:g} cm: mapping resident"),
                                 ("map_bytes", ' stroke-dasharray="6 4"', f"{cm:g} cm: map")):
            pts = " ".join("%.1f,%.1f" % px(s["observed_surface_m2"], s[key] / MIB)
                           for s in run["samples"])
            out.append(f'<polyline points="{pts}" fill="none" stroke="{c}" stroke-width="2"{dash}/>')
            lx = w - right + 12
            out.append(f'<line x1="{lx}" y1="{legend_y}" x2="{lx + 24}" y2="{legend_y}" '
                       f'stroke="{c}" stroke-width="2"{dash}/>')
            out.append(f'<text x="{lx + 30}" y="{legend_y + 4}">{label}</text>')
            legend_y += 18
    out.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


def fit_slope(samples):
    """Least-squares MiB per m2 of mapping memory against observed surface, and the largest
    relative deviation from that line (linearity)."""
    xs = [s["observed_surface_m2"] for s in samples]
    ys = [s["mapping_bytes"] / MIB for s in samples]
    n = len(xs)
    mx, my = sum(xs) / n, sum(ys) / n
    sxx = sum((x - mx) ** 2 for x in xs) or 1.0
    slope = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx
    icept = my - slope * mx
    dev = max(abs(y - (icept + slope * x)) / max(y, 1.0) for x, y in zip(xs, ys))
    return slope, icept, dev


def idle_scan(run):
    """The surface-scan refreshes between frames (what the live mapper does while it waits):
    median / p95 ms, or why there are none."""
    every = run.get("idle_scan_every", 0)
    times = sorted(run.get("idle_scan_ms", []))
    if every <= 0 or not times:
        return "none"
    def q(p):
        return times[min(len(times) - 1, int(p * len(times)))]
    return f"{q(0.5):.1f} / {q(0.95):.1f} (every {every} frames)"


def section(runs, commit, plot):
    cpu = "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            m = re.search(r"model name\s*:\s*(.*)", f.read())
            cpu = m.group(1).strip() if m else cpu
    except OSError:
        pass
    first = runs[0]
    lines = [
        f"{BEGIN} (scripts/bench/building.sh rewrites this section) -->",
        "## Building",
        "",
        f"`panmap-bench-building --building {first['building']}` (scripts/bench/building.sh): the "
        f"default procedural building, {first['rooms']} rooms along a corridor, "
        f"{first['floor_area_m2']:.0f} m2 of floor, walked once through every room (5 Hz, "
        f"0.5 m/s, {first['frames']} frames), rendered in-process with m2f masks and mapped at "
        "ground-truth poses, 2 threads; measured on "
        f"{datetime.date.today().isoformat()} at commit `{commit}` on {cpu} "
        f"({platform.machine()}). `mapping resident` is the process's resident memory minus "
        "what it held before the first frame (the building, its renderer); `map` is TSDF "
        "blocks, occupancy and the super-point graph; observed surface counts the voxels the "
        "surface passes through (observed, |sdf| < half a voxel) times a voxel's face. "
        "`idle scan refresh`: as the live mapper's worker does while it waits for the next "
        "frame (`panmap-mapper --idle-scan-every`, default 10 frames), the benchmark brings the "
        "graph's surface scan up to date between frames, outside the frame's time; the final "
        "optimisation then reads only the last frames' blocks. Offline mapping of a log has no "
        "such wait: its final graph reads the blocks changed since the last periodic "
        "forgetting, up to 100 frames (about 120 ms more on the 2 cm building, "
        "docs/MAPPING.md).",
        "",
        f"![memory against observed surface]({plot.split('/')[-1]})",
        "",
        "| voxel | frames | frame ms median / p95 | peak mapping resident MiB | map MiB at the end "
        "| mapping / map | MiB per m2 (fit) | largest deviation from the fit | final graph "
        "vertices / edges | idle scan refresh ms median / p95 | final optimisation ms (graph + "
        "solve) | export s | export peak resident MiB (before) |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in runs:
        last = r["samples"][-1]
        peak_mapping = max(s["mapping_bytes"] for s in r["samples"]) / MIB
        slope, _, dev = fit_slope(r["samples"])
        lines.append(
            f"| {r['voxel_size_m'] * 100:g} cm | {r['frames']} | {r['frame_ms_median']:.1f} / "
            f"{r['frame_ms_p95']:.1f} | {peak_mapping:.0f} | {last['map_bytes'] / MIB:.0f} | "
            f"{last['mapping_bytes'] / max(last['map_bytes'], 1):.2f} | {slope:.3f} | "
            f"{dev * 100:.0f} % | {r['graph_vertices']} / {r['graph_edges']} | "
            f"{idle_scan(r)} | "
            f"{r['graph_ms']:.0f} + {r['solve_ms']:.0f} | {r['export_ms'] / 1000:.1f} | "
            f"{r['export_peak_resident_bytes'] / MIB:.0f} "
            f"({r['resident_before_export_bytes'] / MIB:.0f}) |")
    lines += ["", "Every output's cost (seconds to write, megabytes on disk):", "",
              "| voxel | " + " | ".join(runs[0]["export_steps_s"].keys()) + " |",
              "|---|" + "---|" * len(runs[0]["export_steps_s"])]
    for r in runs:
        lines.append(f"| {r['voxel_size_m'] * 100:g} cm | " +
                     " | ".join(f"{v:.2f} s" for v in r["export_steps_s"].values()) + " |")
    names = sorted(runs[0]["files_bytes"].keys())
    lines += ["", "| voxel | " + " | ".join(names) + " |", "|---|" + "---|" * len(names)]
    for r in runs:
        lines.append(f"| {r['voxel_size_m'] * 100:g} cm | " +
                     " | ".join(f"{r['files_bytes'].get(n, 0) / 1e6:.1f}" for n in names) + " |")
    lines += ["", "Samples (every 250 frames):", ""]
    for r in runs:
        lines += [f"{r['voxel_size_m'] * 100:g} cm:", "",
                  "| frame | mapping MiB | map MiB | blocks | observed surface m2 | super-points "
                  "| graph edges | frame ms median / p95 |", "|---|---|---|---|---|---|---|---|"]
        for s in r["samples"]:
            lines.append(f"| {s['frame']} | {s['mapping_bytes'] / MIB:.0f} | "
                         f"{s['map_bytes'] / MIB:.0f} | {s['blocks']} | "
                         f"{s['observed_surface_m2']:.0f} | {s['superpoints']} | "
                         f"{s['graph_edges']} | {s['frame_ms_median']:.1f} / "
                         f"{s['frame_ms_p95']:.1f} |")
        lines.append("")
    lines.append(END)
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("runs", nargs="+", help="panmap-bench-building --json files")
    ap.add_argument("--doc", required=True)
    ap.add_argument("--plot", required=True)
    ap.add_argument("--commit", default="unknown")
    args = ap.parse_args()
    runs = [json.load(open(p)) for p in args.runs]
    svg_plot(runs, args.plot)
    text = open(args.doc).read()
    new = section(runs, args.commit, args.plot)
    if BEGIN in text and END in text:
        a = text.index(BEGIN)
        b = text.index(END) + len(END) + 1
        text = text[:a] + new + text[b:]
    else:
        text = text.rstrip("\n") + "\n\n" + new
    with open(args.doc, "w") as f:
        f.write(text)
    print(f"building_report: wrote {args.doc} and {args.plot}")


if __name__ == "__main__":
    main()
