#!/usr/bin/env bash
# lcm-logplayer, panmap-mapper and panmap-optimizer on three hosts: three Linux network
# namespaces, each with one veth leg on a bridge (in a fourth namespace), a multicast route
# and LCM at ttl=1, as on a robot's LAN. The same log is then mapped with all three processes
# in one namespace (the single-host run), and the outputs must be byte-identical.
#
#   scripts/three_hosts.sh [--log FILE] [--keep DIR] [--speed S]
#     --log    LCM log to replay (default: a 120-frame render of room 1, m2f masks)
#     --keep   keep both runs' outputs in DIR (default: a temporary folder, removed)
#     --speed  lcm-logplayer speed factor (default 4)
# Needs root (CAP_NET_ADMIN, CAP_SYS_ADMIN) and `ip netns`: where either is missing it prints
# "three_hosts: SKIPPED: <why>" and exits 0, so CI says plainly that it skipped. Exit 1 when
# the outputs differ or a run failed, 2 on bad usage.
set -euo pipefail
cd "$(dirname "$0")/.."

log= keep= speed=4
while [ $# -gt 0 ]; do
  case "$1" in
    --log) log="$2"; shift ;;
    --keep) keep="$2"; shift ;;
    --speed) speed="$2"; shift ;;
    -h|--help) sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "three_hosts: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
  shift
done

skip() { echo "three_hosts: SKIPPED: $*"; exit 0; }
fail() { echo "three_hosts: FAILED: $*" >&2; exit 1; }

[ "$(id -u)" -eq 0 ] || skip "not root (network namespaces need CAP_NET_ADMIN and CAP_SYS_ADMIN)"
command -v ip >/dev/null || skip "no 'ip' command (iproute2)"
command -v lcm-logplayer >/dev/null || skip "no lcm-logplayer (scripts/setup.sh installs liblcm-bin)"
for tool in panmap-mapper panmap-optimizer panmap-command panmap-synth; do
  [ -x "build/$tool" ] || fail "build/$tool is missing (run scripts/setup.sh first)"
done

# Namespace and link names carry this process id, so two runs never collide.
tag=$$
ns_bridge="pmbr$tag" ns_player="pmplay$tag" ns_mapper="pmmap$tag" ns_optimizer="pmopt$tag"
hosts=("$ns_player" "$ns_mapper" "$ns_optimizer")
work=$(mktemp -d /tmp/panmap-three-hosts.XXXXXX)
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  for ns in "${hosts[@]}" "$ns_bridge"; do ip netns del "$ns" 2>/dev/null || true; done
  rm -rf "$work"
}
trap cleanup EXIT

ip netns add "$ns_bridge" 2>/dev/null || skip "cannot create a network namespace here (ip netns add failed: no CAP_SYS_ADMIN, or a container without it)"
ip -n "$ns_bridge" link add br0 type bridge 2>/dev/null || skip "cannot create a bridge (no bridge support in this kernel or container)"
# No IGMP snooping: with no querier on this LAN the bridge would otherwise forward a group's
# traffic only to ports it saw join, and the player never joins.
ip -n "$ns_bridge" link set br0 type bridge mcast_snooping 0
ip -n "$ns_bridge" link set br0 up
address=10
for ns in "${hosts[@]}"; do
  address=$((address + 1))
  ip netns add "$ns"
  ip link add "v$ns" type veth peer name eth0 netns "$ns" 2>/dev/null ||
    skip "cannot create a veth pair (no veth support in this kernel or container)"
  ip link set "v$ns" netns "$ns_bridge"
  ip -n "$ns_bridge" link set "v$ns" master br0 up
  ip -n "$ns" link set lo up
  ip -n "$ns" addr add "10.213.77.$address/24" dev eth0
  ip -n "$ns" link set eth0 up
  ip -n "$ns" route add 224.0.0.0/4 dev eth0
done
echo "three_hosts: hosts $ns_player (10.213.77.11), $ns_mapper (.12), $ns_optimizer (.13) on bridge br0 of $ns_bridge"

