#!/usr/bin/env bash
# Builds the project with sanitizers (CMake preset asan or tsan, into build-asan
# or build-tsan) and runs the test suite there. Extra arguments go to ctest,
# e.g. scripts/run_sanitizers.sh asan -L unit.
#   asan: AddressSanitizer + UndefinedBehaviorSanitizer (UBSan findings abort)
#   tsan: ThreadSanitizer
# Debian's Fast DDS is not instrumented; tests/sanitizers/ holds the settings
# and suppressions for what ASan/LSan/TSan report inside it (not in our code).
set -euo pipefail
case ${1:-} in -h | --help) sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0"; exit 0 ;; esac
root=$(cd "$(dirname "$0")/.." && pwd)
kind=${1:?usage: run_sanitizers.sh asan|tsan [ctest args]}
shift
case $kind in
  asan|tsan) ;;
  *) echo "run_sanitizers: unknown kind '$kind' (asan or tsan)" >&2; exit 2 ;;
esac
"$root/scripts/install_deps.sh"
build_dir=$root/build-$kind
generator=()
command -v ninja >/dev/null 2>&1 && generator=(-G Ninja)
[[ -f $build_dir/CMakeCache.txt ]] || cmake --preset "$kind" "${generator[@]}" >/dev/null
cmake --build "$build_dir" --parallel "$(nproc)"
supp=$root/tests/sanitizers
# Fast DDS 2.9 (Debian) deletes a StatisticsWriterImpl through the wrong type.
export ASAN_OPTIONS="new_delete_type_mismatch=0:detect_stack_use_after_return=1:strict_string_checks=1"
export LSAN_OPTIONS="suppressions=$supp/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export TSAN_OPTIONS="suppressions=$supp/tsan.supp:halt_on_error=1:second_deadlock_stack=1"
ctest --test-dir "$build_dir" --output-on-failure --parallel "$(nproc)" --timeout 900 "$@"
