#!/usr/bin/env bash
# A made-up two-robot data set in MRCLAM's file layout, for tests that must run
# without ../shared: robot 1 drives 100 odometry rows (10 s at 10 Hz, 0.2 m/s,
# 0.1 rad/s) with 10 camera frames of landmark 6 and 3 sightings of robot 2;
# robot 2 drives 80 rows with 8 frames and no sightings; ground truth beside
# the odometry; two surveyed landmarks (6, 7).
#   tests/support/make_mrclam_dataset.sh DIR
set -euo pipefail
data=${1:?usage: make_mrclam_dataset.sh DIR}
mkdir -p "$data"
printf '# Subject #\tBarcode #\n1\t11\n2\t12\n3\t13\n4\t14\n5\t15\n6\t16\n7\t17\n' > "$data/Barcodes.dat"
printf '# Subject\tx\ty\tsx\tsy\n6\t2.0\t1.0\t0\t0\n7\t-1.0\t2.0\t0\t0\n' > "$data/Landmark_Groundtruth.dat"
make_robot() {  # ROBOT ODOMETRY_ROWS FRAMES SIGHTINGS
  local r=$1 rows=$2 frames=$3 sightings=$4
  awk -v n="$rows" 'BEGIN { print "# t v w"; for (i = 0; i < n; ++i) printf "%.3f\t0.2\t0.1\n", 1000 + 0.1 * i }' \
    > "$data/Robot${r}_Odometry.dat"
  awk -v n="$rows" 'BEGIN { print "# t x y th"; for (i = 0; i < n; ++i) printf "%.3f\t%.4f\t0.0\t%.4f\n", 1000 + 0.1 * i, 0.02 * i, 0.01 * i }' \
    > "$data/Robot${r}_Groundtruth.dat"
  awk -v f="$frames" -v s="$sightings" 'BEGIN { print "# t barcode range bearing";
    for (i = 0; i < f; ++i) printf "%.3f\t16\t2.0\t0.3\n", 1000.05 + i;
    for (i = 0; i < s; ++i) printf "%.3f\t12\t1.5\t-0.2\n", 1000.55 + i }' > "$data/Robot${r}_Measurement.dat"
}
make_robot 1 100 10 3
make_robot 2 80 8 0
