#!/usr/bin/env bash
# Sets up a fresh Debian machine for panmap and builds it into build/. Idempotent and
# non-interactive; safe to rerun. Steps it cannot do (no root, no network rights) are reported
# at the end, and the build still runs when the packages are there.
#
#   scripts/setup.sh [--skip-apt] [--skip-network] [--skip-build] [--build-dir DIR]
#                    [--targets "panmap-mapper panmap-synth ..."]   (default: everything)
#                    [--with-open3d]   (also Open3D, for scripts/bench/speed.sh only)
set -euo pipefail
cd "$(dirname "$0")/.."

skip_apt=0 skip_network=0 skip_build=0 build_dir=build targets= with_open3d=0
while [ $# -gt 0 ]; do
  case "$1" in
    --skip-apt) skip_apt=1 ;;
    --skip-network) skip_network=1 ;;
    --skip-build) skip_build=1 ;;
    --build-dir) build_dir="$2"; shift ;;
    --targets) targets="$2"; shift ;;
    --with-open3d) with_open3d=1 ;;
    -h|--help) sed -n '2,9p' "$0"; exit 0 ;;
    *) echo "setup.sh: unknown option $1" >&2; exit 2 ;;
  esac
  shift
done

# Every Debian package the build, tests, benchmarks and tools use.
packages=(
  build-essential cmake pkg-config git
  liblcm-dev liblcm-bin liblcm-java libglib2.0-dev   # LCM (C/C++ library, tools, lcm.jar)
  default-jdk-headless libjchart2d-java               # types jar for lcm-spy, its charts
  libeigen3-dev                                       # geometry
  libabsl-dev zlib1g-dev                              # block hash map, map file checksums
  libzstd-dev zstd                                    # frame store compression (loop repair); zstd: trace_object.py
  libopencv-dev                                       # image codecs, depth segmentation, resampling
  liboctomap-dev octomap-tools                        # occupancy tree for planners
  libceres-dev                                        # pose refinement against the map
  libgtest-dev libgmock-dev libbenchmark-dev          # tests and benchmarks
  nlohmann-json3-dev libcli11-dev                     # JSON files, command-line parsing
  libnanoflann-dev libboost-graph-dev                 # k-d tree (evaluation), graph algorithms
  clang libclang-rt-14-dev                            # libFuzzer and sanitisers (scripts/fuzz.sh)
  iproute2 procps                                     # ip / sysctl for the LCM network setup
)

# Open3D's TSDF volume is only measured side by side with ours (panmap-bench-open3d).
[ "$with_open3d" -eq 1 ] && packages+=(libopen3d-dev)

problems=()
as_root() {
  if [ "$(id -u)" -eq 0 ]; then "$@";
  elif command -v sudo >/dev/null && sudo -n true 2>/dev/null; then sudo -n "$@";
  else return 1; fi
}

if [ "$skip_apt" -eq 0 ]; then
  missing=()
  for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ ${#missing[@]} -gt 0 ]; then
    echo "setup: installing ${#missing[@]} Debian packages: ${missing[*]}"
    if as_root env DEBIAN_FRONTEND=noninteractive apt-get update -q >/dev/null &&
       as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends \
         "${missing[@]}" >/tmp/panmap-apt.log 2>&1; then
      echo "setup: packages installed"
    else
      problems+=("could not apt-get install ${missing[*]} (need root; see /tmp/panmap-apt.log)")
    fi
  else
    echo "setup: all ${#packages[@]} Debian packages already installed"
  fi
fi

# LCM's UDP multicast on loopback: multicast on lo, a route for LCM's group, and receive
# buffers that hold a burst of 2 MB frames at 30 Hz.
if [ "$skip_network" -eq 0 ]; then
  if as_root ip link set lo multicast on 2>/dev/null; then
    echo "setup: multicast enabled on lo"
  else
    problems+=("could not enable multicast on lo (needs root / CAP_NET_ADMIN): UDP tests will skip")
  fi
  if as_root ip route replace 239.255.76.0/24 dev lo 2>/dev/null; then
    echo "setup: route 239.255.76.0/24 via lo"
  else
    problems+=("could not route 239.255.76.0/24 via lo: UDP tests will skip")
  fi
  if as_root sysctl -q -w net.core.rmem_max=67108864 net.core.rmem_default=16777216 \
       >/dev/null 2>&1; then
    echo "setup: socket receive buffers raised (rmem_max 64 MiB, rmem_default 16 MiB)"
  else
    problems+=("could not raise net.core.rmem_max (read-only /proc/sys?): large UDP messages may drop")
  fi
fi

if [ "$skip_build" -eq 0 ]; then
  jobs=$(nproc 2>/dev/null || echo 2)
  mkdir -p "$build_dir"
  cmake_args=(-DCMAKE_BUILD_TYPE=Release)
  [ "$with_open3d" -eq 1 ] && cmake_args+=(-DPANMAP_WITH_OPEN3D=ON)
  cmake -S . -B "$build_dir" "${cmake_args[@]}" >"$build_dir/configure.log" 2>&1 ||
    { cat "$build_dir/configure.log"; echo "setup: cmake configure failed" >&2; exit 1; }
  echo "setup: building ${targets:-everything} into $build_dir/ with $jobs jobs"
  target_args=()
  for t in $targets; do target_args+=(--target "$t"); done
  if ! cmake --build "$build_dir" -j "$jobs" "${target_args[@]}" >"$build_dir/build.log" 2>&1; then
    grep -E -B2 -A6 "error" "$build_dir/build.log" | head -80
    echo "setup: build failed (full log: $build_dir/build.log)" >&2
    exit 1
  fi
  grep -E "warning:" "$build_dir/build.log" | head -20 || true
  echo "setup: build done"
fi

if [ ${#problems[@]} -gt 0 ]; then
  echo "setup: done, but could not:"
  for p in "${problems[@]}"; do echo "  - $p"; done
else
  echo "setup: done"
fi
