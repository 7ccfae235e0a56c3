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
  "$work/launch.log" | grep -v "status" | sed -n '1,60p' # reads it all: no SIGPIPE under pipefail
if grep -E "received, [1-9][0-9]* lost" "$work/launch.log"; then fail "messages lost"; fi
grep -q "check passed" "$work/launch.log" || fail "the log check"
# The bridge saw its readers (the logger, each robot's estimator and evaluator) without its time-out.
if grep "fewer than" "$work/launch.log"; then fail "the dataset bridge started before all its readers matched"; fi

"$(dirname "$0")/support/live_vs_offline.sh" "$bin" "$config" "$dataset" "$work/run" "$work/launch.log" 1,2 1 \
  "$duration" "$max_diff" || fail "live and offline differ"

"$bin/pixyslam_log" print "$work/run/run.mcap" --topics pixyslam/fleet_map --json > "$work/fleet.json" ||
  fail "print the fleet map"
tail -n 1 "$work/fleet.json" | grep -q '"robot_id":"robot1".*"robot_id":"robot2"' || fail "the fleet map lacks a robot"
echo PASS
