#!/usr/bin/env bash
# Builds the libFuzzer targets (Clang, ASan + UBSan, preset "fuzz", into
# build-fuzz) and runs each for SECONDS (default 60) from its committed seed
# corpus. Prints executions per target; fails on any crash, leak, sanitizer
# report or broken invariant (the input is kept and its path printed).
#   tests/fuzz/run_fuzz.sh [SECONDS] [TARGET...]
# Longer campaign, e.g. one hour each:  tests/fuzz/run_fuzz.sh 3600
# FUZZ_JOBS: build jobs and targets run at once (default: the number of cores).
set -euo pipefail
case ${1:-} in -h | --help) sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0"; exit 0 ;; esac
root=$(cd "$(dirname "$0")/../.." && pwd)
seconds=${1:-60}
shift || true
targets=("$@")
((${#targets[@]})) || targets=(fuzz_arduino_parser fuzz_pixy_parser fuzz_yaml_options fuzz_mcap_reader fuzz_cdr_topics)
build_dir=${FUZZ_BUILD_DIR:-$root/build-fuzz}
jobs=${FUZZ_JOBS:-$(nproc)}
if ! command -v clang++-14 >/dev/null || ! compgen -G "/usr/lib/llvm-14/lib/clang/*/lib/linux/libclang_rt.fuzzer-*.a" >/dev/null; then
  echo "run_fuzz: clang-14 with libFuzzer (libclang-rt-14-dev) not installed, skipping"
  exit 77
fi
if [[ ! -f $build_dir/CMakeCache.txt ]]; then
  # -O1 (libFuzzer's usual level): the build is the long part of a short run.
  cmake -S "$root" -B "$build_dir" -G Ninja -DCMAKE_CXX_COMPILER=clang++-14 -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -DNDEBUG" \
    -DPIXYSLAM_FUZZ=ON -DBUILD_TESTING=OFF -DPIXYSLAM_BUILD_BENCHMARKS=OFF -DPIXYSLAM_BUILD_MAP_VIEW=OFF >/dev/null
fi
cmake --build "$build_dir" --target pixyslam_fuzzers --parallel "$jobs" >/dev/null

work=$(mktemp -d /tmp/pixyslam_fuzz.XXXXXX)
trap 'rm -rf "$work"' EXIT
artifacts=${FUZZ_ARTIFACTS:-$root/build-fuzz/artifacts}
mkdir -p "$artifacts"

run_one() {
  local t=$1
  mkdir -p "$work/$t"
  # New inputs go to the scratch corpus; the committed seeds are read only.
  if "$build_dir/bin/$t" "$work/$t" "$root/tests/fuzz/corpus/$t" -max_total_time="$seconds" \
      -print_final_stats=1 -artifact_prefix="$artifacts/$t-" -close_fd_mask=1 >"$work/$t.log" 2>&1; then
    local runs
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$work/$t.log")
    printf '%-22s %12s executions in %s s, 0 crashes\n' "$t" "$runs" "$seconds"
  else
    printf '%-22s FAILED: see below; input kept in %s\n' "$t" "$artifacts"
    grep -E "ERROR|invariant|SUMMARY|Test unit written" "$work/$t.log" | head -20
    return 1
  fi
}
export -f run_one
export build_dir work seconds artifacts root
printf '%s\n' "${targets[@]}" | xargs -P "$jobs" -I{} bash -c 'run_one {}'
