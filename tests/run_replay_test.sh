#!/usr/bin/env bash
# Replays a recorded run's odometry and camera frames (pixyslam_play) through
# a fresh estimator with the same config and seed (config/launch_replay.yaml,
# on a DDS domain of its own) and passes only if every recorded MapState is
# reproduced exactly (`pixyslam_log compare`: all fields but samples_late and the stamps'
# clock and the step's CPU time).
#   run_replay_test.sh BIN_DIR CONFIG_DIR LOG.mcap
set -euo pipefail
bin=$1 config=$2 log=$3
work=$(mktemp -d /tmp/pixyslam_replay_test.XXXXXX)
trap 'rm -rf "$work"' EXIT
trap 'exit 130' INT TERM  # a killed test still cleans up (the EXIT trap)
cp -r "$config" "$work/config"
domain=$((20 + $$ % 100))
sed -i "s/^  domain_id: 0/  domain_id: $domain/" "$work"/config/*.yaml
# The player, delayed on a busy host, can hold a sample back longer than the
# live bridges did (CI: odometry 0.054 s late at 13.7 s; in a later run a frame
# late beyond the camera's 0.05 s wait, between 10 and 20 s).
source "$(dirname "${BASH_SOURCE[0]}")/support/estimator_waits.sh"
estimator_waits_for_both_streams "$work/config"

status=0
read -r -a launch_args <<< "${LAUNCH_ARGS:-}"  # as the recorded run had them
"$bin/pixyslam_launch" "$work/config/launch_replay.yaml" --input "$log" "${launch_args[@]}" --run-dir "$work/run" \
  > "$work/out.log" 2>&1 || status=$?
grep -v "status: " "$work/out.log"
if [[ $status -ne 0 ]]; then
  echo "FAIL: pixyslam_launch exited with $status"
  exit 1
fi
grep -q "\[compare_maps\] SAME" "$work/out.log" || { echo "FAIL: no SAME from compare"; exit 1; }
echo "PASS"
