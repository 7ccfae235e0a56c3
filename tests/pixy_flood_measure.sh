#!/bin/bash
# What a flood on the Pixy line does to the pixy bridge and the estimator
# (docs/robustness.md, "Floods on the Pixy line"). A measurement, not a test:
#   tests/pixy_flood_measure.sh BIN_DIR CONFIG_DIR [sync|frames] [RATE] [SECONDS]
# Starts pixy_flood (a hostile Pixy on a pty: RATE bytes/s of sync words, or
# RATE valid frames/s), slam_estimator and pixy_bridge on that pty, on DDS
# domain $PIXYSLAM_DDS_DOMAIN (default 211), floods for SECONDS (default 5)
# after 4 s of start-up, then stops them with SIGINT and prints the bytes
# offered and read, the CPU the bridge and the estimator used during the
# flood, the bridge's WARN lines and its final status lines.
set -u
bin=${1:?usage: pixy_flood_measure.sh BIN_DIR CONFIG_DIR [sync|frames] [RATE] [SECONDS]}
cfg=${2:?usage: pixy_flood_measure.sh BIN_DIR CONFIG_DIR [sync|frames] [RATE] [SECONDS]}
pattern=${3:-sync}
rate=${4:-1000000}
seconds=${5:-5}
export PIXYSLAM_DDS_DOMAIN=${PIXYSLAM_DDS_DOMAIN:-211}
work=$(mktemp -d /tmp/pixy_flood.XXXXXX)
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null; done
  wait 2>/dev/null
  rm -rf "$work"
}
trap cleanup EXIT

cpu_s() {  # utime + stime of a process, in seconds
  awk -v hz="$(getconf CLK_TCK)" '{ sub(/^.*\) /, ""); print ($12 + $13) / hz }' "/proc/$1/stat"
}

startup=4
"$bin/pixy_flood" "$work/pixy" "$pattern" "$rate" "$seconds" "$startup" >"$work/flood.out" 2>&1 &
flood=$!
pids+=("$flood")
for _ in $(seq 50); do [ -e "$work/pixy" ] && break; sleep 0.1; done
"$bin/slam_estimator" --config "$cfg/slam_estimator.yaml" >/dev/null 2>"$work/estimator.err" &
estimator=$!
pids+=("$estimator")
"$bin/pixy_bridge" --config "$cfg/pixy_bridge.yaml" --device "$work/pixy" >/dev/null 2>"$work/bridge.err" &
bridge=$!
pids+=("$bridge")

sleep "$startup"
b0=$(cpu_s "$bridge"); e0=$(cpu_s "$estimator")
sleep "$seconds"
b1=$(cpu_s "$bridge"); e1=$(cpu_s "$estimator")
wait "$flood"  # it keeps the pty open for 1 s after the flood
kill -INT "$bridge" "$estimator" 2>/dev/null || true
wait "$bridge" "$estimator"

cat "$work/flood.out"
awk -v b0="$b0" -v b1="$b1" -v e0="$e0" -v e1="$e1" -v s="$seconds" \
  'BEGIN { printf "cpu during the flood: pixy_bridge %.0f %%, slam_estimator %.0f %%\n", 100 * (b1 - b0) / s, 100 * (e1 - e0) / s }'
grep -E "WARN|final status" "$work/bridge.err"
