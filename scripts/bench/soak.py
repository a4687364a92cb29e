#!/usr/bin/env python3
"""Soak test (issue 21): a long live run through lcm-logplayer with garbage on the wire and the
optimiser killed and restarted, watching resident memory and every frame's fate.

A rendered room (panmap-synth, --loop-frames at 30 Hz) is repeated with shifted timestamps
until the log holds --frames frames, with a garbage event every --garbage-every real events
(panmap-bench-soak-log). lcm-logplayer replays it in real time over loopback UDP into a live
panmap-mapper (autosave on) and panmap-optimizer. During the run the optimiser is killed
(SIGKILL) and restarted --restarts times, each time followed by `panmap-command optimise`;
at the end `finish` asks the last optimiser for the final labels. Every --sample-s seconds the
mapper's resident memory (/proc) and its PANMAP_STATUS (panmap-command status) are sampled.

The repeated room adds no new surface after the first loop, so resident memory minus the map's
own bytes must stay flat after that warm-up; every frame sent must be integrated, dropped by
the queue (counted) or refused with a counted reason, and the garbage's reasons must match what
was injected. Writes the section between the soak markers of docs/PERFORMANCE.md.

  python3 scripts/bench/soak.py [--frames 10000] [--voxel-size 0.02] [--keep DIR]
"""
import argparse
import datetime
import json
import os
import platform
import shutil
import signal
import subprocess
import sys
import tempfile
import time

import doc_section  # same folder

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BUILD = os.path.join(ROOT, "build")
BEGIN = "<!-- soak:begin (scripts/bench/soak.py) -->"
END = "<!-- soak:end -->"


def tool(name):
    return os.path.join(BUILD, name)


def run(cmd):
    result = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if result.returncode != 0:
        raise RuntimeError("failed (%d): %s\n%s" % (result.returncode, " ".join(cmd),
                                                    result.stdout[-2000:]))
    return result.stdout


def rss_bytes(pid):
    try:
        with open("/proc/%d/status" % pid) as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return None


