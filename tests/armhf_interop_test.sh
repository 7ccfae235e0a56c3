#!/usr/bin/env bash
# An armhf process among native ones: the simulated robot, both bridges, the
# logger and the evaluator run natively; the SLAM estimator is the armhf build
# (scripts/cross_build_armhf.sh) under qemu-arm-static. They talk over UDP on
# loopback (the default profile: no shared memory, no multicast). Passes if
# the run ends cleanly with the evaluator's ATE under MAX_ATE (the armhf
# estimator got every input and its MapStates arrived) and the log holds every
# MapState the armhf estimator published. Skips (77) without the armhf build.
#   armhf_interop_test.sh BIN_DIR CONFIG_DIR ARMHF_BUILD_DIR SIM_DURATION_S MAX_ATE_M
set -euo pipefail
bin=$1 config=$2 armhf_build=$3 duration=$4 max_ate=$5
cache="$armhf_build/CMakeCache.txt"
if [[ ! -x $armhf_build/bin/slam_estimator || ! -f $cache ]] || ! command -v qemu-arm-static > /dev/null; then
  echo "SKIP: no armhf build in $armhf_build (scripts/cross_build_armhf.sh) or no qemu-arm-static"
  exit 77
fi
sysroot=$(sed -n 's/^PIXYSLAM_ARMHF_SYSROOT:PATH=//p' "$cache")
shim=$armhf_build/bin/libpixyslam_qemu_multicast_if_shim.so  # qemu-user cannot do IP_MULTICAST_IF
work=$(mktemp -d /tmp/pixyslam_armhf_test.XXXXXX)
trap 'rm -rf "$work"' EXIT
trap 'exit 130' INT TERM  # a killed test still cleans up (the EXIT trap)
cp -r "$config" "$work/config"
domain=$((60 + $$ % 100))
sed -i "s/^  domain_id: 0/  domain_id: $domain/" "$work"/config/*.yaml
sed -i "s/^  duration_s: [0-9.]* /  duration_s: $duration /" "$work/config/robot_sim.yaml"
sed -i -E "s/--max-ate, '[0-9.]+'/--max-ate, '$max_ate'/" "$work/config/launch_sim.yaml"
sed -i "s#command: \[slam_estimator, #command: [qemu-arm-static, -L, '$sysroot', -E, 'LD_PRELOAD=$shim', '$armhf_build/bin/slam_estimator', #" \
  "$work/config/launch_sim.yaml"
grep -q "qemu-arm-static" "$work/config/launch_sim.yaml" || { echo "FAIL: could not put the armhf estimator in"; exit 1; }

status=0
"$bin/pixyslam_launch" "$work/config/launch_sim.yaml" --run-dir "$work/run" > "$work/out.log" 2>&1 || status=$?
grep -v "robot_sim: t \|status: \|^\[map_view\]   " "$work/out.log"
[[ $status -eq 0 ]] || { echo "FAIL: pixyslam_launch exited with $status"; exit 1; }
file "$armhf_build/bin/slam_estimator" | grep -q "ARM" || { echo "FAIL: the estimator is not an ARM program"; exit 1; }
steps=$(grep -E '\[slam_estimator\].*steps [0-9]+' "$work/out.log" | tail -1 | grep -oE 'steps [0-9]+' | grep -oE '[0-9]+')
[[ -n $steps && $steps -gt 0 ]] || { echo "FAIL: the armhf estimator made no step"; exit 1; }
"$bin/pixyslam_log" check "$work/run/run.mcap" --expect "pixyslam/map_state=$steps"
echo "PASS: armhf slam_estimator under qemu, $steps MapStates to native readers"
