#!/usr/bin/env bash
# The main job: installs what is missing, builds, and runs the whole system on
# this machine: the simulated robot (robot_sim, writing Arduino and Pixy bytes
# into pseudo-terminals), the encoder and pixy bridges, the SLAM estimator, the
# logger and a live evaluator, all over the loopback-only DDS profile. The run
# ends by itself after two laps (~90 s) and prints the pose and landmark errors,
# messages per topic and where the MCAP log is. Exit code 0 only if every
# process ended cleanly and the ATE is under 0.10 m.
#   scripts/run_demo.sh [--run-dir DIR] [--duration S]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/install_deps.sh"
"$root/scripts/build.sh"
build_dir=${BUILD_DIR:-$root/build}
run_dir="$build_dir/demo_run"
if [[ "${1:-}" == "--run-dir" ]]; then run_dir=$2; shift 2; fi
rm -rf "$run_dir"
exec "$build_dir/bin/pixyslam_launch" "$root/config/launch_sim.yaml" --run-dir "$run_dir" "$@"
