#!/usr/bin/env bash
# ctest mrclam_fleet_dataset6: the first DURATION seconds of Dataset6's robots 1
# and 2 through the live system (config/launch_mrclam.yaml at rate 0: the
# dataset bridge, two estimators, two evaluators, fleet_map and the logger on a
# DDS domain of its own), against slam_offline mrclam on the same cut and seed.
# Passes if each robot's live trajectory has the offline runner's steps and
# stays within MAX_DIFF_M of it (the live stamps are integer nanoseconds from an
# epoch, the offline times unix seconds in doubles: not bit-identical), each
# live evaluator's ATE equals the offline runner's, no message was lost, and
# the fleet map fused both robots. Skips (77) without the
# data set (../shared is not part of a clone).
#   mrclam_fleet_test.sh BIN_DIR CONFIG_DIR DATASET_DIR [DURATION_S] [MAX_DIFF_M]
set -euo pipefail
bin=$1 config=$2 dataset=$3 duration=${4:-60} max_diff=${5:-0.001}
if [[ ! -f $dataset/Robot1_Odometry.dat ]]; then
  echo "SKIP: no MRCLAM data set at $dataset"
  exit 77
fi
work=$(mktemp -d "${TMPDIR:-/tmp}/pixyslam_mrclam_fleet.XXXXXX")
trap 'rm -rf "$work"' EXIT
trap 'exit 130' INT TERM
fail() { echo "FAIL: $*"; tail -n 40 "$work/launch.log" 2>/dev/null; exit 1; }
domain=$((20 + $$ % 40))

PIXYSLAM_DDS_DOMAIN=$domain "$bin/pixyslam_launch" "$config/launch_mrclam.yaml" --input "$dataset" \
  --run-dir "$work/run" robots:=1,2 rate:=0 "recording_s:=$duration" seed:=1 > "$work/launch.log" 2>&1 ||
  fail "pixyslam_launch: exit $?"
grep -E "dataset_bridge: published|pose ATE RMSE|landmarks +[0-9]+ mapped|received, [0-9]+ lost|OK   pixyslam/(odometry|fleet_map)|fleet_map:|summary|exit code" \
  "$work/launch.log" | grep -v "status" | head -n 60
if grep -E "received, [1-9][0-9]* lost" "$work/launch.log"; then fail "messages lost"; fi
grep -q "check passed" "$work/launch.log" || fail "the log check"

for r in 1 2; do
  "$bin/slam_offline" mrclam --config "$config/slam_mrclam.yaml" --dataset "$dataset" --robot "$r" --seed 1 \
    --duration "$duration" --out-dir "$work/offline$r" > "$work/offline$r.log" 2>&1 || fail "slam_offline robot $r"
  grep "pose ATE RMSE" "$work/offline$r.log" | sed "s/^/offline robot $r: /"
  # The live evaluator scored the same estimates (every MapState reached it) as the offline runner.
  live_ate=$(sed -n "s/^\[evaluator_robot$r\] *pose ATE RMSE *\([0-9.]*\) m.*/\1/p" "$work/launch.log")
  offline_ate=$(sed -n 's/^pose ATE RMSE *\([0-9.]*\) m.*/\1/p' "$work/offline$r.log")
  awk -v a="$live_ate" -v b="$offline_ate" 'BEGIN { exit !(a != "" && b != "" && a - b < 0.0015 && b - a < 0.0015) }' ||
    fail "robot $r: live evaluator ATE '$live_ate' m, offline '$offline_ate' m"
  # Step by step: the same number of steps, the largest position difference.
  paste -d, "$work/run/robot$r/trajectory.csv" "$work/offline$r/trajectory.csv" | awk -F, -v r="$r" -v max="$max_diff" '
    NR == 1 { next }
    $1 == "" || $5 == "" { uneven = 1; next }
    { n++; d = sqrt(($2 - $6) ^ 2 + ($3 - $7) ^ 2); if (d > worst) worst = d }
    END {
      printf "robot %s: %d steps, largest position difference live vs offline %.4f m\n", r, n, worst
      if (uneven || n == 0 || worst > max) exit 1
    }' || fail "robot $r: live and offline differ (steps or more than $max_diff m)"
done

"$bin/pixyslam_log" print "$work/run/run.mcap" --topic pixyslam/fleet_map --json > "$work/fleet.json" ||
  fail "print the fleet map"
tail -n 1 "$work/fleet.json" | grep -q '"robot_id":"robot1".*"robot_id":"robot2"' || fail "the fleet map lacks a robot"
echo PASS
