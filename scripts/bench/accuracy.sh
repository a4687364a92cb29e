#!/usr/bin/env bash
# The accuracy suite: renders seeded rooms, maps them with every method variant, scores them
# and regenerates docs/RESULTS.md (about 10-15 minutes on 2 cores). Options: see --help.
#   scripts/bench/accuracy.sh [--rooms 3,4,5] [--frames 450] [--jobs N] [--keep-logs]
set -euo pipefail
cd "$(dirname "$0")/../.."
[ -x build/panmap-mapper ] || scripts/setup.sh --skip-network
cmake --build build -j "$(nproc)" --target panmap-mapper panmap-synth panmap-eval >/dev/null
exec python3 scripts/bench/accuracy.py "$@"
