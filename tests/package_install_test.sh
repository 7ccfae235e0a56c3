#!/usr/bin/env bash
# The Debian packages installed with apt into a clean Debian 12 root, then the
# demo run from the installed files only. The root is the container image
# localhost/pixyslam-logger (docker/build_images.sh, ctest fixture
# container_images): the debootstrap base image plus `apt-get install` of this
# build's pixyslam-robot and pixyslam-station packages and the Debian
# libraries they depend on, nothing else. Passes if both packages are
# installed, the pixyslam user and the /usr/bin/pixyslam-NAME links exist, the
# demo (the packaged launcher, programs and /etc/pixyslam/launch_sim.yaml, as
# the pixyslam user, no network but the container's loopback) ends with exit
# 0: every process clean, the evaluator's ATE within the launch file's bound,
# the log check passed; then apt-get purge leaves no user, /etc/pixyslam or link.
# Skips (77) without podman, root or the image.
#   package_install_test.sh SOURCE_DIR [DURATION_S]
set -euo pipefail
source=$1 duration=${2:-25}
command -v podman >/dev/null || { echo "SKIP: podman is not installed"; exit 77; }
[[ $(id -u) -eq 0 ]] || { echo "SKIP: needs root"; exit 77; }
export CONTAINERS_CONF=${CONTAINERS_CONF:-$source/docker/containers.conf}
image=localhost/pixyslam-logger:latest
podman image exists "$image" || { echo "SKIP: $image missing (docker/build_images.sh)"; exit 77; }
work=$(mktemp -d /tmp/pixyslam_install_test.XXXXXX)
cleanup() {
  podman rm -f "pxi$$" > /dev/null 2>&1 || true
  rm -rf "$work"
}
trap cleanup EXIT
trap 'exit 130' INT TERM
fail() { echo "FAIL: $*"; exit 1; }
echo "image $image: $(podman image inspect "$image" --format '{{.Size}}') bytes"

podman run --rm --network none --entrypoint sh "$image" -c '
  set -e
  dpkg-query -W -f "\${Package} \${Version} \${Status}\n" pixyslam-robot pixyslam-station
  getent passwd pixyslam
  ls /usr/bin/pixyslam-* | tr "\n" " "; echo' > "$work/installed.txt" 2>&1 || { cat "$work/installed.txt"; fail "installed state"; }
cat "$work/installed.txt"
grep -q "pixyslam-robot .* install ok installed" "$work/installed.txt" || fail "pixyslam-robot not installed"
grep -q "pixyslam-station .* install ok installed" "$work/installed.txt" || fail "pixyslam-station not installed"
grep -q "^pixyslam:.*:/var/lib/pixyslam:/usr/sbin/nologin" "$work/installed.txt" || fail "no pixyslam system user"
grep -q "/usr/bin/pixyslam-map-view" "$work/installed.txt" || fail "no /usr/bin/pixyslam-map-view"

# The demo from the installed files, as the pixyslam user, loopback only.
start=$(date +%s)
status=0
podman run --name "pxi$$" --network none "$image" \
  /etc/pixyslam/launch_sim.yaml --run-dir /tmp/demo duration:="$duration" > "$work/demo.log" 2>&1 || status=$?
grep -E "^\[launch\]|ATE|landmark" "$work/demo.log" | tail -25
[[ $status -eq 0 ]] || { tail -40 "$work/demo.log"; fail "the installed demo exited with $status"; }
grep -q "started slam_estimator (pid [0-9]*): /usr/lib/pixyslam/bin/slam_estimator" "$work/demo.log" ||
  fail "the launcher did not start the installed slam_estimator"
demo_s=$(($(date +%s) - start))

# Purge: both packages go, with the user, /etc/pixyslam and the links.
podman run --rm --network none --user root --entrypoint sh "$image" -c '
  apt-get purge -y -qq pixyslam-station pixyslam-robot > /dev/null 2>&1
  getent passwd pixyslam && echo "user left"
  ls -d /etc/pixyslam /usr/lib/pixyslam /usr/bin/pixyslam-* 2> /dev/null && echo "files left"
  echo purged' > "$work/purge.txt" 2>&1 || true
[[ $(cat "$work/purge.txt") == purged ]] || { cat "$work/purge.txt"; fail "apt-get purge left something"; }
echo "PASS: installed with apt (whoami in the image: $(podman run --rm --network none --entrypoint whoami "$image")), ran the demo for $duration s ($demo_s s), purged clean"
