#!/usr/bin/env bash
# Accuracy on UTIAS MRCLAM (data not in the repo): robots 1-5 of a dataset, seeds
# 1-3, one parameter set. Usage: scripts/eval_mrclam.sh [DATASET_DIR] [extra mrclam_eval args]
# Default dataset: ../shared/data/mrclam/Dataset6 beside the checkout. Skips (exit 0)
# when the folder is absent.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
dataset=${1:-$root/../shared/data/mrclam/Dataset6}
shift || true
if [[ ! -d "$dataset" ]]; then echo "eval_mrclam: $dataset not found, skipping"; exit 0; fi
"$root/scripts/build.sh" >/dev/null
build_dir=${BUILD_DIR:-$root/build}
"$build_dir/bin/mrclam_eval" --dataset "$dataset" --config "$root/config/slam_mrclam.yaml" "$@"
