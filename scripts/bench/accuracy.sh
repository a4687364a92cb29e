#!/usr/bin/env bash
# The accuracy suite: renders real ScanNet scene geometry, ScanNet-like rooms and box rooms,
# maps them with every method variant, scores them and regenerates docs/RESULTS.md (about
# 40 minutes on 2 cores with the one shipped scene). Options: see --help.
#   scripts/bench/accuracy.sh [--scannet DIR...] [--seeds 1,2] [--scannet-like 31,32,33]
#                             [--rooms 3,4,5] [--jobs N] [--keep-logs] [--report-only]
set -euo pipefail
cd "$(dirname "$0")/../.."
# --help answers before the setup and the build, which take minutes on a fresh machine.
for arg in "$@"; do
  case "$arg" in -h|--help) exec python3 scripts/bench/accuracy.py --help ;; esac
done
[ -x build/panmap-mapper ] || scripts/setup.sh --skip-network
cmake --build build -j "$(nproc)" --target panmap-mapper panmap-synth panmap-eval >/dev/null
exec python3 scripts/bench/accuracy.py "$@"
