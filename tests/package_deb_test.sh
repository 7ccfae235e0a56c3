#!/usr/bin/env bash
# The Debian packages pixyslam-robot and pixyslam-station (cpack -G DEB from
# this build): their control data (runtime dependencies found by
# dpkg-shlibdeps: no GUI library for the robot; conffiles), their files (programs in
# /usr/lib/pixyslam/bin with /usr/bin/pixyslam-NAME links, /etc/pixyslam,
# systemd units whose ExecStart exists in the package), no file that another
# package of this Debian system owns (dpkg refuses to overwrite those: a
# /usr/bin/logger made the package uninstallable), and the unpacked robot side
# running: the packaged launcher, started through its /usr/bin link, starts
# the packaged bridges from the packaged launch_robot.yaml (no serial devices
# here: they wait for them) and stops them cleanly. Nothing is installed on
# the machine.
#   package_deb_test.sh BUILD_DIR
set -euo pipefail
build=$1
command -v dpkg-deb >/dev/null || { echo "SKIP: no dpkg-deb"; exit 77; }
work=$(mktemp -d /tmp/pixyslam_deb_test.XXXXXX)
trap 'rm -rf "$work"' EXIT
trap 'exit 130' INT TERM  # a killed test still cleans up (the EXIT trap)
cpack --config "$build/CPackConfig.cmake" -G DEB -B "$work/out" > "$work/cpack.log" 2>&1 || { cat "$work/cpack.log"; exit 1; }
robot_deb=$(ls "$work"/out/pixyslam-robot_*.deb)
station_deb=$(ls "$work"/out/pixyslam-station_*.deb)
fail() { echo "FAIL: $*"; exit 1; }
robot_info=$(dpkg-deb -I "$robot_deb")
station_info=$(dpkg-deb -I "$station_deb")
echo "$robot_info" | grep -E "^ (Package|Version|Depends|Installed-Size):"
echo "$station_info" | grep -E "^ (Package|Version|Depends|Installed-Size):"
for dep in libfastrtps2.9 libyaml-cpp0.7 libzstd1 libopencv-videoio406; do
  echo "$robot_info" | grep -q "Depends:.*$dep" || fail "pixyslam-robot's Depends lacks $dep"
done
! echo "$robot_info" | grep -E "^ Depends:.*(highgui|libqt|libgtk|libceres)" || fail "pixyslam-robot depends on a GUI library or Ceres"
echo "$station_info" | grep -q "Depends:.*pixyslam-robot (= " || fail "pixyslam-station does not depend on pixyslam-robot"
echo "$station_info" | grep -q "Depends:.*libopencv-highgui406" || fail "pixyslam-station lacks map_view's highgui"
for deb in "$robot_deb" "$station_deb"; do
  dpkg-deb -x "$deb" "$work/root"  # both into one root: the station's programs beside the robot's
done
dpkg-deb -e "$robot_deb" "$work/control"
dpkg-deb -e "$station_deb" "$work/station_control"
for f in usr/lib/pixyslam/bin/slam_estimator usr/lib/pixyslam/bin/encoder_bridge usr/lib/pixyslam/bin/pixy_bridge \
         usr/lib/pixyslam/bin/pixy_bridge_camera \
         usr/lib/pixyslam/bin/logger usr/lib/pixyslam/bin/pixyslam_launch usr/lib/pixyslam/bin/pixyslam_calibrate \
         usr/bin/pixyslam-launch usr/bin/pixyslam-logger usr/bin/pixyslam-slam-estimator usr/bin/pixyslam-calibrate \
         etc/pixyslam/dds/profiles.xml etc/pixyslam/launch_robot.yaml etc/default/pixyslam \
         usr/lib/systemd/system/pixyslam-robot.service usr/lib/systemd/system/pixyslam-station.service; do
  [[ -e $work/root/$f ]] || fail "$f is in neither package"
done
# pixy_bridge runs pixy_bridge_camera from its own folder for a camera (and --help).
# grep > /dev/null, not -q: an early exit of grep would make the writer's SIGPIPE the pipeline's status.
"$work/root/usr/lib/pixyslam/bin/pixy_bridge" --help | grep "camera.input" > /dev/null ||
  fail "the packaged pixy_bridge --help does not reach pixy_bridge_camera (no camera keys)"
