#!/usr/bin/env bash
# Compares a launch_mrclam.yaml run with slam_offline mrclam on the same data,
# seed and cut, robot by robot: the live evaluator's ATE (from the launcher's
# output) equals the offline runner's within 1.5 mm, and RUN_DIR/robotN/
# trajectory.csv has the offline runner's steps, every position within
# MAX_DIFF_M (the live stamps are integer nanoseconds, the offline times unix
# seconds in doubles: not bit-identical). Prints the figures; exit 1 and a
# line saying what differs when they do not match.
#   live_vs_offline.sh BIN_DIR CONFIG_DIR DATASET_DIR RUN_DIR LAUNCH_LOG ROBOTS SEED [DURATION_S] [MAX_DIFF_M]
set -euo pipefail
bin=$1 config=$2 dataset=$3 run=$4 launch_log=$5 robots=$6 seed=$7 duration=${8:-0} max_diff=${9:-0.001}
work=$(mktemp -d "${TMPDIR:-/tmp}/pixyslam_live_vs_offline.XXXXXX")
trap 'rm -rf "$work"' EXIT
cut=()
if [[ $duration != 0 ]]; then cut=(--duration "$duration"); fi
for r in ${robots//,/ }; do
  "$bin/slam_offline" mrclam --config "$config/slam_mrclam.yaml" --dataset "$dataset" --robot "$r" --seed "$seed" \
    "${cut[@]}" --out-dir "$work/offline$r" > "$work/offline$r.log" 2>&1 ||
    { tail -n 5 "$work/offline$r.log"; echo "FAIL: slam_offline robot $r"; exit 1; }
  grep "pose ATE RMSE" "$work/offline$r.log" | sed "s/^/offline robot $r: /"
  # The live evaluator scored the same estimates (every MapState reached it) as the offline runner.
  live_ate=$(sed -n "s/^\[evaluator_robot$r\] *pose ATE RMSE *\([0-9.]*\) m.*/\1/p" "$launch_log" | tail -n 1)
  offline_ate=$(sed -n 's/^pose ATE RMSE *\([0-9.]*\) m.*/\1/p' "$work/offline$r.log")
  awk -v a="$live_ate" -v b="$offline_ate" 'BEGIN { exit !(a != "" && b != "" && a - b < 0.0015 && b - a < 0.0015) }' ||
    { echo "FAIL: robot $r: live evaluator ATE '$live_ate' m, offline '$offline_ate' m"; exit 1; }
  # Step by step: the same number of steps, the largest position difference.
  paste -d, "$run/robot$r/trajectory.csv" "$work/offline$r/trajectory.csv" | awk -F, -v r="$r" -v max="$max_diff" '
    NR == 1 { next }
    $1 == "" || $5 == "" { uneven = 1; next }
    { n++; d = sqrt(($2 - $6) ^ 2 + ($3 - $7) ^ 2); if (d > worst) worst = d }
    END {
      printf "robot %s: %d steps, largest position difference live vs offline %.4f m\n", r, n, worst
      if (uneven || n == 0 || worst > max) exit 1
    }' || { echo "FAIL: robot $r: live and offline differ (steps or more than $max_diff m)"; exit 1; }
done
