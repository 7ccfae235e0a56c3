#!/usr/bin/env bash
# Accuracy on UTIAS MRCLAM (data not in the repo): robots 1-5 of a dataset, seeds
# 1-3, one parameter set. Usage: scripts/eval_mrclam.sh [DATASET_DIR] [extra mrclam_eval args]
# Default dataset: ../shared/data/mrclam/Dataset6 beside the checkout. Skips (exit 0)
# when that default folder is absent; a DATASET_DIR given that does not exist exits 1.
# The extra arguments: build/bin/mrclam_eval --help lists them.
set -euo pipefail
case ${1:-} in -h | --help) sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0"; exit 0 ;; esac
root=$(cd "$(dirname "$0")/.." && pwd)
dataset=$root/../shared/data/mrclam/Dataset6
if [[ $# -gt 0 && $1 != -* ]]; then
  dataset=$1
  shift
  if [[ ! -d "$dataset" ]]; then echo "eval_mrclam: data set folder $dataset not found" >&2; exit 1; fi
fi
if [[ ! -d "$dataset" ]]; then echo "eval_mrclam: $dataset not found, skipping"; exit 0; fi
"$root/scripts/build.sh" >/dev/null
build_dir=${BUILD_DIR:-$root/build}
"$build_dir/bin/mrclam_eval" --dataset "$dataset" --config "$root/config/slam_mrclam.yaml" "$@"
