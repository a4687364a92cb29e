#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ with clang into build-fuzz/ and runs each on a copy of
# its seed corpus (fuzz/corpus/<target>; the committed corpus never grows).
#
#   scripts/fuzz.sh [--time SECONDS] [--runs N] [--targets a,b] [--jobs N] [--report FILE]
#                   [--opt LEVEL] [--no-build]
#     --time     seconds per target (default 60); with --runs, whichever comes first
#     --runs     executions per target (default: no limit)
#     --targets  comma-separated subset of: image_codec ply text_files dataset coco_panoptic
#                scannet_gt config map_file lcm_messages lcm_session (default: all)
#     --jobs     targets run side by side (default 1; each target is one process)
#     --report   rewrite the generated table of this Markdown file (e.g. docs/FUZZING.md)
#     --opt      clang's -O level for the build (default 3, as Release; CI's brief runs use 1,
#                a quicker clean build with about as many executions a second)
#     --no-build run what build-fuzz/ holds
# Prints one line per target: executions, exec/s, seconds, corpus size, result. Exits 1 when
# a target crashed (the crash input's path is in its line), 2 on bad usage.
set -euo pipefail
cd "$(dirname "$0")/.."

all_targets=(image_codec ply text_files dataset coco_panoptic scannet_gt config map_file
             lcm_messages lcm_session)
# Largest input per target: room for the seeds and a little growth. map_file's seeds hold a
# 22.5 KB voxel block; the rest are small files or messages.
declare -A max_len=(
  [image_codec]=4096 [ply]=4096 [text_files]=2048 [dataset]=8192 [coco_panoptic]=4096
  [scannet_gt]=4096 [config]=8192 [map_file]=65536 [lcm_messages]=4096 [lcm_session]=8192)

seconds=60 runs=0 targets= jobs=1 report= build=1 opt=3
usage() { sed -n '2,17p' "$0" | sed 's/^# \{0,1\}//'; }
while [ $# -gt 0 ]; do
  case "$1" in
    --time) seconds="$2"; shift ;;
    --runs) runs="$2"; shift ;;
    --targets) targets="$2"; shift ;;
    --jobs) jobs="$2"; shift ;;
    --report) report="$2"; shift ;;
    --opt) opt="$2"; shift ;;
    --no-build) build=0 ;;
    -h|--help) usage; exit 0 ;;
    *) echo "fuzz.sh: unknown option $1" >&2; usage >&2; exit 2 ;;
  esac
  shift
done
for n in "$seconds" "$runs" "$jobs" "$opt"; do
  [[ "$n" =~ ^[0-9]+$ ]] || { echo "fuzz.sh: '$n' is not a number" >&2; exit 2; }
done
[ "$jobs" -ge 1 ] || jobs=1
[ "$opt" -le 3 ] || { echo "fuzz.sh: --opt takes 0 to 3, not $opt" >&2; exit 2; }
if [ -n "$targets" ]; then
  IFS=, read -r -a selected <<<"$targets"
  for t in "${selected[@]}"; do
    [ -n "${max_len[$t]:-}" ] || { echo "fuzz.sh: unknown target $t" >&2; exit 2; }
  done
else
  selected=("${all_targets[@]}")
fi

build_dir=build-fuzz
if [ "$build" -eq 1 ]; then
  command -v clang++ >/dev/null || { echo "fuzz.sh: clang++ not found (scripts/setup.sh installs it)" >&2; exit 1; }
  mkdir -p "$build_dir"
  start=$(date +%s)
  # Only what the targets link is built: no tests, benchmarks, Java jar or tools.
  if ! CC=clang CXX=clang++ cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release \
      -DPANMAP_BUILD_FUZZERS=ON -DPANMAP_BUILD_TESTS=OFF -DPANMAP_BUILD_BENCHMARKS=OFF \
      -DPANMAP_BUILD_JAVA=OFF -DCMAKE_CXX_FLAGS_RELEASE="-O$opt -DNDEBUG" \
      -DCMAKE_C_FLAGS_RELEASE="-O$opt -DNDEBUG" >"$build_dir/configure.log" 2>&1; then
    cat "$build_dir/configure.log"; echo "fuzz.sh: configure failed" >&2; exit 1
  fi
  build_jobs=$(nproc 2>/dev/null || echo 2)
  target_args=()
  for t in "${selected[@]}"; do target_args+=(--target "fuzz_$t"); done
  if ! cmake --build "$build_dir" -j "$build_jobs" "${target_args[@]}" >"$build_dir/build.log" 2>&1; then
    grep -E -B2 -A6 "error" "$build_dir/build.log" | head -60
    echo "fuzz.sh: build failed (full log: $build_dir/build.log)" >&2; exit 1
  fi
  echo "fuzz.sh: built ${#selected[@]} targets at -O$opt in $(( $(date +%s) - start )) s"
fi

work=$(mktemp -d /tmp/panmap-fuzz-run.XXXXXX)
trap 'rm -rf "$work"' EXIT
artifacts="$build_dir/fuzz-artifacts"
mkdir -p "$artifacts"

