#!/usr/bin/env bash
# Discovery at fleet scale: N robots' processes (encoder_bridge, pixy_bridge and
# slam_estimator per robot, dds.robot_id robot1..N: 3N participants) on one DDS
# domain, in a network namespace this script makes (its own loopback with
# multicast: no traffic leaves it; root needed), with simple multicast
# discovery or through a `fastdds discovery` server. The bridges' devices do not
# exist (they retry), so what flows is discovery and the 1 Hz diagnostics.
# With --sim, once every reader matched, a robot_sim per robot (hardware.seed =
# the robot's number, ground truth on DDS: 4N participants) drives SETTLE_S
# simulated seconds in real time (measured from 10 s after they started):
# then the sensor data flows too, and each
# estimator's input counts (its own robot's samples, the others' it dropped)
# are printed from its final line.
# Prints: the time until every estimator's Odometry reader matched all N
# encoder_bridge writers (seen by pixyslam_spy topics), CPU time and peak RSS
# per process kind over SETTLE_S seconds, and the bytes on the namespace's
# loopback (start-up and steady state per second).
#   scripts/fleet_scale.sh N multicast|server [SETTLE_S] [--sim]     (docs/deployment.md)
# Exit status: 0 measured, 1 the readers did not all match within 120 s (or,
# --sim, an estimator got none of its robot's samples or lost some), 2 usage,
# 77 not root (skipped).
set -euo pipefail
usage() { sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0"; }
case ${1:-} in -h | --help) usage; exit 0 ;; esac
sim=0
args=()
for a in "$@"; do if [[ $a == --sim ]]; then sim=1; else args+=("$a"); fi; done
set -- "${args[@]}"
(($# >= 2 && $# <= 3)) || { usage >&2; exit 2; }
n=$1 mode=$2 settle=${3:-30}
[[ $settle =~ ^[0-9]+$ ]] && ((settle >= 1)) || { echo "fleet_scale: SETTLE_S must be a whole number of seconds >= 1" >&2; exit 2; }
[[ $n =~ ^[0-9]+$ ]] && ((n >= 1 && n <= 200)) || { echo "fleet_scale: N must be 1..200" >&2; exit 2; }
[[ $mode == multicast || $mode == server ]] || { echo "fleet_scale: mode must be multicast or server" >&2; exit 2; }
((EUID == 0)) || { echo "fleet_scale: needs root (it makes a network namespace); skipped" >&2; exit 77; }
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${BUILD_DIR:-$root/build}/bin
ns=pxscale$$
work=$(mktemp -d /tmp/pixyslam_fleet_scale.XXXXXX)
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill -INT "$pid" 2>/dev/null || true; done
  sleep 1
  for pid in "${pids[@]}"; do kill -KILL "$pid" 2>/dev/null || true; done
  wait 2>/dev/null || true
  # Anything still in the namespace (a process that outlived its parent) goes with it.
  ip netns pids "$ns" 2>/dev/null | xargs -r kill -KILL 2>/dev/null || true
  ip netns del "$ns" 2>/dev/null || true
  if [[ -n ${KEEP_WORK:-} ]]; then echo "kept $work"; else rm -rf "$work"; fi
}
trap cleanup EXIT
trap 'exit 130' INT TERM
ip netns del "$ns" 2>/dev/null || true  # left by a run killed before its cleanup (the name recurs with the pid)
ip netns add "$ns"
ip -n "$ns" link set lo up
ip -n "$ns" link set lo multicast on
ip -n "$ns" route add 224.0.0.0/4 dev lo
in_ns() { ip netns exec "$ns" "$@"; }
rx_bytes() { ip -n "$ns" -s -j link show lo | sed -n 's/.*"rx":{"bytes":\([0-9]*\).*/\1/p'; }

env_common=(PIXYSLAM_DDS_DOMAIN=7 PIXYSLAM_DDS_INTERFACES=127.0.0.1)
if [[ $mode == multicast ]]; then
  env_common+=(PIXYSLAM_DDS_PROFILE=lan_multicast)
else
  env_common+=(PIXYSLAM_DDS_PROFILE=discovery_client PIXYSLAM_DDS_SERVER=127.0.0.1:11811)
  ip netns exec "$ns" fastdds discovery -i 0 -l 127.0.0.1 -p 11811 > "$work/server.log" 2>&1 &
  pids+=($!)
  sleep 1
fi
start_bytes=$(rx_bytes)
t0=$(date +%s.%N)
declare -A kind_of
for r in $(seq "$n"); do
  set_robot=(--set "dds.robot_id=robot$r" --set dds.diagnostics_period_s=1)
  ip netns exec "$ns" env "${env_common[@]}" "$bin/encoder_bridge" --config "$root/config/encoder_bridge.yaml" \
    --device "$work/arduino$r" "${set_robot[@]}" --set node.wait_readers=0 > "$work/enc$r.log" 2>&1 &
  pids+=($!); kind_of[$!]=encoder_bridge
  ip netns exec "$ns" env "${env_common[@]}" "$bin/pixy_bridge" --config "$root/config/pixy_bridge.yaml" \
    --device "$work/pixy$r" "${set_robot[@]}" --set node.wait_readers=0 > "$work/pixy$r.log" 2>&1 &
  pids+=($!); kind_of[$!]=pixy_bridge
  ip netns exec "$ns" env "${env_common[@]}" "$bin/slam_estimator" --config "$root/config/slam_estimator.yaml" \
    "${set_robot[@]}" > "$work/est$r.log" 2>&1 &
  pids+=($!); kind_of[$!]=slam_estimator
done
# (ip netns exec and env exec the program: $! is its pid.)
# Matched: the spy sees N writers and N + 0 readers of Odometry (each estimator's reader
# matches every robot's writer; the spy's own participant reads nothing here).
matched_s=""
for _ in $(seq 120); do
  line=$(in_ns env "${env_common[@]}" "$bin/pixyslam_spy" topics --json --duration 1 2>/dev/null |
    grep '"pixyslam/odometry"' || true)
  writers=$(sed -n 's/.*"writers":\([0-9]*\).*/\1/p' <<< "$line")
  readers=$(sed -n 's/.*"readers":\([0-9]*\).*/\1/p' <<< "$line")
  if [[ ${writers:-0} -ge $n && ${readers:-0} -ge $n ]]; then
    matched_s=$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }')
    break
  fi
