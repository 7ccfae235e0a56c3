#!/usr/bin/env bash
# ctest dataset_bridge_two_robots: a made-up two-robot MRCLAM data set (robot 1:
# 100 odometry rows, 10 landmark frames, 3 sightings of robot 2; robot 2: 80,
# 8, 0; ground truth beside the odometry) published by dataset_bridge at rate 0
# (as fast as acknowledged) on a DDS domain of its own, with two estimators
# (dds.robot_id robot1 and robot2) and `pixyslam_log record` listening. Passes
# if the recording holds every sample once, seq 1..N per robot and topic, and
# each estimator took exactly its own robot's samples and counted the other's,
# and `pixyslam_log hz --robot-id robot2` counted robot 2's 80 odometry samples only
# (the bridge waits for it: a second recorder on the other topics gives each
# topic four readers, and records just those two topics);
# the recording's robot sightings print, fleet_map fused both robots' maps,
# and map_view draws both robots.
#   dataset_bridge_test.sh BIN_DIR CONFIG_DIR
set -euo pipefail
bin=$1 config=$2
domain=$((140 + $$ % 40))
work=$(mktemp -d "${TMPDIR:-/tmp}/pixyslam_dataset_bridge.XXXXXX")
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill -INT "$pid" 2>/dev/null || true; done
  sleep 0.3
  for pid in "${pids[@]}"; do kill -KILL "$pid" 2>/dev/null || true; done
  wait 2>/dev/null || true
  if [[ -n ${KEEP_WORK:-} ]]; then echo "kept $work"; else rm -rf "$work"; fi
}
trap cleanup EXIT
trap 'exit 130' INT TERM
fail() { echo "FAIL: $*"; for f in "$work"/*.log; do echo "== $f"; tail -n 15 "$f"; done; exit 1; }

data=$work/Dataset
"$(dirname "$0")/support/make_mrclam_dataset.sh" "$data"

"$bin/pixyslam_log" record --out "$work/run.mcap" --domain "$domain" > "$work/record.log" 2>&1 &
record_pid=$!
pids+=("$record_pid")
for r in 1 2; do
  "$bin/slam_estimator" --config "$config/slam_estimator_mrclam.yaml" --domain "$domain" \
    --set dds.robot_id=robot$r > "$work/estimator$r.log" 2>&1 &
  pids+=("$!")
  eval "estimator${r}_pid=$!"
done
# The fleet map of both estimators' maps.
"$bin/fleet_map" --config "$config/fleet_map.yaml" --domain "$domain" --set fleet_map.period_s=0.2 \
  > "$work/fleet_map.log" 2>&1 &
fleet_pid=$!
pids+=("$fleet_pid")
# `hz --robot-id`: robot 2's odometry only. The bridge waits for it too: a
# second recorder on the other two topics makes every topic's reader count 4
# (its own robot_id, so that its diagnostics are not taken for the first's).
"$bin/pixyslam_log" record pixyslam/landmark_observation pixyslam/ground_truth --out "$work/others.mcap" \
  --set dds.robot_id=second_logger \
  --domain "$domain" > "$work/record_others.log" 2>&1 &
others_pid=$!
pids+=("$others_pid")
# hz listens until it is interrupted after the bridge (which waits for every
# reader's acknowledgement): a fixed window could close before a slow start ends.
"$bin/pixyslam_log" hz pixyslam/odometry --robot-id robot2 --duration 600 --json --domain "$domain" \
  > "$work/hz.out" 2> "$work/hz.log" &
hz_pid=$!
pids+=("$hz_pid")
sleep 1
# Readers per topic: the recorder, and hz (odometry) or the second recorder
# (observations, ground truth), and per robot its estimator.
"$bin/dataset_bridge" --config "$config/dataset_bridge.yaml" --dataset "$data" --robots 1,2 --rate 0 \
  --domain "$domain" --set dataset_bridge.wait_readers=2 --set dataset_bridge.wait_readers_per_robot=1 \
  > "$work/bridge.log" 2>&1 || fail "dataset_bridge: exit $?"
cat "$work/bridge.log"
if grep -q "fewer than" "$work/bridge.log"; then fail "the bridge did not see its 4 readers per topic"; fi
grep -q "published 180 odometry, 18 observations, 180 ground truth, 3 robot sightings" "$work/bridge.log" ||
  fail "bridge counts"

sleep 0.5
kill -INT "$hz_pid" 2>/dev/null || true
wait "$hz_pid" || fail "pixyslam_log hz --robot-id robot2: exit $?"
tail -n 1 "$work/hz.out"
tail -n 1 "$work/hz.out" | grep -q '"messages":80,' || fail "hz --robot-id robot2 did not count robot 2's 80 odometry samples"

for r in 1 2; do
  pid_var=estimator${r}_pid
  kill -INT "${!pid_var}" 2>/dev/null || true
  wait "${!pid_var}" || fail "slam_estimator robot$r: exit $?"
done
kill -INT "$fleet_pid" 2>/dev/null || true
wait "$fleet_pid" || fail "fleet_map: exit $?"
kill -INT "$record_pid" "$others_pid" 2>/dev/null || true
wait "$record_pid" || fail "pixyslam_log record: exit $?"
wait "$others_pid" || fail "pixyslam_log record (two topics): exit $?"
grep "slam_estimator: odometry" "$work/estimator1.log" "$work/estimator2.log"
# Each estimator: its own robot's samples, none lost; the other robot's counted.
grep -q "odometry 100 (lost 0), observations 10 (lost 0), other robots' 88," "$work/estimator1.log" ||
  fail "estimator robot1 did not take exactly robot 1's samples"
grep -q "odometry 80 (lost 0), observations 8 (lost 0), other robots' 110," "$work/estimator2.log" ||
  fail "estimator robot2 did not take exactly robot 2's samples"

"$bin/pixyslam_log" check "$work/run.mcap" --expect pixyslam/odometry=180 \
  --expect pixyslam/landmark_observation=18 --expect pixyslam/ground_truth=180 --expect pixyslam/robot_sighting=3 \
  > "$work/check.log" 2>&1 ||
  fail "log check"
cat "$work/check.log"
grep -q "robot1: seq 1..100, robot2: seq 1..80" "$work/check.log" || fail "odometry seq per robot"
# The second recorder: its two topics, every sample, nothing else.
"$bin/pixyslam_log" check "$work/others.mcap" --expect pixyslam/landmark_observation=18 \
  --expect pixyslam/ground_truth=180 > "$work/check_others.log" 2>&1 || fail "log check (two topics)"
if grep -q "pixyslam/odometry" "$work/check_others.log"; then fail "the two-topic recording holds odometry"; fi
# Robot 1's sightings of robot 2, as written.
"$bin/pixyslam_log" print "$work/run.mcap" --topics pixyslam/robot_sighting --json > "$work/sightings.json" ||
  fail "print sightings"
head -n 1 "$work/sightings.json"
[[ $(grep -c '"seen_robot_id":"robot2"' "$work/sightings.json") == 3 ]] || fail "sightings of robot2"
# The fleet map: the one landmark both robots mapped, fused from both.
"$bin/pixyslam_log" print "$work/run.mcap" --topics pixyslam/fleet_map --json > "$work/fleet.json" || fail "print fleet"
tail -n 1 "$work/fleet.json" | cut -c1-300
tail -n 1 "$work/fleet.json" | grep -q '"landmark_id":6,.*"robots":2}' || fail "fleet map did not fuse both robots"
tail -n 1 "$work/fleet.json" | grep -q '"robot_id":"robot1".*"robot_id":"robot2"' || fail "fleet map robots"
# Both robots in one picture (map_view is built whenever OpenCV is there).
if [[ -x $bin/map_view ]]; then
  "$bin/map_view" render "$work/run.mcap" --out "$work/map.png" > "$work/render.log" 2>&1 || fail "map_view render"
  cat "$work/render.log"
  grep -q "; robots robot1, robot2 -> " "$work/render.log" || fail "map_view did not draw both robots"
fi
echo PASS
