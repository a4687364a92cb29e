#!/usr/bin/env bash
# The main job on the bundled demo, on a fresh Debian machine:
#  1. set up and build (scripts/setup.sh);
#  2. make the demo log in logs/ if missing (panmap-synth: procedural room 1, seed 1, a 90 s
#     survey at 5 Hz; and the real 7-Scenes sample imported, for trying the mapper on real data);
#  3. start panmap-optimizer and panmap-mapper (2 cm voxels: a whole room at 1 cm makes a
#     1.3 GB map file), replay the log with lcm-logplayer over loopback UDP, send "finish",
#     print where the outputs are and score the map against the room's ground truth.
# Where UDP multicast is unavailable it says so and maps the log offline instead.
#   scripts/demo.sh [--offline] [--speed S]     (S: lcm-logplayer speed, default 2: 10 Hz)
set -euo pipefail
cd "$(dirname "$0")/.."
offline=0
speed=2
while [ $# -gt 0 ]; do
  case "$1" in
    --offline) offline=1 ;;
    --speed) speed="$2"; shift ;;
    -h|--help) sed -n '2,11p' "$0"; exit 0 ;;
    *) echo "demo.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
  shift
done

# Only the tools the demo runs (scripts/test.sh builds everything).
scripts/setup.sh --targets "panmap-import panmap-loginfo panmap-synth panmap-mapper \
  panmap-optimizer panmap-command panmap-eval panmap-occupancy-probe"
mkdir -p logs
data=../shared/data/7scenes-200
if [ -d "$data" ] && [ ! -f logs/7scenes-200.lcmlog ]; then
  build/panmap-import "$data" logs/7scenes-200.lcmlog
fi
log_dir=logs/room1-survey
if [ ! -f $log_dir/sequence.lcmlog ]; then
  build/panmap-synth --room 1 --frames 450 --rate-hz 5 --masks m2f --poses gt --seed 1 \
    --out $log_dir
fi
build/panmap-loginfo --quiet --shallow $log_dir/sequence.lcmlog
out=out/room1
rm -rf "$out"

# LCM's default URL (what lcm-spy listens to), kept on this machine.
url="udpm://239.255.76.67:7667?ttl=0&recv_buf_size=16777216"
if [ "$offline" = 0 ] && ! build/panmap-command --self-test --lcm-url "$url"; then
  echo "demo: UDP multicast on loopback is unavailable here (scripts/setup.sh needs root for it);"
  echo "demo: mapping the log offline instead"
  offline=1
fi

if [ "$offline" = 1 ]; then
  build/panmap-mapper --log $log_dir/sequence.lcmlog --out "$out" --config configs/fast_2cm.yaml
else
  pids=()
  trap 'kill "${pids[@]}" 2>/dev/null || true' EXIT
  build/panmap-optimizer --lcm-url "$url" & pids+=($!)
  build/panmap-mapper --lcm-url "$url" --out "$out" --config configs/fast_2cm.yaml &
  mapper=$!; pids+=($mapper)
  sleep 1  # both subscribed before the first message
  echo "demo: replaying $log_dir/sequence.lcmlog at ${speed}x (watch it with scripts/lcm_spy.sh)"
  lcm-logplayer -s "$speed" -l "$url" $log_dir/sequence.lcmlog
  build/panmap-command --lcm-url "$url" finish
  wait "$mapper"
fi

echo
echo "demo: outputs in $out/:"
for f in mesh_semantic.ply mesh_instance.ply mesh_superpoint.ply objects.json occupancy.bt \
         trajectory.txt map.panmap report.json config.yaml snapshot_semantic.png \
         snapshot_instance.png; do
  [ -f "$out/$f" ] && printf '  %-24s %s\n' "$f" "$(du -h "$out/$f" | cut -f1)"
done
echo "demo: the map against the room's ground truth ($log_dir/gt/):"
# The summary rows by name: panmap-eval's per-class table and diagnostics grow over time.
build/panmap-eval --pred $out/mesh_instance.ply --gt $log_dir/gt/mesh.ply \
  --confidences $out/objects.json |
  grep -E '^(class |average/sum|GT things at IoU|objects:|stuff IoU|reliability:)'
echo "demo: query the occupancy like a planner: build/panmap-occupancy-probe --file $out/occupancy.bt --point X Y Z"