ldd "$work/root/usr/lib/pixyslam/bin/pixy_bridge" | grep opencv > /dev/null && fail "pixy_bridge loads OpenCV (only pixy_bridge_camera should)"
dpkg-deb -c "$robot_deb" | grep "usr/lib/pixyslam/bin/map_view" > /dev/null && fail "map_view (GUI) is in pixyslam-robot"
dpkg-deb -c "$station_deb" | grep "etc/pixyslam" > /dev/null && fail "pixyslam-station ships config files (pixyslam-robot's)"
grep -qx "/etc/pixyslam/slam_estimator.yaml" "$work/control/conffiles" || fail "config files are not conffiles"
# Every /usr/bin entry is a pixyslam-NAME link to a program of the package.
for link in "$work"/root/usr/bin/*; do
  [[ $(basename "$link") == pixyslam-* && -L $link && -x $link ]] || fail "/usr/bin/$(basename "$link") is not a pixyslam-NAME link to a program"
done
# No file of the package belongs to an installed Debian package (dpkg would
# refuse to unpack it over that package's file).
while IFS= read -r path; do
  path=${path#.}
  [[ -z $path || -d $work/root$path && ! -L $work/root$path ]] && continue
  if owner=$(dpkg-query -S "$path" 2>/dev/null) && ! [[ ${owner%%:*} =~ ^pixyslam(-robot|-station)?$ ]]; then
    fail "$path is also in the installed package ${owner%%:*}"
  fi
done < <(cd "$work/root" && find . -mindepth 1)
for script in postinst prerm postrm; do
  [[ -x $work/control/$script && -x $work/station_control/$script ]] || fail "no $script maintainer script in both"
done
grep -q "adduser --system" "$work/control/postinst" || fail "postinst makes no system user"
for unit in "$work"/root/usr/lib/systemd/system/*.service; do
  for line in User=pixyslam NoNewPrivileges=yes ProtectSystem=strict PrivateTmp=yes; do
    grep -qx "$line" "$unit" || fail "$(basename "$unit"): no $line"
  done
  # systemd's own exposure score (0 safe .. 10 unsafe; a unit with no hardening is 9.6).
  if command -v systemd-analyze >/dev/null && systemd-analyze security --offline=yes "$unit" >/dev/null 2>&1; then
    score=$(systemd-analyze security --offline=yes "$unit" 2>/dev/null | sed -n 's/.*exposure level for .*: \([0-9.]*\) .*/\1/p')
    echo "$(basename "$unit"): systemd-analyze security exposure $score"
    [[ -n $score ]] && awk -v s="$score" 'BEGIN { exit !(s <= 2.5) }' || fail "$(basename "$unit"): exposure '$score' above 2.5"
  fi
done
for unit in "$work"/root/usr/lib/systemd/system/*.service; do
  exe=$(sed -n 's/^ExecStart=\([^ ]*\).*/\1/p' "$unit")
  [[ -x $work/root$exe ]] || fail "$(basename "$unit"): ExecStart $exe is not in the package"
  config=$(sed -n 's/^ExecStart=[^ ]* \([^ ]*\).*/\1/p' "$unit")
  [[ -f $work/root$config ]] || fail "$(basename "$unit"): $config is not in the package"
done
# The robot side from the unpacked files, on a private DDS domain, for 3 s.
domain=$((40 + $$ % 100))
sed -i "s/^  domain_id: 0/  domain_id: $domain/" "$work"/root/etc/pixyslam/*.yaml
status=0
"$work/root/usr/bin/pixyslam-launch" "$work/root/etc/pixyslam/launch_robot.yaml" --run-dir "$work/run" \
  --duration 3 > "$work/run.log" 2>&1 || status=$?
grep "\[launch\]" "$work/run.log"
[[ $status -eq 0 ]] || fail "the packaged robot side exited with $status"
grep -q "started encoder_bridge (pid [0-9]*): $work/root/usr/lib/pixyslam/bin/encoder_bridge" "$work/run.log" ||
  fail "the launcher did not start the packaged encoder_bridge"
echo "PASS: $(basename "$robot_deb") $(stat -c %s "$robot_deb") bytes, $(basename "$station_deb") $(stat -c %s "$station_deb") bytes"