# Runs one target; writes its result line to $work/<target>.result.
run_target() {
  local t=$1 corpus="$work/$1.corpus" log="$build_dir/fuzz-$1.log"
  mkdir -p "$corpus"
  cp fuzz/corpus/"$t"/* "$corpus"/
  local args=(-max_len="${max_len[$t]}" -rss_limit_mb=2048 -timeout=10 -print_final_stats=1
              -max_total_time="$seconds" -artifact_prefix="$artifacts/$t-")
  [ "$runs" -gt 0 ] && args+=(-runs="$runs")
  local start end rc=0
  start=$(date +%s.%N)
  UBSAN_OPTIONS=print_stacktrace=1 "$build_dir/fuzz/fuzz_$t" "${args[@]}" "$corpus" \
    >"$log" 2>&1 || rc=$?
  end=$(date +%s.%N)
  local execs files kb elapsed rate result
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  execs=${execs:-0}
  elapsed=$(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.0f", b - a }')
  rate=$(awk -v n="$execs" -v s="$elapsed" 'BEGIN { printf "%.0f", (s > 0 ? n / s : 0) }')
  files=$(find "$corpus" -type f | wc -l)
  kb=$(find "$corpus" -type f -printf '%s\n' | awk '{ s += $1 } END { printf "%d", s / 1024 }')
  if [ "$rc" -eq 0 ]; then
    result=ok
  else
    local crash
    crash=$(sed -n 's/.*Test unit written to \(.*\)$/\1/p' "$log" | tail -1)
    result="CRASH (exit $rc): ${crash:-no input saved}, log $log"
  fi
  printf '%s\t%s\t%s\t%s\t%s files / %s KB\t%s\n' "$t" "$execs" "$rate" "$elapsed" "$files" \
    "$kb" "$result" >"$work/$t.result"
  printf 'fuzz.sh: %-14s %10s execs %7s/s %5s s  %s\n' "$t" "$execs" "$rate" "$elapsed" "$result"
}

echo "fuzz.sh: ${#selected[@]} targets, ${seconds} s each$([ "$runs" -gt 0 ] && echo " or $runs runs"), $jobs at a time"
for t in "${selected[@]}"; do
  while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do wait -n || true; done
  run_target "$t" &
done
wait

printf '\n%-14s %12s %9s %8s  %-22s %s\n' target executions exec/s seconds corpus result
crashed=0
for t in "${selected[@]}"; do
  IFS=$'\t' read -r name execs rate elapsed corpus result <"$work/$t.result"
  printf '%-14s %12s %9s %8s  %-22s %s\n' "$name" "$execs" "$rate" "$elapsed" "$corpus" "$result"
  [ "$result" = ok ] || crashed=1
done

if [ -n "$report" ]; then
  # Rows of the targets run now replace theirs; the other targets keep their last row, so a
  # single target can be rerun (each row names its commit and date).
  commit=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
  git diff --quiet HEAD -- src include fuzz cmake CMakeLists.txt 2>/dev/null || commit="$commit+changes"
  model=$(lscpu 2>/dev/null | sed -n 's/^Model name: *//p' | head -1)
  limit="$seconds s"
  [ "$runs" -gt 0 ] && limit="$runs executions or $seconds s, whichever first"
  # The level build-fuzz/ was built at (with --no-build, not necessarily --opt's).
  built_opt=$(sed -n 's/^CMAKE_CXX_FLAGS_RELEASE:STRING=-O\([0-9]\).*/\1/p' \
              "$build_dir/CMakeCache.txt" 2>/dev/null)
  [ "${built_opt:-3}" = 3 ] || limit="$limit, -O$built_opt"
  day=$(date -u '+%Y-%m-%d')
  [ -f "$report" ] || printf '<!-- fuzz-table:begin -->\n<!-- fuzz-table:end -->\n' >"$report"
  table="$work/table.md"
  {
    echo "<!-- fuzz-table:begin (generated by scripts/fuzz.sh --report; do not edit) -->"
    echo "Machine: $(nproc) cores, ${model:-unknown CPU}. Last run: $day, commit $commit, $limit per target, $jobs at a time."
    echo
    echo "| target | executions | exec/s | seconds | corpus at the end | result | run |"
    echo "| --- | ---: | ---: | ---: | --- | --- | --- |"
    for t in "${all_targets[@]}"; do
      if [ -f "$work/$t.result" ]; then
        IFS=$'\t' read -r name execs rate elapsed corpus result <"$work/$t.result"
        echo "| $name | $execs | $rate | $elapsed | $corpus | $result | $commit, $day, $limit |"
      else
        grep -E "^\| $t \|" "$report" | head -1 || true
      fi
    done
    echo "<!-- fuzz-table:end -->"
  } >"$table"
  awk -v table="$table" '
    /<!-- fuzz-table:begin/ { while ((getline line < table) > 0) print line; skip = 1; next }
    /<!-- fuzz-table:end/ { skip = 0; next }
    !skip { print }' "$report" >"$work/report.md"
  cp "$work/report.md" "$report"
  echo "fuzz.sh: table written to $report"
fi
exit "$crashed"
