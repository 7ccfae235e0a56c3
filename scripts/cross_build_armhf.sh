#!/usr/bin/env bash
# Cross-builds every robot-side program (and the rest but map_view) for the
# Raspberry Pi 2 (armhf, Cortex-A7) and runs the armhf unit tests under
# qemu-arm-static. Nothing armhf is installed on this machine: the armhf
# libraries (Fast DDS, yaml-cpp, ...) are Debian packages unpacked into a
# sysroot (debootstrap --foreign fetches them with their dependencies), and
# Debian's cross compiler builds against it (cmake/toolchain-armhf.cmake).
#   scripts/cross_build_armhf.sh [--sysroot DIR] [--build-dir DIR] [--no-tests] [ctest args...]
# Output: BUILD_DIR/bin (default build-armhf/bin); the sysroot is kept for the
# next run (default build-armhf-sysroot/).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
sysroot=$root/build-armhf-sysroot
build_dir=$root/build-armhf
run_tests=1
while [[ $# -gt 0 ]]; do
  case $1 in
    --sysroot) sysroot=$(realpath -m "${2:?}"); shift 2 ;;
    --build-dir) build_dir=$(realpath -m "${2:?}"); shift 2 ;;
    --no-tests) run_tests=0; shift ;;
    *) break ;;
  esac
done

SUDO=""
if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
missing=()
for p in crossbuild-essential-armhf qemu-user-static debootstrap; do dpkg -s "$p" > /dev/null 2>&1 || missing+=("$p"); done
if ((${#missing[@]})); then
  $SUDO apt-get update -qq
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# The sysroot: the armhf -dev packages and everything they need, unpacked.
packages=libfastrtps-dev,libfastcdr-dev,libyaml-cpp-dev,libeigen3-dev,libgtest-dev,libzstd-dev,liblz4-dev,libssl-dev
if [[ ! -f $sysroot/.pixyslam_sysroot ]]; then
  mirror=$(grep -hoE '^(URIs:|deb) +https?://[^ ]+' /etc/apt/sources.list /etc/apt/sources.list.d/*.sources 2>/dev/null |
    grep -v security | head -1 | awk '{print $2}' || true)
  mirror=${mirror:-http://deb.debian.org/debian}
  rm -rf "$sysroot"
  mkdir -p "$(dirname "$sysroot")"
  echo "cross_build_armhf: armhf sysroot from $mirror (~40 s)"
  $SUDO debootstrap --arch=armhf --foreign --variant=minbase --include="$packages" bookworm "$sysroot" "$mirror" \
    > "$sysroot.log" 2>&1 || { tail -20 "$sysroot.log"; exit 1; }
  # --foreign unpacks only the base; unpack the rest (no maintainer scripts run).
  for deb in "$sysroot"/var/cache/apt/archives/*.deb; do $SUDO dpkg-deb -x "$deb" "$sysroot"; done
  # No device nodes: qemu -L would open the sysroot's /dev/ptmx instead of the real one.
  $SUDO rm -rf "$sysroot"/dev/* "$sysroot"/var/cache/apt/archives/*.deb
  # Debian's CMake package files name /usr/... absolutely: point them into the sysroot.
  { grep -rlE '"/usr/(lib|include)|_IMPORT_PREFIX "/usr"' "$sysroot"/usr/lib/arm-linux-gnueabihf/cmake \
      "$sysroot"/usr/share/*/cmake "$sysroot"/usr/lib/cmake 2>/dev/null || true; } | while read -r f; do
    $SUDO sed -i -E "s#\"/usr/(lib|include)#\"$sysroot/usr/\1#g; s#_IMPORT_PREFIX \"/usr\"#_IMPORT_PREFIX \"$sysroot/usr\"#g" "$f"
  done
  $SUDO touch "$sysroot/.pixyslam_sysroot"
  rm -f "$sysroot.log"
fi

cmake -S "$root" -B "$build_dir" -DCMAKE_TOOLCHAIN_FILE="$root/cmake/toolchain-armhf.cmake" \
  -DPIXYSLAM_ARMHF_SYSROOT="$sysroot" -DCMAKE_BUILD_TYPE=Release \
  -DPIXYSLAM_BUILD_BENCHMARKS=OFF -DPIXYSLAM_BUILD_MAP_VIEW=OFF > /dev/null
cmake --build "$build_dir" -j "$(nproc)"
file "$build_dir/bin/slam_estimator"
if ((run_tests)); then
  # Through the emulator (CMAKE_CROSSCOMPILING_EMULATOR); unit tests by default.
  if [[ $# -eq 0 ]]; then set -- -L unit; fi
  ctest --test-dir "$build_dir" --output-on-failure --parallel "$(nproc)" "$@"
fi
