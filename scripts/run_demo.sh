#!/usr/bin/env bash
# The main job: installs what is missing, builds, and runs a full SLAM run on the
# built-in simulated robot. Output: build/demo/{trajectory,landmarks}.csv.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/install_deps.sh"
"$root/scripts/build.sh"
build_dir=${BUILD_DIR:-$root/build}
"$build_dir/bin/slam_offline" sim --config "$root/config/slam_sim.yaml" --out "$build_dir/demo"
