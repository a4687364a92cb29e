#!/usr/bin/env bash
# The main job on the bundled demo: set up and build, make the demo logs in logs/ if missing
# (the real 7-Scenes sample imported; a synthetic room rendered with panmap-synth, seed 1),
# map the synthetic room offline and print where the outputs are.
#   scripts/demo.sh
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
mkdir -p logs
data=../shared/data/7scenes-200
if [ -d "$data" ] && [ ! -f logs/7scenes-200.lcmlog ]; then
  build/panmap-import "$data" logs/7scenes-200.lcmlog
fi
if [ ! -f logs/room1/sequence.lcmlog ]; then
  build/panmap-synth --room 1 --frames 300 --masks m2f --poses gt --seed 1 --out logs/room1
fi
build/panmap-loginfo --quiet --shallow logs/room1/sequence.lcmlog
build/panmap-mapper --log logs/room1/sequence.lcmlog --out out/room1
echo
echo "demo: outputs in out/room1/: mesh_semantic.ply mesh_instance.ply mesh_superpoint.ply"
echo "      map.panmap report.json snapshot_{semantic,instance,superpoint,color}.png"
echo "demo: ground truth of the room in logs/room1/gt/; replay the log with"
echo "      lcm-logplayer logs/room1/sequence.lcmlog   (watch with scripts/lcm_spy.sh)"
