#!/usr/bin/env bash
# The main job on the bundled demo, on a fresh Debian machine:
#  1. set up and build (scripts/setup.sh);
#  2. make the demo log in logs/ if missing (panmap-synth, procedural room 1, seed 1; and the
#     real 7-Scenes sample imported, for trying the mapper on real data);
#  3. start panmap-optimizer and panmap-mapper, replay the log with lcm-logplayer over loopback
#     UDP, send "finish", and print where the outputs are.
# Where UDP multicast is unavailable it says so and maps the log offline instead.
#   scripts/demo.sh [--offline] [--speed S]     (S: lcm-logplayer speed, default 0.5)
set -euo pipefail
cd "$(dirname "$0")/.."
offline=0
speed=0.5
while [ $# -gt 0 ]; do
  case "$1" in
    --offline) offline=1 ;;
    --speed) speed="$2"; shift ;;
    -h|--help) sed -n '2,9p' "$0"; exit 0 ;;
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
if [ ! -f logs/room1/sequence.lcmlog ]; then
  build/panmap-synth --room 1 --frames 300 --masks m2f --poses gt --seed 1 --out logs/room1
fi
build/panmap-loginfo --quiet --shallow logs/room1/sequence.lcmlog
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
  build/panmap-mapper --log logs/room1/sequence.lcmlog --out "$out"
else
  pids=()
  trap 'kill "${pids[@]}" 2>/dev/null || true' EXIT
  build/panmap-optimizer --lcm-url "$url" & pids+=($!)
  build/panmap-mapper --lcm-url "$url" --out "$out" & mapper=$!; pids+=($mapper)
  sleep 1  # both subscribed before the first message
  echo "demo: replaying logs/room1/sequence.lcmlog at ${speed}x (watch it with scripts/lcm_spy.sh)"
  lcm-logplayer -s "$speed" -l "$url" logs/room1/sequence.lcmlog
  build/panmap-command --lcm-url "$url" finish
  wait "$mapper"
fi

echo
echo "demo: outputs in $out/:"
for f in mesh_semantic.ply mesh_instance.ply mesh_superpoint.ply objects.json occupancy.bt \
         map.panmap report.json config.yaml snapshot_semantic.png snapshot_instance.png; do
  [ -f "$out/$f" ] && printf '  %-24s %s\n' "$f" "$(du -h "$out/$f" | cut -f1)"
done
echo "demo: ground truth of the room in logs/room1/gt/; score the map with"
echo "      build/panmap-eval --pred $out/mesh_instance.ply --gt logs/room1/gt/mesh.ply"
