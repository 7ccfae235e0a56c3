#!/usr/bin/env bash
# The main job: installs what is missing, builds, and runs the whole system on
# this machine: the simulated robot (robot_sim, writing Arduino and Pixy bytes
# into pseudo-terminals), the encoder and pixy bridges, the SLAM estimator, the
# logger and a live evaluator, all over the loopback-only DDS profile. The run
# ends by itself after two laps (~90 s) and prints the pose and landmark errors,
# messages per topic and where the MCAP log is. Exit code 0 only if every
# process ended cleanly and the ATE is under 0.13 m (config/launch_sim.yaml says why).
#   scripts/run_demo.sh [--run-dir DIR] [any pixyslam_launch argument, e.g. particles:=300 duration:=30]
# The default run folder build/demo_run is emptied first; a folder given with
# --run-dir DIR (or --run-dir=DIR) must be new or empty.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build_dir=${BUILD_DIR:-$root/build}
run_dir="$build_dir/demo_run"
launch_args=()
while (($#)); do
  case $1 in
    -h | --help)
      sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0"
      exit 0
      ;;
    --run-dir)
      (($# >= 2)) || { echo "run_demo.sh: --run-dir needs a folder" >&2; exit 2; }
      run_dir=$2
      shift 2
      ;;
    --run-dir=*)
      run_dir=${1#--run-dir=}
      shift
      ;;
    *)
      launch_args+=("$1")
      shift
      ;;
  esac
done
if [[ $run_dir != "$build_dir/demo_run" && -d $run_dir && -n $(ls -A "$run_dir") ]]; then
  echo "run_demo.sh: --run-dir $run_dir exists and is not empty (give a new folder)" >&2
  exit 2
fi
"$root/scripts/install_deps.sh"
"$root/scripts/build.sh"
[[ $run_dir != "$build_dir/demo_run" ]] || rm -rf "$run_dir"  # the default folder holds the last demo only
exec "$build_dir/bin/pixyslam_launch" "$root/config/launch_sim.yaml" --run-dir "$run_dir" "${launch_args[@]}"
