#!/usr/bin/env bash
# The Debian packages installed with apt into a clean Debian 12 root (the
# container tests' debootstrap image, localhost/pixyslam-base:bookworm, in
# podman), then the demo run from the installed files only: the packaged
# launcher, programs and /etc/pixyslam/launch_sim.yaml, as the pixyslam user
# the maintainer scripts made, with no network but the container's loopback.
# Passes if apt installs both packages (and their Debian dependencies), the
# user and the /usr/bin/pixyslam-NAME links exist, and the demo ends with exit
# 0: every process clean, the evaluator's ATE within the launch file's bound,
# the log check passed; then apt-get purge leaves no user, /etc/pixyslam or link. apt reaches the machine's Debian mirror during the
# image build only (--network host, as docker/build_images.sh).
# Skips (77) without podman, root or the base image (ctest fixture container_images).
#   package_install_test.sh BUILD_DIR SOURCE_DIR [DURATION_S]
set -euo pipefail
build=$1 source=$2 duration=${3:-25}
command -v podman >/dev/null || { echo "SKIP: podman is not installed"; exit 77; }
[[ $(id -u) -eq 0 ]] || { echo "SKIP: needs root"; exit 77; }
export CONTAINERS_CONF=${CONTAINERS_CONF:-$source/docker/containers.conf}
base=localhost/pixyslam-base:bookworm
podman image exists "$base" || { echo "SKIP: $base missing (docker/build_base_image.sh)"; exit 77; }
work=$(mktemp -d /tmp/pixyslam_install_test.XXXXXX)
image=localhost/pixyslam-installed-test:$$
cleanup() {
  podman rm -f "pxi$$" > /dev/null 2>&1 || true
  podman rmi -f "$image" > /dev/null 2>&1 || true
  rm -rf "$work"
}
trap cleanup EXIT
trap 'exit 130' INT TERM
fail() { echo "FAIL: $*"; exit 1; }

cpack --config "$build/CPackConfig.cmake" -G DEB -B "$work/out" > "$work/cpack.log" 2>&1 || { cat "$work/cpack.log"; exit 1; }
cp "$work"/out/pixyslam-robot_*.deb "$work"/out/pixyslam-station_*.deb "$work/"
cat > "$work/Containerfile" <<CONTAINERFILE
FROM $base
COPY pixyslam-robot_*.deb pixyslam-station_*.deb /tmp/debs/
RUN apt-get update -qq \\
 && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends /tmp/debs/*.deb > /tmp/apt.log \\
 && rm -rf /var/lib/apt/lists/* /tmp/debs
CONTAINERFILE
start=$(date +%s)
podman build --network host -q -f "$work/Containerfile" -t "$image" "$work" > "$work/build.log" 2>&1 ||
  { tail -30 "$work/build.log"; fail "apt could not install the packages into $base"; }
echo "apt install of both packages into $base: $(($(date +%s) - start)) s, image $(podman image inspect "$image" --format '{{.Size}}') bytes"

podman run --rm --network none "$image" sh -c '
  set -e
  dpkg-query -W -f "\${Package} \${Version} \${Status}\n" pixyslam-robot pixyslam-station
  getent passwd pixyslam
  ls /usr/bin/pixyslam-* | tr "\n" " "; echo
  systemd-analyze --version > /dev/null 2>&1 || true' > "$work/installed.txt" 2>&1 || { cat "$work/installed.txt"; fail "installed state"; }
cat "$work/installed.txt"
grep -q "pixyslam-robot .* install ok installed" "$work/installed.txt" || fail "pixyslam-robot not installed"
grep -q "pixyslam-station .* install ok installed" "$work/installed.txt" || fail "pixyslam-station not installed"
grep -q "^pixyslam:.*:/var/lib/pixyslam:/usr/sbin/nologin" "$work/installed.txt" || fail "no pixyslam system user"
grep -q "/usr/bin/pixyslam-map-view" "$work/installed.txt" || fail "no /usr/bin/pixyslam-map-view"

# The demo from the installed files, as the pixyslam user, loopback only.
start=$(date +%s)
status=0
podman run --name "pxi$$" --network none --user pixyslam "$image" \
  pixyslam-launch /etc/pixyslam/launch_sim.yaml --run-dir /tmp/demo duration:="$duration" > "$work/demo.log" 2>&1 || status=$?
grep -E "^\[launch\]|ATE|landmark" "$work/demo.log" | tail -25
[[ $status -eq 0 ]] || { tail -40 "$work/demo.log"; fail "the installed demo exited with $status"; }
grep -q "started slam_estimator (pid [0-9]*): /usr/lib/pixyslam/bin/slam_estimator" "$work/demo.log" ||
  fail "the launcher did not start the installed slam_estimator"
demo_s=$(($(date +%s) - start))

# Purge: both packages go, with the user, /etc/pixyslam and the links.
podman run --rm --network none "$image" sh -c '
  apt-get purge -y -qq pixyslam-station pixyslam-robot > /dev/null 2>&1
  getent passwd pixyslam && echo "user left"
  ls -d /etc/pixyslam /usr/lib/pixyslam /usr/bin/pixyslam-* 2> /dev/null && echo "files left"
  echo purged' > "$work/purge.txt" 2>&1 || true
[[ $(cat "$work/purge.txt") == purged ]] || { cat "$work/purge.txt"; fail "apt-get purge left something"; }
echo "PASS: installed with apt, ran the demo for $duration s ($demo_s s), purged clean"