done
[[ -n $matched_s ]] || { echo "fleet_scale: Odometry writers/readers ${writers:-0}/${readers:-0} of $n after 120 s"; exit 1; }
startup_bytes=$(($(rx_bytes) - start_bytes))
declare -A cpu0
ticks=$(getconf CLK_TCK)
cpu_of() { awk '{print $14 + $15}' "/proc/$1/stat" 2>/dev/null || echo 0; }
warmup_s=0
if ((sim)); then
  # Each robot drives (its bridges open the pseudo-terminals within reopen_period_s); measured
  # over SETTLE_S s while all drive, from WARMUP_S after they started (the sims' own
  # participants discovered, the bridges' devices open), then stopped.
  warmup_s=10
  sims=()
  for r in $(seq "$n"); do
    ip netns exec "$ns" env "${env_common[@]}" "$bin/robot_sim" --config "$root/config/robot_sim.yaml" \
      --duration $((warmup_s + settle + 60)) --arduino-link "$work/arduino$r" --pixy-link "$work/pixy$r" \
      --set "hardware.seed=$r" --set "dds.robot_id=robot$r" > "$work/sim$r.log" 2>&1 &
    pids+=($!); kind_of[$!]=robot_sim; sims+=($!)
  done
  sleep "$warmup_s"
