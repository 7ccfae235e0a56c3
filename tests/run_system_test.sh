#!/usr/bin/env bash
# Integration test of the whole system on loopback: robot_sim, both bridges,
# the estimator, the map optimiser, the logger and the evaluator started by pixyslam_launch from
# a copy of config/ on a DDS domain of its own. Passes if every process ends
# cleanly, the evaluator's ATE is under MAX_ATE (so MapState arrived and the
# map is near the truth), and the log holds every message each publisher sent
# (seq 1..N per topic, N = the publisher's own count).
# The log is kept as KEEP_LOG when given (for the replay test; the estimator
# then waits up to 1 s for either stream, as the replayed one does). LAUNCH names
# another launch file of CONFIG_DIR (launch_sim_camera.yaml: the camera backend
# on robot_sim's rendered images); with it 3/4 of the poles must be mapped, none
# under a wrong id. LAUNCH_ARGS are launch arguments (e.g. "particles:=150
# seed:=2"): the estimator must report running with them.
#   [LAUNCH=FILE] [LAUNCH_ARGS=...] run_system_test.sh BIN_DIR CONFIG_DIR SIM_DURATION_S MAX_ATE_M [KEEP_LOG]
set -euo pipefail
bin=$1 config=$2 duration=$3 max_ate=$4 keep_log=${5:-}
launch=${LAUNCH:-launch_sim.yaml}
read -r -a launch_args <<< "${LAUNCH_ARGS:-}"
work=$(mktemp -d /tmp/pixyslam_system_test.XXXXXX)
trap 'rm -rf "$work"' EXIT
cp -r "$config" "$work/config"
domain=$((120 + $$ % 100))
sed -i "s/^  domain_id: 0/  domain_id: $domain/" "$work"/config/*.yaml
sed -i "s/^  duration_s: [0-9.]* /  duration_s: $duration /" "$work/config/robot_sim.yaml"
sed -i -E "s/--max-ate, '[0-9.]+'/--max-ate, '$max_ate'/" "$work/config/$launch"
if [[ -n "$keep_log" ]]; then
  # The recording the replay test must reproduce, made with the waits the
  # replayed estimator has (CI 2026-11-28: two samples late at 21 s of 44).
  source "$(dirname "${BASH_SOURCE[0]}")/support/estimator_waits.sh"
  estimator_waits_for_both_streams "$work/config"
fi

status=0
"$bin/pixyslam_launch" "$work/config/$launch" "${launch_args[@]}" --run-dir "$work/run" > "$work/out.log" 2>&1 &
launcher=$!
trap 'kill "$launcher" 2>/dev/null || true; wait 2>/dev/null || true; rm -rf "$work"' EXIT
trap 'exit 130' INT TERM  # a killed test still cleans up (the EXIT trap)
# pixyslam_spy echo of every topic while the system runs: 20 samples each.
topics=(odometry landmark_observation map_state ground_truth)
sleep 8
echoes=()
for t in "${topics[@]}"; do
  "$bin/pixyslam_spy" echo "pixyslam/$t" --json --count 20 --duration 20 \
    --config "$work/config/slam_estimator.yaml" > "$work/echo_$t.jsonl" 2> "$work/echo_$t.err" &
  echoes+=($!)
done
trap 'kill "$launcher" "${echoes[@]}" 2>/dev/null || true; wait 2>/dev/null || true; rm -rf "$work"' EXIT
for pid in "${echoes[@]}"; do wait "$pid" || { echo "FAIL: pixyslam_spy echo failed"; cat "$work"/echo_*.err; exit 1; }; done
wait "$launcher" || status=$?
grep -v "robot_sim: t \|status: " "$work/out.log"
if [[ $status -ne 0 ]]; then
  echo "FAIL: pixyslam_launch exited with $status"
  exit 1
fi

# The launch arguments reached the estimator (particles:=N, seed:=S).
for a in "${launch_args[@]}"; do
  case $a in
    particles:=*) grep -qE "slam_estimator: ${a#particles:=} particles," "$work/out.log" ||
                    { echo "FAIL: the estimator did not run with $a"; exit 1; } ;;
    seed:=*) grep -qE "slam_estimator: [0-9]+ particles, seed ${a#seed:=}," "$work/out.log" ||
               { echo "FAIL: the estimator did not run with $a"; exit 1; } ;;
  esac
done

# The map optimiser ran beside the filter: its solutions reached the evaluator,
# which scored the newest against the truth.
if grep -q "name: map_optimizer" "$work/config/$launch"; then
  grep -E "map optimiser +[0-9]+ solutions" "$work/out.log" ||
    { echo "FAIL: no OptimisedMap reached the evaluator"; exit 1; }
  # --out-dir: every keyframe of the final solution (not the topic's thinned list).
  keyframes=$(grep -oE 'keyframes [0-9]+ \(in the problem [0-9]+' "$work/out.log" | tail -1 | grep -oE '[0-9]+$' || true)
  rows=$(($(wc -l < "$work/run/optimised/trajectory.csv") - 1))
  if [[ -z "$keyframes" || "$rows" -ne "$keyframes" ]]; then
    echo "FAIL: the map optimiser's trajectory.csv has $rows rows, its problem ${keyframes:-?} keyframes"; exit 1
  fi
  echo "map optimiser trajectory.csv: $rows keyframes"
fi

if [[ $launch != launch_sim.yaml ]]; then
  # Most poles mapped in one lap, and none under a wrong id (one would be metres
  # off its pole and lift the raw landmark RMSE far above 0.15 m).
  mapped=$(grep -oE 'landmarks +[0-9]+ mapped of [0-9]+, RMSE [0-9.]+' "$work/out.log" | tail -1)
  read -r got of rmse <<< "$(echo "$mapped" | grep -oE '[0-9.]+' | tr '\n' ' ')"
  if [[ -z "$mapped" || $((4 * got)) -lt $((3 * of)) ]] || awk "BEGIN{exit !($rmse > 0.15)}"; then
    echo "FAIL: landmarks: $mapped (want >= 3/4 of the poles, raw RMSE <= 0.15 m)"; exit 1
  fi
  echo "landmarks: $mapped m raw"
fi

# What each publisher says it sent (its final status line).
count() { grep -oE "$1" "$work/out.log" | tail -1 | grep -oE '[0-9]+' | head -1; }
odometry=$(count 'odometry published [0-9]+')
observations=$(count 'observations published [0-9]+')
truth=$(count '[0-9]+ ground truth messages')
maps=$(grep -E '\[slam_estimator\].*steps [0-9]+' "$work/out.log" | tail -1 | grep -oE 'steps [0-9]+' | grep -oE '[0-9]+')
echo "publishers: odometry $odometry, observations $observations, map states $maps, ground truth $truth"
for n in "$odometry" "$observations" "$truth" "$maps"; do
  if [[ -z "$n" || "$n" -eq 0 ]]; then echo "FAIL: a publisher count is missing or zero"; exit 1; fi
done
"$bin/pixyslam_log" check "$work/run/run.mcap" \
  --expect "pixyslam/odometry=$odometry" --expect "pixyslam/landmark_observation=$observations" \
  --expect "pixyslam/map_state=$maps" --expect "pixyslam/ground_truth=$truth"
# Every echoed sample is, field for field, a message the publisher sent (the
# log holds exactly what each publisher sent: checked above).
for t in "${topics[@]}"; do
  "$bin/pixyslam_log" print "$work/run/run.mcap" --topics "pixyslam/$t" --json > "$work/log_$t.jsonl"
  lines=$(wc -l < "$work/echo_$t.jsonl")
  if [[ $lines -ne 20 ]]; then echo "FAIL: echo pixyslam/$t printed $lines samples, wanted 20"; exit 1; fi
  while IFS= read -r line; do
    grep -qF "\"message\":$line}" "$work/log_$t.jsonl" ||
      { echo "FAIL: echo pixyslam/$t printed a sample no publisher sent: $line"; exit 1; }
  done < "$work/echo_$t.jsonl"
  echo "echo pixyslam/$t: 20 samples, each equal to a published one (e.g. $(head -c 100 "$work/echo_$t.jsonl")...)"
done
if [[ -n "$keep_log" ]]; then cp "$work/run/run.mcap" "$keep_log"; fi
echo "PASS"
