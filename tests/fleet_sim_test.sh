#!/usr/bin/env bash
# ctest fleet_sim_two_robots: config/launch_fleet_sim.yaml with two simulated
# robots (robot_sim.yaml's run cut to SIM_S seconds) on a DDS domain of its own
# (loopback profile). Passes if the launcher and every process end with 0, each
# estimator took exactly its own robot's samples (odometry and observations
# equal to what that robot's bridges published, none lost) and counted exactly
# the other robot's as other robots', each evaluator's ATE is within its
# --max-ate, the log check passed (seq 1..N per robot), and the fleet map and
# its picture hold both robots.
#   fleet_sim_test.sh BIN_DIR CONFIG_DIR [SIM_S]
set -euo pipefail
bin=$1 config=$2 sim_s=${3:-20}
work=$(mktemp -d "${TMPDIR:-/tmp}/pixyslam_fleet_sim.XXXXXX")
trap 'if [[ -n ${KEEP_WORK:-} ]]; then echo "kept $work"; else rm -rf "$work"; fi' EXIT
trap 'exit 130' INT TERM
fail() { echo "FAIL: $*"; exit 1; }
cp -r "$config" "$work/config"
sed -i -E "s/^  duration_s: [0-9.]+ /  duration_s: $sim_s /" "$work/config/robot_sim.yaml"
grep -q "^  duration_s: $sim_s " "$work/config/robot_sim.yaml" || fail "cannot set robot_sim.yaml's duration_s"

status=0
PIXYSLAM_DDS_DOMAIN=$((60 + $$ % 40)) "$bin/pixyslam_launch" "$work/config/launch_fleet_sim.yaml" \
  --run-dir "$work/run" > "$work/launch.log" 2>&1 || status=$?
log=$work/launch.log
grep -E "odometry published|observations published|slam_estimator: odometry|pose ATE RMSE|robots robot|\[log_check\]|exit code" "$log"
[[ $status -eq 0 ]] || fail "pixyslam_launch exited with $status"
if grep -q "<- FAILED" "$log"; then fail "a process failed"; fi
grep -q "check passed" "$log" || fail "the log check"

last() { grep -E "^\[$1\]" "$log" | grep -oE "$2" | tail -n 1 | grep -oE '[0-9]+' | head -n 1; }
declare -A odometry observations
for r in 1 2; do
  odometry[$r]=$(last "encoder_bridge_robot$r" 'odometry published [0-9]+')
  observations[$r]=$(last "pixy_bridge_robot$r" 'observations published [0-9]+')
  [[ ${odometry[$r]:-0} -gt 0 && ${observations[$r]:-0} -gt 0 ]] || fail "robot $r's bridges published nothing"
done
for r in 1 2; do
  other=$((3 - r))
  expect="odometry ${odometry[$r]} (lost 0), observations ${observations[$r]} (lost 0), other robots' $((odometry[$other] + observations[$other])),"
  grep -E "^\[estimator_robot$r\]" "$log" | grep -F "$expect" > /dev/null ||
    fail "estimator robot$r: expected '$expect'"
  echo "estimator robot$r: $expect (as robot $r's and robot $other's bridges published)"
done
"$bin/pixyslam_log" print "$work/run/run.mcap" --topics pixyslam/fleet_map --json > "$work/fleet.json" ||
  fail "print the fleet map"
tail -n 1 "$work/fleet.json" | grep -q '"robot_id":"robot1".*"robot_id":"robot2"' || fail "the fleet map lacks a robot"
grep -q "robots robot1, robot2 -> " "$log" || fail "the fleet picture lacks a robot"
echo PASS