fi
for pid in "${!kind_of[@]}"; do cpu0[$pid]=$(cpu_of "$pid"); done
settle_bytes0=$(rx_bytes)
sleep "$settle"
settle_bytes=$(($(rx_bytes) - settle_bytes0))
participants=$((3 * n))
traffic="discovery + 1 Hz diagnostics"
if ((sim)); then participants=$((4 * n)) traffic="discovery, diagnostics and every robot's sensor data"; fi
echo "fleet_scale: $n robots, $participants participants (+ the spy), $mode discovery, namespace loopback"
echo "  every estimator's Odometry reader matched all $n writers after $matched_s s (spy polls of 1 s)"
echo "  loopback traffic: $((startup_bytes / 1024)) KiB until then, $((settle_bytes / settle / 1024)) KiB/s over ${settle} s from ${warmup_s} s later ($traffic)"
for kind in encoder_bridge pixy_bridge slam_estimator robot_sim; do
  cpu=0 rss=0 count=0
  for pid in "${!kind_of[@]}"; do
    [[ ${kind_of[$pid]} == "$kind" ]] || continue
    c=$(($(cpu_of "$pid") - cpu0[$pid]))
    m=$(awk '/VmHWM/ {print $2}' "/proc/$pid/status" 2>/dev/null || echo 0)
    cpu=$((cpu + c)) rss=$((rss + m)) count=$((count + 1))
  done
  ((count > 0)) || continue
  awk -v k="$kind" -v c="$cpu" -v t="$ticks" -v s="$settle" -v r="$rss" -v n="$count" \
    'BEGIN { printf "  %-15s x%-3d CPU %.2f %% of a core each (steady), peak RSS %.1f MB each\n", k, n, 100 * c / t / s / n, r / n / 1024 }'
done
if ((sim)); then
  # The estimators' input: stop the robots, then the estimators, and read their final lines.
  for pid in "${sims[@]}"; do kill -INT "$pid" 2>/dev/null || true; done
  for pid in "${sims[@]}"; do wait "$pid" 2>/dev/null || true; done
  sleep 1
  for pid in "${!kind_of[@]}"; do [[ ${kind_of[$pid]} == slam_estimator ]] && { kill -INT "$pid" 2>/dev/null || true; }; done
  for pid in "${!kind_of[@]}"; do [[ ${kind_of[$pid]} == slam_estimator ]] && { wait "$pid" 2>/dev/null || true; }; done
  for f in "$work"/est*.log; do grep "slam_estimator: odometry" "$f" | tail -n 1; done | sed -n "s/.*slam_estimator: odometry \([0-9]*\) (lost \([0-9]*\)), observations \([0-9]*\) (lost \([0-9]*\)), other robots' \([0-9]*\), steps \([0-9]*\), late \([0-9]*\).*/\1 \2 \3 \4 \5 \6 \7/p" |
    awk -v n="$n" '
      function span(v, k) { if (!(k in lo) || v < lo[k]) lo[k] = v; if (!(k in hi) || v > hi[k]) hi[k] = v }
      { span($1, "odo"); span($3, "obs"); span($5, "other"); lost += $2 + $4; late += $7; own += $1 + $3; others += $5 }
      END {
        if (NR != n) { printf "  estimators: %d of %d final lines\n", NR, n; exit 1 }
        printf "  each estimator took its own robot: odometry %d-%d, observations %d-%d (lost %d, late %d in all)\n", lo["odo"], hi["odo"], lo["obs"], hi["obs"], lost, late
        printf "  and dropped the other robots%s samples: %d-%d each (%.1f per own sample)\n", "\047", lo["other"], hi["other"], others / own
        if (lo["odo"] == 0 || lo["obs"] == 0 || lost > 0) { print "  FAIL: an estimator got none of its robot%s samples, or lost some", "\047"; exit 1 }
      }' || { echo "fleet_scale: the estimators' input (above) is incomplete"; exit 1; }
fi
