#!/usr/bin/env bash
# Cross-builds every robot-side program (and the rest but map_view and the
# programs only the native tests run) for the Raspberry Pi 2 (armhf, Cortex-A7)
# and runs the armhf unit tests under qemu-arm-static. Nothing armhf is
# installed on this machine: the armhf libraries (Fast DDS, yaml-cpp, ...) are
# Debian packages unpacked into a sysroot (debootstrap --foreign fetches them
# with their dependencies), and Debian's cross compiler builds against it
# (cmake/toolchain-armhf.cmake).
#   scripts/cross_build_armhf.sh [--sysroot DIR] [--build-dir DIR] [--no-tests] [--prepare-only] [--map-optimizer] [ctest args...]
# --prepare-only: the cross tools, the sysroot and the configured build folder,
# nothing compiled (mostly downloads: scripts/run_tests.sh runs it beside the
# native build).
# Output: BUILD_DIR/bin (default build-armhf/bin); the sysroot is kept for the
# next run (default build-armhf-sysroot/).
# --map-optimizer: also Ceres (libceres-dev and its dependencies, in a sysroot
# of its own, default build-armhf-sysroot-ceres/), the map optimiser and the
# benchmarks, to measure the optimiser's cost on the Pi's instruction set
# (docs/benchmarks.md); the robot itself does not need it.
set -euo pipefail
case ${1:-} in -h | --help) sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0"; exit 0 ;; esac
root=$(cd "$(dirname "$0")/.." && pwd)
sysroot=$root/build-armhf-sysroot
build_dir=$root/build-armhf
run_tests=1
prepare_only=0
map_optimizer=0
sysroot_given=0
while [[ $# -gt 0 ]]; do
  case $1 in
    --sysroot) sysroot=$(realpath -m "${2:?}"); sysroot_given=1; shift 2 ;;
    --build-dir) build_dir=$(realpath -m "${2:?}"); shift 2 ;;
    --no-tests) run_tests=0; shift ;;
    --prepare-only) prepare_only=1; shift ;;
    --map-optimizer) map_optimizer=1; shift ;;
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
packages=libfastrtps-dev,libfastcdr-dev,libyaml-cpp-dev,libcli11-dev,libeigen3-dev,libgtest-dev,libzstd-dev,liblz4-dev,libssl-dev
extra_cmake=(-DPIXYSLAM_BUILD_BENCHMARKS=OFF -DPIXYSLAM_BUILD_MAP_OPTIMIZER=OFF)
if ((map_optimizer)); then
  packages+=,libceres-dev,libbenchmark-dev
  ((sysroot_given)) || sysroot=$root/build-armhf-sysroot-ceres
  extra_cmake=(-DPIXYSLAM_BUILD_BENCHMARKS=ON -DPIXYSLAM_BUILD_MAP_OPTIMIZER=ON)
fi
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
  $SUDO touch "$sysroot/.pixyslam_sysroot"
  rm -f "$sysroot.log"
fi
# Debian's CMake package files name /usr/... absolutely (quoted, or in a ;-list
# as Ceres' BLAS and LAPACK): point them into the sysroot (idempotent).
{ grep -rlE '[";]/usr/(lib|include)|_IMPORT_PREFIX "/usr"' "$sysroot"/usr/lib/arm-linux-gnueabihf/cmake \
    "$sysroot"/usr/share/*/cmake "$sysroot"/usr/lib/cmake 2>/dev/null || true; } | while read -r f; do
  $SUDO sed -i -E "s#([\";])/usr/(lib|include)#\1$sysroot/usr/\2#g; s#_IMPORT_PREFIX \"/usr\"#_IMPORT_PREFIX \"$sysroot/usr\"#g" "$f"
done
# BLAS and LAPACK (Ceres) live in blas/ and lapack/ behind update-alternatives
# links, which no maintainer script made here: link them where the linker and
# qemu's loader look.
for lib in blas lapack; do
  for f in "$sysroot/usr/lib/arm-linux-gnueabihf/$lib/lib$lib.so"*; do
    [[ -e $f ]] && $SUDO ln -sfn "$lib/${f##*/}" "$sysroot/usr/lib/arm-linux-gnueabihf/${f##*/}"
  done
done

generator=()
if command -v ninja > /dev/null && [[ ! -f $build_dir/Makefile ]]; then generator=(-G Ninja); fi
cmake -S "$root" -B "$build_dir" "${generator[@]}" -DCMAKE_TOOLCHAIN_FILE="$root/cmake/toolchain-armhf.cmake" \
  -DPIXYSLAM_ARMHF_SYSROOT="$sysroot" -DCMAKE_BUILD_TYPE=Release \
  -DPIXYSLAM_BUILD_MAP_VIEW=OFF "${extra_cmake[@]}" > /dev/null
if ((prepare_only)); then exit 0; fi
cmake --build "$build_dir" -j "$(nproc)"
file "$build_dir/bin/slam_estimator"
if ((run_tests)); then
  # Through the emulator (CMAKE_CROSSCOMPILING_EMULATOR); unit tests by default.
  if [[ $# -eq 0 ]]; then set -- -L unit; fi
  ctest --test-dir "$build_dir" --output-on-failure --parallel "$(nproc)" "$@"
fi
