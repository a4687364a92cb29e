#!/usr/bin/env bash
# Loop closures on rendered rooms (issue 22): panmap-synth renders a room surveyed twice (the
# second lap walks back to the start) with SLAM drift and ends the log with the correction a
# back-end would publish at the loop (ground-truth poses of every 10th frame, optionally with a
# residual error); the same sequence is also rendered with ground-truth poses. Mapped three
# ways at 2 cm, tracking off: ground-truth poses, drifted poses, drifted poses repaired by the
# correction (--frame-store). Prints mAP50, the mean surface distance to the ground-truth mesh
# and the occupancy agreement with the ground-truth-pose run for each, and how many of the
# drifted map's objects and super-points keep their id through the repair, and which of the
# graph edges it keeps or drops the ground-truth-pose map has too (object_ids.py;
# docs/LOOP_CLOSURE.md).
#   scripts/bench/loop_rooms.sh [--room N] [--seed N] [--poses slam|slam-hard|light|heavy] [--frames N]
#                               [--residual-cm S] [--residual-deg S] [--style boxes|scannet]
#                               [--reintegrate-also]
# --reintegrate-also maps a fourth way: repaired by re-integration only (--repair-reintegrate-only,
# the stored pixel labels of the first mapping), to compare with mapping the frames again.
set -euo pipefail
cd "$(dirname "$0")/../.."
room=3 seed=3 poses=slam-hard frames=450 residual_cm=0 residual_deg=0 style=boxes
reintegrate_also=0
while [ $# -gt 0 ]; do
  case "$1" in
    --room) room="$2"; shift 2 ;;
    --seed) seed="$2"; shift 2 ;;
    --poses) poses="$2"; shift 2 ;;
    --frames) frames="$2"; shift 2 ;;
    --residual-cm) residual_cm="$2"; shift 2 ;;
    --residual-deg) residual_deg="$2"; shift 2 ;;
    --style) style="$2"; shift 2 ;;
    --reintegrate-also) reintegrate_also=1; shift ;;
    -h|--help) sed -n 2,13p "$0"; exit 0 ;;
    *) echo "loop_rooms.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
cmake --build build -j "$(nproc)" --target panmap-synth panmap-mapper panmap-eval \
  panmap-occupancy-probe >/dev/null
work=build/loop_rooms/room$room-seed$seed-$poses
rm -rf "$work" && mkdir -p "$work"
synth=(build/panmap-synth -q --room "$room" --room-style "$style" --laps 2 --seed "$seed"
       --frames "$frames" --rate-hz 5 --masks m2f)
"${synth[@]}" --poses gt --out "$work/gt_seq"
"${synth[@]}" --poses "$poses" --correction-every 10 --correction-residual-cm "$residual_cm" \
  --correction-residual-deg "$residual_deg" --out "$work/drift_seq"
map() {  # log, out, extra args
  build/panmap-mapper -q --no-snapshots --voxel-size 0.02 --tracking off --log "$1" \
    --out "$work/$2" "${@:3}" >/dev/null
}
# The graphs say which objects and super-points kept their ids through the repair, and which
# of the edges it dropped the map from ground-truth poses has (scripts/bench/object_ids.py).
map "$work/gt_seq/sequence.lcmlog" gt_poses --graph-json "$work/gt_poses/graph.json"
map "$work/drift_seq/sequence.lcmlog" drifted --graph-json "$work/drifted/graph.json"
map "$work/drift_seq/sequence.lcmlog" repaired --frame-store "$work/store" \
  --graph-json "$work/repaired/graph.json"
maps=(gt_poses drifted repaired)
if [ "$reintegrate_also" = 1 ]; then
  map "$work/drift_seq/sequence.lcmlog" reintegrated --frame-store "$work/store_reintegrated" \
    --repair-reintegrate-only
  maps+=(reintegrated)
fi
python3 - "$work" <<'PY'
import json, sys
work = sys.argv[1]
info = json.load(open(work + "/drift_seq/info.json"))
r = json.load(open(work + "/repaired/report.json"))
print("sequence: %d frames, input ATE %.2f cm, correction of %d keyframes (residual %g cm, %g deg)"
      % (info["frames"], 100 * info["measured"]["input_ate_rmse_m"],
         info["correction"]["keyframes"], info["correction"]["residual_cm"],
         info["correction"]["residual_deg"]))
print("repair:", "; ".join(r["corrections"]["repairs"]) or "none")
try:
    r = json.load(open(work + "/reintegrated/report.json"))
    print("re-integration:", "; ".join(r["corrections"]["repairs"]) or "none")
except FileNotFoundError:
    pass
PY
for m in "${maps[@]}"; do
  build/panmap-eval --pred "$work/$m/mesh_instance.ply" --gt "$work/gt_seq/gt/mesh.ply" \
    --json "$work/$m/eval.json" >/dev/null
  map50=$(python3 -c "import json,sys; print('%.1f' % (100*json.load(open(sys.argv[1]))['map50']))" \
    "$work/$m/eval.json")
  surface=$(python3 scripts/bench/surface_distance.py "$work/$m/mesh_instance.ply" \
    "$work/gt_seq/gt/mesh.ply")
  occupancy=$(build/panmap-occupancy-probe --file "$work/$m/occupancy.bt" \
    --compare "$work/gt_poses/occupancy.bt")
  purity=$(python3 -c "import json,sys; print('%.3f' % json.load(open(sys.argv[1]))['diagnostics']['superpoint_purity'])" \
    "$work/$m/eval.json")
  echo "$m: mAP50 $map50; purity $purity; ${surface#*: }; occupancy vs gt_poses: $occupancy"
done
python3 scripts/bench/object_ids.py "$work/drifted/graph.json" "$work/repaired/graph.json" \
  --reference "$work/gt_poses/graph.json" --repaired-mesh "$work/repaired/mesh_superpoint.ply" \
  --reference-mesh "$work/gt_poses/mesh_superpoint.ply"
