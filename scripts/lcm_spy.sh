#!/usr/bin/env bash
# Starts lcm-spy with panmap's message types on the classpath, so our channels show decoded.
# Debian's /usr/bin/lcm-spy fails on Java 17; this runs lcm.spy.Spy directly.
#   scripts/lcm_spy.sh [--lcm-url URL]
set -euo pipefail
cd "$(dirname "$0")/.."
types_jar=build/lcmtypes/panmap_lcmtypes.jar
[ -f "$types_jar" ] || { echo "lcm_spy.sh: $types_jar missing: run scripts/setup.sh first" >&2; exit 1; }
for jar in /usr/share/java/lcm.jar /usr/share/java/jchart2d.jar; do
  [ -f "$jar" ] || { echo "lcm_spy.sh: $jar missing: run scripts/setup.sh first" >&2; exit 1; }
done
exec java -cp "/usr/share/java/lcm.jar:/usr/share/java/jchart2d.jar:$types_jar" lcm.spy.Spy "$@"
