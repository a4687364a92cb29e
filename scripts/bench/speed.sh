#!/usr/bin/env bash
# Speed and memory of the mapping pipeline on this machine, side by side with Open3D's
# ScalableTSDFVolume on the same frames, and the pipeline's parts; writes docs/PERFORMANCE.md.
# About 15 minutes on 2 cores. Installs libopen3d-dev (setup.sh --with-open3d) when it can;
# without it the Open3D columns say so.
#   scripts/bench/speed.sh [--no-memory | --memory-only]
#     --no-memory    skip the 3000-frame memory run
#     --memory-only  only the memory run (4 min): rewrites its section of docs/PERFORMANCE.md
set -euo pipefail
cd "$(dirname "$0")/../.."
memory=1
memory_only=0
for arg in "$@"; do
  case "$arg" in
    --no-memory) memory=0 ;;
    --memory-only) memory_only=1 ;;
    -h|--help) sed -n '2,8p' "$0"; exit 0 ;;
    *) echo "speed.sh: unknown option $arg" >&2; exit 2 ;;
  esac
done
out=docs/PERFORMANCE.md
# The long-run memory section, between markers so that --memory-only can replace it alone.
memory_section() {  # $1: the table rows
  cat <<MD
<!-- memory:begin (scripts/bench/speed.sh; --memory-only rewrites this section alone) -->
## Memory on a long run

\`panmap-bench-memory --room 1 --frames 3000 --voxel-size 0.02\`: a 100 s walk (30 Hz)
through one room, rendered in-process and mapped frame by frame with its masks; measured on
$(date -u +%Y-%m-%d) at commit \`$(git rev-parse --short HEAD)\`. Resident memory against what the map
holds: TSDF blocks, occupancy cells and the super-point graph with its bookkeeping (estimated
from its table slots and std::map nodes); \`other\` is the rest of the process (the renderer
and its room, libraries, scratch buffers), which must stay flat. Graph edges are kept only
between super-points that own observed surface and touch there, or whose co-observation is
strong (\`graph.prune_edges\`, checked every 100 frames; docs/MAPPING.md). \`graph ms\` and
\`total ms\` are the medians of the graph update and the whole frame over the 250 frames
before each sample (2 threads, with rendering in between).

$1
<!-- memory:end -->
MD
}
if [ "$memory_only" -eq 1 ]; then
  scripts/setup.sh --skip-network --skip-apt --targets panmap-bench-memory >&2
  [ -f "$out" ] && grep -q '<!-- memory:begin' "$out" ||
    { echo "speed.sh: $out has no memory section markers: run the whole script" >&2; exit 1; }
  echo "bench: 3000 frames through one room, memory sampled every 250 frames" >&2
  section=$(mktemp)
  memory_section "$(build/panmap-bench-memory --room 1 --frames 3000 --voxel-size 0.02 --every 250)" >"$section"
  awk -v section="$section" '
    /<!-- memory:begin/ { while ((getline line < section) > 0) print line; skip = 1; next }
    /<!-- memory:end -->/ { skip = 0; next }
    !skip { print }' "$out" >"$section.md"
  mv "$section.md" "$out"
  rm -f "$section"
  echo "bench: rewrote the memory section of $out" >&2
  exit 0
fi

targets="panmap-bench-mapping panmap-bench-memory panmap-bench-renderer panmap-bench-segmentation
  panmap-bench-block-hash panmap-bench-optimiser panmap-bench-tracking panmap-bench-occupancy
  panmap-bench-frame-store panmap-synth"
open3d=1
scripts/setup.sh --skip-network --with-open3d --targets "$targets panmap-bench-open3d" >&2 || {
  echo "speed.sh: building with Open3D failed; measuring without it" >&2
  open3d=0
  cmake -S . -B build -DPANMAP_WITH_OPEN3D=OFF >/dev/null
  scripts/setup.sh --skip-network --skip-apt --targets "$targets" >&2
}
data=../shared/data/7scenes-200
mkdir -p docs
cpu=$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

echo "bench: rendering a synthetic room (panmap-synth --room 1, 300 frames, m2f masks)" >&2
build/panmap-synth --room 1 --frames 300 --masks m2f --poses gt --seed 1 --quiet --out "$tmp/room1" >/dev/null
room_log="$tmp/room1/sequence.lcmlog"

# One row per (input, voxel size, threads): ours, then Open3D on the same decoded frames.
mapping_rows() {  # $1 = name, remaining: input arguments
  local name=$1; shift
  local rows=""
  for voxel in 0.01 0.02 0.05; do
    for threads in 1 2; do
      echo "bench: $name at $voxel m, $threads thread(s)" >&2
      rows+="$(build/panmap-bench-mapping "$@" --voxel-size $voxel --threads $threads --markdown-row \
                 --json "$tmp/ours_${name}_${voxel}_${threads}.json")"$'\n'
      if [ "$open3d" -eq 1 ]; then
        build/panmap-bench-open3d "$@" --voxel-size $voxel --threads $threads \
          --json "$tmp/open3d_${name}_${voxel}_${threads}.json" >/dev/null
      fi
    done
  done
  printf '%s' "$rows"
}
rows=$(mapping_rows 7scenes --data "$data")
room_rows=$(mapping_rows room1 --log "$room_log")
comparison=$(python3 scripts/bench/open3d_ratio.py "$tmp" "$open3d")

memory_rows="(not run: --no-memory)"
if [ "$memory" -eq 1 ]; then
  echo "bench: 3000 frames through one room, memory sampled every 250 frames" >&2
  memory_rows=$(build/panmap-bench-memory --room 1 --frames 3000 --voxel-size 0.02 --every 250)
fi

# Google Benchmark CSV: name,iterations,real_time,cpu_time,time_unit,...
gb() { "$1" --benchmark_format=csv "${@:2}" 2>/dev/null | grep '^"' ; }
echo "bench: renderer, segmentation, block hash map" >&2
render=$(gb build/panmap-bench-renderer | grep median | awk -F, '{gsub(/"/,"",$1); printf "| %s | %.1f ms |\n", $1, $3}')
segment=$(gb build/panmap-bench-segmentation --benchmark_repetitions=5 --benchmark_report_aggregates_only=true | grep median | awk -F, '{gsub(/"/,"",$1); printf "| %s | %.1f ms |\n", $1, $3}')
optimiser=$(gb build/panmap-bench-optimiser | grep median | awk -F, '{gsub(/"/,"",$1); printf "| %s | %.1f ms |\n", $1, $3}')
echo "bench: pose refinement, occupancy" >&2
tracking=$(build/panmap-bench-tracking --benchmark_format=csv 2>/dev/null | python3 scripts/bench/gb_counters.py median_ms p95_ms)
occupancy=$(build/panmap-bench-occupancy --benchmark_format=csv --benchmark_filter=BM_IntegrateFrame 2>/dev/null | python3 scripts/bench/gb_counters.py median_ms p95_ms)
# Separate run: the CSV reporter needs the same counters in every row.
occupancy+=$'\n'$(build/panmap-bench-occupancy --benchmark_format=csv --benchmark_filter=BM_OctomapInsertPointCloud 2>/dev/null | python3 scripts/bench/gb_counters.py median_ms p95_ms)
hash=$(gb build/panmap-bench-block-hash | awk -F, '{gsub(/"/,"",$1); printf "| %s | %.2f ms |\n", $1, $3}')
echo "bench: loop-closure frame store" >&2
frame_store=$(build/panmap-bench-frame-store --data "$data" 2>/dev/null)

memory_text=$(memory_section "$memory_rows")
# The soak and building sections belong to scripts/bench/soak.py and building.sh: kept as
# they were.
soak=""
building=""
if [ -f "$out" ]; then
  soak=$(sed -n '/<!-- soak:begin/,/<!-- soak:end -->/p' "$out")
  building=$(sed -n '/<!-- building:begin/,/<!-- building:end -->/p' "$out")
fi

cat > "$out" <<MD
# Performance

Generated by \`scripts/bench/speed.sh\` on $(date -u +%Y-%m-%d) at commit
\`$(git rev-parse --short HEAD)\`; machine: ${cpu}, $(nproc) cores. Do not edit by hand: rerun
the script. Times are wall-clock milliseconds per 640x480 frame, median / p95.

## Against Open3D

Label-TSDF integration alone (TSDF, colour and super-point label votes; panmap's
\`integration\` stage) against Open3D's \`ScalableTSDFVolume::Integrate\` (TSDF and colour,
Debian's libopen3d-dev) on the same frames and poses, same voxel size, truncation 4 voxels,
depth 0.1-3.5 m, both restricted to the same number of threads (Open3D through OpenMP).
Ratio = Open3D / panmap (above 1: panmap is faster). Target of roadmap issue 9: at least 2.

${comparison}

## Mapping pipeline (no network)

Per frame: 2D segmentation (III-A), super-point association (III-B; the occupancy update runs
alongside it on the other thread), label-TSDF integration with votes, graph update (III-C, only
with panoptic masks) and the occupancy update; \`total\` is the whole \`Mapper::integrate\`
call. Periodic outputs, timed separately every 30th frame (a live mapper publishes them once a
second): \`mesh update\` is \`Mapper::updateMesh\`, what a live view needs: marching cubes on
the blocks changed since the last update, each block's mesh labelled right after it is meshed
(on both threads); \`whole mesh\` then assembles the welded, labelled mesh of the whole map
from the stored block meshes (\`Mapper::extractMesh\`, what an export costs on top);
\`octree export\` serialises the occupancy tree as \`PANMAP_OCTOMAP\` carries it. Map MB:
voxel blocks and index at the end.

Real frames of \`7scenes-200\` (200 frames, geometry only), decoded beforehand (peak RSS
includes the ~300 MB of decoded input):

| voxel | threads | frames | segmentation | super-points | integration | graph | occupancy | total | mesh update | whole mesh | octree export | map MB | peak RSS MB | bytes / voxel |
|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|
${rows}

A synthetic room (\`panmap-synth --room 1 --frames 300 --masks m2f --poses gt\`, 30 Hz) with
panoptic masks, so the super-point graph is updated every frame; frames are decoded one by one
from the log:

| voxel | threads | frames | segmentation | super-points | integration | graph | occupancy | total | mesh update | whole mesh | octree export | map MB | peak RSS MB | bytes / voxel |
|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|
${room_rows}

Targets of roadmap issue 9 (2 threads, median total): <= 33 ms at 1 cm, <= 15 ms at 2 cm; of
issue 23: mesh update at 1 cm on 7-Scenes <= 30 ms median, 60 ms p95.

${memory_text}

## Parts

Renderer (\`panmap-bench-renderer\`, one core, 640x480; synthetic room and procedural rooms of
216k and 454k triangles), median of 5:

| benchmark | time per frame |
|---|---|
${render}

Depth segmentation alone (\`panmap-bench-segmentation\`, 7-Scenes frame 0), median of 5:

| benchmark | time |
|---|---|
${segment}

Final optimisation (\`panmap-bench-optimiser\`: alpha-beta swap + instance refinement on a
random graph of 5,000 super-points, 20 classes, 50,000 edges; "typical": 8 % of super-points
start with a wrong class, "noisy": 22 %; target of roadmap issue 4: <= 100 ms), median of 9:

| benchmark | time |
|---|---|
${optimiser}

Pose refinement against the map (\`panmap-bench-tracking\`: 640x480 frames of a procedural
room against its 1 cm TSDF, default config (its pixel strides: 16 then 8 px before issue 20, 20 then 10 since); target of roadmap issue 8:
<= 15 ms), median:

| benchmark | median ms | p95 ms |
|---|---|---|
${tracking}

Occupancy update (\`panmap-bench-occupancy\`: a 640x480 frame into the 5 cm cell grid, pixel
stride 2, 4 (the default) or 8; and, for comparison, OctoMap's own \`insertPointCloud\` of the
same frames at the same strides):

| benchmark | median ms | p95 ms |
|---|---|---|
${occupancy}

Block index: \`absl::flat_hash_map\` (used by \`TsdfMap\`) against \`std::unordered_map\`, 300k
lookups in runs of 8 and 11k inserts (\`panmap-bench-block-hash\`):

| benchmark | time |
|---|---|
${hash}

Loop-closure frame store (\`panmap-bench-frame-store\`, docs/LOOP_CLOSURE.md: every frame of
7scenes-200 stored with its depth, the per-pixel super-point labels of a geometry-only mapping
run, pose and intrinsics; budget of roadmap issue 22: <= 150 kB per frame; \`add()\` includes
an fsync of each file, of its folder and of the index):

\`\`\`
${frame_store}
\`\`\`
MD
[ -n "$soak" ] && printf '\n%s\n' "$soak" >> "$out"
[ -n "$building" ] && printf '\n%s\n' "$building" >> "$out"
echo "bench: wrote $out" >&2
