#!/usr/bin/env bash
# Sourced by the tests that compare a recorded run with its replay.
# estimator_waits_for_both_streams CONFIG_DIR: the estimator of that config copy
# waits up to 1 s for either stream (odometry_max_delay_s and
# observation_max_delay_s; 0.3 and 0.05 s live). A busy host otherwise makes a
# live estimator or a replayed one take a sample late, and the states after it
# differ. Waiting changes nothing else: every sample is still taken in stamp order.
estimator_waits_for_both_streams() {
  local file=$1/slam_estimator.yaml key
  for key in odometry_max_delay_s observation_max_delay_s; do
    sed -i -E "s/^  $key: [0-9.]+ /  $key: 1.0 /" "$file"
    grep -q "^  $key: 1.0 " "$file" || { echo "FAIL: $key not set in $file"; return 1; }
  done
}
