#!/usr/bin/env bash
# Installs what is missing, builds (native, and the armhf cross build whose
# unit tests and estimator the `armhf` tests run under qemu; PIXYSLAM_ARMHF=0
# skips it), and runs every test (ctest). Extra arguments go to ctest, e.g.
# scripts/run_tests.sh -L unit.
set -euo pipefail
case ${1:-} in -h | --help) sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0"; exit 0 ;; esac
root=$(cd "$(dirname "$0")/.." && pwd)
# Each phase's wall time, on one line at the end (and when a phase fails).
phases=""
phase() {
  local name=$1 start=$SECONDS rc=0
  shift
  "$@" || rc=$?
  phases+=" $name $((SECONDS - start)) s,"
  ((rc == 0)) || echo "run_tests: $name failed (exit status $rc) after $((SECONDS - start)) s"
  return "$rc"
}
phase install "$root/scripts/install_deps.sh"
armhf=0
[[ ${PIXYSLAM_ARMHF:-1} == 0 ]] || armhf=1
if ((armhf)); then
  # The cross tools and the armhf sysroot are mostly downloads: beside the
  # native build, which keeps the cores busy (its output in a file until then).
  # Its own process group (setsid), stopped with it if the build fails.
  armhf_prepare_log=$(mktemp /tmp/pixyslam_armhf_prepare.XXXXXX)
  setsid "$root/scripts/cross_build_armhf.sh" --prepare-only --build-dir "$root/build-armhf" \
    > "$armhf_prepare_log" 2>&1 &
  armhf_prepare=$!
  trap 'kill -- -"$armhf_prepare" 2> /dev/null || true; rm -f "$armhf_prepare_log"' EXIT
fi
phase build "$root/scripts/build.sh"
if ((armhf)); then
  armhf_prepared() {
    local rc=0
    wait "$armhf_prepare" || rc=$?
    cat "$armhf_prepare_log"
    return "$rc"
  }
  phase armhf_prepare armhf_prepared
  phase armhf_build "$root/scripts/cross_build_armhf.sh" --no-tests --build-dir "$root/build-armhf"
fi
build_dir=${BUILD_DIR:-$root/build}
# Two tests more than cores: the DDS tests (one at a time, RESOURCE_LOCK dds)
# mostly wait on simulated real time, the container image build mostly on apt,
# while the armhf unit tests under qemu and the fuzz build (both niced) keep
# the cores busy beside them from the start (with one more than cores, the fuzz
# build waited ~150 s for the images and was the last test to end).
# The pure unit tests first, on their own (under a minute; a failure shows
# early and they do not load the cores beside the timing-sensitive DDS runs).
status=0
if (($# == 0)); then
  phase unit_tests ctest --test-dir "$build_dir" --output-on-failure --parallel "$(nproc)" --timeout 600 -L '^unit$' ||
    status=$?
  set -- -LE '^unit$'
fi
phase tests ctest --test-dir "$build_dir" --output-on-failure --parallel "$(($(nproc) + 2))" --timeout 600 "$@" || status=$?
echo "run_tests: ${phases%,} (total $SECONDS s)"
exit "$status"