def status(url, timeout_s=3.0):
    result = subprocess.run([tool("panmap-command"), "status", "--lcm-url", url,
                             "--timeout-s", str(timeout_s)],
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    if result.returncode != 0:
        return None
    return json.loads(result.stdout)


def log(message):
    print("soak: " + message, file=sys.stderr, flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--frames", type=int, default=10000)
    parser.add_argument("--loop-frames", type=int, default=300, help="frames of the rendered room")
    parser.add_argument("--voxel-size", type=float, default=0.02)
    parser.add_argument("--garbage-every", type=int, default=50)
    parser.add_argument("--restarts", type=int, default=2, help="optimiser kills and restarts")
    parser.add_argument("--sample-s", type=float, default=5.0)
    parser.add_argument("--url", default="udpm://239.255.76.67:7690?ttl=0&recv_buf_size=16777216")
    parser.add_argument("--out", default=os.path.join(ROOT, "docs", "PERFORMANCE.md"))
    parser.add_argument("--keep", default="", help="work folder to keep (default: a temporary one)")
    args = parser.parse_args()

    if subprocess.run([tool("panmap-command"), "--self-test", "--lcm-url", args.url]).returncode:
        sys.exit("soak: UDP multicast on loopback does not work here (run scripts/setup.sh as root)")
    work = args.keep or tempfile.mkdtemp(prefix="panmap-soak-")
    os.makedirs(work, exist_ok=True)
    try:
        log("rendering %d frames of room 1" % args.loop_frames)
        run([tool("panmap-synth"), "--room", "1", "--frames", str(args.loop_frames), "--masks",
             "m2f", "--poses", "gt", "--seed", "3", "-q", "--out", os.path.join(work, "seq")])
        soak_log = os.path.join(work, "soak.lcmlog")
        log("writing the %d-frame log" % args.frames)
        run([tool("panmap-bench-soak-log"), os.path.join(work, "seq", "sequence.lcmlog"), soak_log,
             "--frames", str(args.frames), "--garbage-every", str(args.garbage_every)])
        summary = json.load(open(soak_log + ".json"))
        log_bytes = os.path.getsize(soak_log)
        result = soak(args, work, soak_log)
        result.update(summary=summary, log_bytes=log_bytes)
        write_section(args, result)
    finally:
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)


def soak(args, work, soak_log):
    out = os.path.join(work, "out")
    optimiser_log = open(os.path.join(work, "optimizer.log"), "a")

    def start_optimiser():
        return subprocess.Popen([tool("panmap-optimizer"), "--lcm-url", args.url],
                                stdout=optimiser_log, stderr=subprocess.STDOUT)

    optimiser = start_optimiser()
    mapper = subprocess.Popen(
        [tool("panmap-mapper"), "--lcm-url", args.url, "--out", out, "--voxel-size",
         str(args.voxel_size), "--no-snapshots", "--autosave-s", "60", "--optimizer-timeout-s",
         "300"],
        stdout=open(os.path.join(work, "mapper.log"), "w"), stderr=subprocess.STDOUT)
    for _ in range(30):
        if status(args.url, 1.0):
            break
    else:
        raise RuntimeError("panmap-mapper published no status")
    duration_s = args.frames / 30.0
    restart_at = [duration_s * (k + 1) / (args.restarts + 1) for k in range(args.restarts)]
    log("replaying %.0f s of frames; optimiser restarts at %s s" %
        (duration_s, ", ".join("%.0f" % t for t in restart_at)))
    player = subprocess.Popen(["lcm-logplayer", "-l", args.url, soak_log],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    start = time.time()
    samples, restarts = [], []
    next_sample = start
    while player.poll() is None:
        now = time.time()
        if restart_at and now - start >= restart_at[0]:
            restart_at.pop(0)
            optimiser.send_signal(signal.SIGKILL)
            optimiser.wait()
            optimiser = start_optimiser()
            time.sleep(1.0)  # let it subscribe before the request
            run([tool("panmap-command"), "optimise", "--lcm-url", args.url])
            restarts.append(round(now - start, 1))
            log("optimiser killed and restarted at %.0f s" % (now - start))
        if now >= next_sample:
            next_sample += args.sample_s
            s = status(args.url)
            rss = rss_bytes(mapper.pid)
            if s and rss:
                samples.append({"t_s": round(now - start, 1), "rss": rss, **s})
                if len(samples) % 12 == 1:
                    log("t %.0f s: %d frames integrated, %.0f MiB resident" %
                        (now - start, s["frames_integrated"], rss / 2**20))
        time.sleep(0.2)
    replay_s = time.time() - start
    # Let the mapper finish its queue, then ask for the final labels.
    last = None
    for _ in range(60):
        s = status(args.url)
        if s and last and s["frames_integrated"] == last["frames_integrated"]:
            break
        last = s
    run([tool("panmap-command"), "finish", "--lcm-url", args.url])
    mapper.wait(timeout=600)
    optimiser.send_signal(signal.SIGTERM)
    optimiser.wait(timeout=30)
    if mapper.returncode != 0:
        raise RuntimeError("panmap-mapper exited with %d" % mapper.returncode)
    report = json.load(open(os.path.join(out, "report.json")))
    return {"samples": samples, "restarts": restarts, "report": report, "replay_s": replay_s}


def commit():
    try:
        return subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"],
                              stdout=subprocess.PIPE, text=True).stdout.strip()
    except OSError:
        return "unknown"


def cpu_model():
    with open("/proc/cpuinfo") as f:
        for line in f:
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    return platform.processor()


def write_section(args, r):
    report, samples, summary = r["report"], r["samples"], r["summary"]
    bytes_per_block = report["memory"]["map_bytes"] / max(1, report["memory"]["blocks"])
    mib = 2.0 ** 20
    rows = []
    for s in samples:
        map_mib = s["num_blocks"] * bytes_per_block / mib
        rows.append((s["t_s"], s["frames_integrated"], s["rss"] / mib, map_mib,
                     s["rss"] / mib - map_mib, s["num_superpoints"], s["frames_dropped"],
                     s["frames_rejected"]))
    # Warm-up: the first loop (the map grows) and the first snapshot (its scratch stays in the
    # heap for the next ones).
    warm = [row for row in rows if row[1] >= args.loop_frames and row[0] >= 60 + 2 * args.sample_s]
    other = [row[4] for row in warm]
    flat = (min(other), max(other)) if other else (0.0, 0.0)
    slope = 0.0  # least-squares trend of `other`, MiB per 1000 frames mapped
    if len(warm) >= 2:
        xs = [row[1] / 1000.0 for row in warm]
        mx, my = sum(xs) / len(xs), sum(other) / len(other)
        sxx = sum((x - mx) ** 2 for x in xs)
        if sxx > 0:
            slope = sum((x - mx) * (y - my) for x, y in zip(xs, other)) / sxx
    shown = rows[:: max(1, len(rows) // 20)]
    if rows and shown[-1] != rows[-1]:
        shown.append(rows[-1])

    sent = summary["frames"]
    received = report["frames_received"]
    integrated = report["frames_integrated"]
    dropped = report["frames_dropped_behind"]
    rejected = report["rejected"]
    frame_rejects = sum(n for reason, n in rejected.items() if reason.startswith("frame:"))
    expected = summary["expected_rejections"]

    def counted(prefix):
        return sum(n for reason, n in rejected.items() if reason.startswith(prefix))

    # Garbage on CAMERA_RGBD is received like a frame; repeated and late copies are refused
    # with `frame:` reasons of their own.
    garbage_frames = sum(expected.get(k, 0) for k in (
        "malformed CAMERA_RGBD", "frame: repeated timestamp", "frame: out of order"))
    # Whatever arrives on the frame channel, garbage or not, is integrated, pushed out of the
    # full queue (the oldest message, whatever it holds) or refused with a reason.
    refused_on_channel = (frame_rejects + counted("malformed CAMERA_RGBD") +
                          counted("bad CAMERA_RGBD"))
    unaccounted = received - integrated - dropped - refused_on_channel

    autosave = report.get("autosave", {})
    md = [BEGIN, "## Soak", "",
          "Generated by `python3 scripts/bench/soak.py --frames %d` on %s at commit `%s`; "
          "machine: %s, %d cores. Do not edit by hand: rerun the script." % (
              args.frames, datetime.date.today().isoformat(), commit(), cpu_model(),
              os.cpu_count()), "",
          "A rendered room (%d frames at 30 Hz, `m2f` masks) repeated with shifted timestamps "
          "into a %d-frame log (%.1f GB) with a garbage event every %d real events, replayed in "
          "real time by `lcm-logplayer` over loopback UDP into the live `panmap-mapper` (%.0f cm, "
          "2 threads, autosave every 60 s) and `panmap-optimizer`. The optimiser was killed "
          "(SIGKILL) and restarted at %s s, each time followed by `panmap-command optimise`; "
          "`finish` took the final labels from the third instance. The replay took %.0f s." % (
              args.loop_frames, sent, r["log_bytes"] / 1e9, args.garbage_every,
              args.voxel_size * 100, ", ".join(str(t) for t in r["restarts"]), r["replay_s"]),
          "",
          "Resident memory against the map's own bytes (TSDF blocks x bytes per block). After "
          "the warm-up (the first loop, in which the room's surface is mapped, and the first "
          "snapshot at 60 s) `other` (resident minus map) stays between **%.1f and %.1f MiB** "
          "over %d samples, a trend of **%+.2f MiB per 1000 frames** (least squares)." % (
              flat[0], flat[1], len(warm), slope), "",
          "| t [s] | frames mapped | resident MiB | map MiB | other MiB | super-points | "
          "dropped | rejected |",
          "|---|---|---|---|---|---|---|---|"]
    for row in shown:
        md.append("| %.0f | %d | %.1f | %.1f | %.1f | %d | %d | %d |" % row)
    md += ["", "Every frame accounted for:", "",
           "| frames | count |", "|---|---|",
           "| in the log | %d |" % sent,
           "| received on the frame channel (with garbage) | %d |" % received,
           "| lost on UDP (log + garbage - received) | %d |" % (sent + garbage_frames - received),
           "| integrated | %d |" % integrated,
           "| dropped by the live queue (counted) | %d |" % dropped,
           "| refused by the session (`frame:` reasons, malformed or bad frames) | %d |" %
           refused_on_channel,
           "| of which garbage injected on the frame channel | %d |" % garbage_frames,
           "| unaccounted (received - integrated - dropped - refused) | %d |" % unaccounted,
           "", "Garbage injected and counted, by reason (%d garbage events). The live queue "
           "pushes out the oldest message of the frame channel when it is full, garbage "
           "included, and a late copy of a frame whose original was pushed out is no longer "
           "late: where frames were dropped, the counts on the frame channel may fall short of "
           "the injected ones by those." % summary["garbage_events"], "",
           "| reason | injected | counted by the mapper |", "|---|---|---|"]
    for reason in sorted(expected):
        md.append("| %s | %d | %d |" % (reason, expected[reason], counted(reason)))
    others = {k: v for k, v in rejected.items() if not any(k.startswith(e) for e in expected)}
    for reason, n in sorted(others.items()):
        md.append("| %s | - | %d |" % (reason, n))
    md += ["", "Final labels: %s after %d graph request(s); autosave: %d snapshots, the last "
           "%.0f MB, serialised in %.0f ms on the mapping thread and written in %.0f ms." % (
               "optimised" if report["graph"]["optimised"] else "NOT optimised",
               report.get("graph_requests_sent", 0), autosave.get("written", 0),
               autosave.get("last_bytes", 0) / 1e6, autosave.get("last_serialize_ms", 0),
               autosave.get("last_write_ms", 0)), "", END]
    doc_section.splice(args.out, "\n".join(md), BEGIN, END, empty="# Performance\n")
    log("wrote the soak section of %s" % args.out)


if __name__ == "__main__":
    main()
