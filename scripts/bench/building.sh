#!/usr/bin/env bash
# A building-sized map on this machine: panmap-bench-building maps the default procedural
# building (seed 1: >= 20 rooms, >= 1000 m2) along its survey at 5 cm and 2 cm, and
# scripts/bench/building_report.py writes the "Building" section of docs/PERFORMANCE.md and
# the plot docs/building_memory.svg. About 15 minutes on 2 cores, 4 GB of memory at 2 cm.
#   scripts/bench/building.sh [--voxel-sizes "0.05 0.02"] [--frames N]
set -euo pipefail
cd "$(dirname "$0")/../.."
sizes="0.05 0.02" frames=0
while [ $# -gt 0 ]; do
  case "$1" in
    --voxel-sizes) sizes="$2"; shift ;;
    --frames) frames="$2"; shift ;;
    -h|--help) sed -n '2,6p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "building.sh: unknown option $1" >&2; exit 2 ;;
  esac
  shift
done
scripts/setup.sh --skip-network --skip-apt --targets panmap-bench-building >&2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
jsons=()
for v in $sizes; do
  echo "building.sh: mapping the building at $v m" >&2
  build/panmap-bench-building --voxel-size "$v" --frames "$frames" --every 250 \
    --json "$work/building_$v.json" >"$work/building_$v.md"
  jsons+=("$work/building_$v.json")
done
python3 scripts/bench/building_report.py --commit "$(git rev-parse --short HEAD)" \
  --doc docs/PERFORMANCE.md --plot docs/building_memory.svg "${jsons[@]}"