if [ -z "$log" ]; then
  echo "three_hosts: rendering room 1, 120 frames, m2f masks (panmap-synth)"
  build/panmap-synth --room 1 --frames 120 --rate-hz 5 --masks m2f --poses gt --seed 1 \
    --out "$work/room1" >"$work/synth.log" 2>&1 || { cat "$work/synth.log"; fail "panmap-synth failed"; }
  log="$work/room1/sequence.lcmlog"
fi
[ -f "$log" ] || fail "no log $log"

# ttl=1: the datagrams leave the host (ttl=0 would keep them on it) and go no further than
# the LAN. A queue longer than the log: no frame is dropped, so both runs map the same frames.
url="udpm://239.255.76.67:7667?ttl=1&recv_buf_size=16777216"
run() {  # run NAME PLAYER_NS MAPPER_NS OPTIMIZER_NS
  local name=$1 player=$2 mapper=$3 optimizer=$4 out="$work/$1"
  pids=()
  ip netns exec "$optimizer" build/panmap-optimizer --lcm-url "$url" >"$work/$name.optimizer.log" 2>&1 &
  pids+=($!)
  ip netns exec "$mapper" build/panmap-mapper -q --lcm-url "$url" --out "$out" \
    --voxel-size 0.02 --threads 2 --queue-frames 100000 --autosave-s 0 --no-snapshots \
    >"$work/$name.mapper.log" 2>&1 &
  local mapper_pid=$!
  pids+=($mapper_pid)
  # Both subscribed before the first message: the mapper answers status only once it runs.
  local tries=0
  until ip netns exec "$player" build/panmap-command --lcm-url "$url" --timeout-s 1 status \
      >/dev/null 2>&1; do
    tries=$((tries + 1))
    [ "$tries" -lt 30 ] || fail "$name: the mapper never published PANMAP_STATUS across the bridge"
  done
  local start=$(date +%s.%N)
  ip netns exec "$player" lcm-logplayer -s "$speed" -l "$url" "$log" >/dev/null
  ip netns exec "$player" build/panmap-command --lcm-url "$url" finish
  wait "$mapper_pid" || { cat "$work/$name.mapper.log"; fail "$name: panmap-mapper exited non-zero"; }
  kill "${pids[0]}" 2>/dev/null || true
  wait "${pids[0]}" 2>/dev/null || true
  pids=()
  python3 - "$out/report.json" "$name" "$start" "$(date +%s.%N)" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
graph = r.get("graph", {})
print("three_hosts: %-12s %s of %s frames received and integrated, final labels %s, %.1f s" % (
    sys.argv[2], r.get("frames_integrated"), r.get("frames_received"),
    "from panmap-optimizer" if graph.get("optimised") else "NOT optimised",
    float(sys.argv[4]) - float(sys.argv[3])))
PY
}

run three-hosts "$ns_player" "$ns_mapper" "$ns_optimizer"
run single-host "$ns_mapper" "$ns_mapper" "$ns_mapper"

status=0
for f in map.panmap mesh_semantic.ply mesh_instance.ply mesh_superpoint.ply objects.json \
         occupancy.bt trajectory.txt; do
  if [ ! -f "$work/three-hosts/$f" ] || [ ! -f "$work/single-host/$f" ]; then
    echo "three_hosts: $f missing"; status=1
  elif cmp -s "$work/three-hosts/$f" "$work/single-host/$f"; then
    printf 'three_hosts: %-20s identical (%s bytes)\n' "$f" "$(stat -c %s "$work/three-hosts/$f")"
  else
    echo "three_hosts: $f DIFFERS between the three-host and the single-host run"; status=1
  fi
done
if [ -n "$keep" ]; then
  mkdir -p "$keep"
  cp -r "$work/three-hosts" "$work/single-host" "$keep"/
  cp "$work"/*.log "$keep"/ 2>/dev/null || true
  echo "three_hosts: outputs kept in $keep"
fi
[ "$status" -eq 0 ] || fail "outputs differ"
echo "three_hosts: OK: the three-host run equals the single-host run"
