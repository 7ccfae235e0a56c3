#!/usr/bin/env bash
# The new-robot workflow on Dataset6 (issue 16 item 3): every robot calibrated
# blind by `pixyslam_calibrate noise` from config/slam_new_robot.yaml (the
# values docs/calibration.md recommends writing: w_sigma, odometry_delay,
# range_exponent), then scored by mrclam_eval over seeds 1-3; passes if the
# mean ATE of the calibrated configs is within 10 % of config/slam_mrclam.yaml's
# (fitted with the ground truth). Exit 77 without the dataset.
#   mrclam_new_robot_test.sh BIN_DIR CONFIG_DIR DATASET_DIR
set -euo pipefail
bin=$1 config=$2 dataset=$3
if [[ ! -d $dataset ]]; then
  echo "SKIP: $dataset not found"
  exit 77
fi
work=$(mktemp -d /tmp/pixyslam_new_robot_test.XXXXXX)
trap 'rm -rf "$work"' EXIT
trap 'exit 130' INT TERM

mean_ate() {  # the ATE column of mrclam_eval's per-run rows
  awk '$1 ~ /^[1-5]$/ && $2 ~ /^[0-9]+$/ {s += $3; n++} END {if (n == 0) exit 1; printf "%.4f %d\n", s / n, n}'
}
calibrated_rows=""
for robot in 1 2 3 4 5; do
  "$bin/pixyslam_calibrate" noise --dataset "$dataset" --robot "$robot" --config "$config/slam_new_robot.yaml" \
    --out "$work/robot$robot.yaml" --keys w_sigma,odometry_delay,range_exponent > "$work/calibrate$robot.log"
  grep "^calibrated" "$work/calibrate$robot.log"
  calibrated_rows+=$("$bin/mrclam_eval" --dataset "$dataset" --config "$work/robot$robot.yaml" --robots "$robot" \
    --seeds 1,2,3 | grep -E "^$robot +[0-9]+ ")$'\n'
done
read -r calibrated runs < <(printf '%s' "$calibrated_rows" | mean_ate)
read -r fitted fitted_runs < <("$bin/mrclam_eval" --dataset "$dataset" --config "$config/slam_mrclam.yaml" --seeds 1,2,3 | mean_ate)
read -r neutral neutral_runs < <("$bin/mrclam_eval" --dataset "$dataset" --config "$config/slam_new_robot.yaml" --seeds 1,2,3 | mean_ate)
echo "mean ATE over $runs runs: calibrated blind $calibrated m, slam_mrclam.yaml $fitted m ($fitted_runs runs), slam_new_robot.yaml $neutral m ($neutral_runs runs)"
if awk -v c="$calibrated" -v f="$fitted" 'BEGIN {exit !(c <= 1.1 * f)}'; then
  echo "PASS: calibrated within 10 % of slam_mrclam.yaml"
else
  echo "FAIL: calibrated $calibrated m above 1.1 x slam_mrclam.yaml's $fitted m"
  exit 1
fi
