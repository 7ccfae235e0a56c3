#!/usr/bin/env bash
# The armhf build's unit tests (scripts/cross_build_armhf.sh), each run under
# qemu-arm-static by ctest (the toolchain's CMAKE_CROSSCOMPILING_EMULATOR).
# Skips (77) without the armhf build. ARMHF_TEST_PARALLEL: tests at once
# (default: the number of cores).
#   armhf_unit_tests.sh ARMHF_BUILD_DIR
set -euo pipefail
armhf_build=$1
if [[ ! -f $armhf_build/CTestTestfile.cmake ]] || ! command -v qemu-arm-static > /dev/null; then
  echo "SKIP: no armhf build in $armhf_build (scripts/cross_build_armhf.sh) or no qemu-arm-static"
  exit 77
fi
ctest --test-dir "$armhf_build" -L unit --output-on-failure --parallel "${ARMHF_TEST_PARALLEL:-$(nproc)}"
