#!/usr/bin/env bash
# Loop-closure repair on real depth (issue 22): 7scenes-200 imported with injected drift and a
# correction carrying the recorded poses of every 10th frame at the end of the log; mapped with
# a frame store (the map is repaired when the correction arrives), without one (the drifted
# map), and from the recorded poses (the reference). Prints the repair's report line and each
# map's surface distance to the reference map (docs/LOOP_CLOSURE.md).
#   scripts/bench/loop_repair.sh [--data DIR] [--voxel-size M] [--drift light|heavy] [--seed N]
#                                [--every N]
# --data takes any folder panmap-import reads (default ../shared/data/7scenes-200); frames
# without a recorded pose are left out of both logs.
set -euo pipefail
caller=$PWD
cd "$(dirname "$0")/../.."
voxel=0.02 drift=heavy seed=1 every=10 data=../shared/data/7scenes-200
while [ $# -gt 0 ]; do
  case "$1" in
    --data) data=$(cd "$caller" && realpath -m "$2"); shift 2 ;;
    --voxel-size) voxel="$2"; shift 2 ;;
    --drift) drift="$2"; shift 2 ;;
    --seed) seed="$2"; shift 2 ;;
    --every) every="$2"; shift 2 ;;
    -h|--help) sed -n 2,10p "$0"; exit 0 ;;
    *) echo "loop_repair.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
[ -d "$data" ] || { echo "loop_repair.sh: $data is missing" >&2; exit 1; }
cmake --build build -j "$(nproc)" --target panmap-import panmap-mapper >/dev/null
work=build/loop_repair
rm -rf "$work" && mkdir -p "$work"
build/panmap-import -q "$data" "$work/drift.lcmlog" --drift "$drift" --seed "$seed" \
  --correction-every "$every" --invalid-poses skip
build/panmap-import -q "$data" "$work/reference.lcmlog" --invalid-poses skip
map() {  # log, out, extra args
  build/panmap-mapper -q --no-snapshots --voxel-size "$voxel" --tracking off --log "$1" \
    --out "$work/$2" "${@:3}" >/dev/null
}
map "$work/reference.lcmlog" reference
map "$work/drift.lcmlog" drifted
map "$work/drift.lcmlog" repaired --frame-store "$work/store"
python3 - "$work" <<'PY'
import json, sys
work = sys.argv[1]
r = json.load(open(work + "/repaired/report.json"))
print("repair:", "; ".join(r["corrections"]["repairs"]) or "none")
print("frame store: %.1f MB for %d frames, %.1f ms median per frame on the mapping thread (queued for the writer thread)" % (
    sum(__import__("os").path.getsize(__import__("os").path.join(d, f))
        for d, _, fs in __import__("os").walk(work + "/store") for f in fs) / 1e6,
    r["frames_integrated"], r["timings"]["frame_store"]["median_ms"]))
PY
for m in drifted repaired; do
  python3 scripts/bench/surface_distance.py "$work/$m/mesh_instance.ply" \
    "$work/reference/mesh_instance.ply"
done
