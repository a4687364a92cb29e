#!/usr/bin/env bash
# The main job on the bundled demo data: set up, build, import the real 7-Scenes sample
# (../shared/data/7scenes-200) into logs/7scenes-200.lcmlog and check every message with
# panmap-loginfo. (The mapper processes join this demo as they land: see README.)
#   scripts/demo.sh [--data DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
data=../shared/data/7scenes-200
[ "${1:-}" = "--data" ] && data="$2"
scripts/setup.sh
[ -d "$data" ] || { echo "demo.sh: dataset folder $data not found" >&2; exit 1; }
mkdir -p logs
log=logs/7scenes-200.lcmlog
if [ ! -f "$log" ]; then
  build/panmap-import "$data" "$log"
else
  echo "demo: $log exists (delete it to import again)"
fi
build/panmap-loginfo --quiet "$log"
echo "demo: replay it with: lcm-logplayer $log   (watch with: scripts/lcm_spy.sh)"
