#!/usr/bin/env python3
"""Reads Google Benchmark CSV on stdin and prints a markdown table row per benchmark with the
named user counters (e.g. median_ms p95_ms): `gb_counters.py median_ms p95_ms`."""
import csv
import sys

lines = [l for l in sys.stdin if l.startswith("name,") or l.startswith('"')]
for row in csv.DictReader(lines):
    cells = []
    for key in sys.argv[1:]:
        value = row.get(key, "")
        cells.append("%.2f" % float(value) if value not in ("", None) else "-")
    print("| %s | %s |" % (row["name"], " | ".join(cells)))
