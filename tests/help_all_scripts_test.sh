#!/usr/bin/env bash
# Every script a user runs (scripts/*.sh, docker/*.sh, tests/fuzz/run_fuzz.sh):
# `--help` exits 0 within 5 s and prints the script's header comment (and so
# does nothing else: before this test, `run_tests.sh --help` started a build,
# `paper_experiments.sh --help` an experiment and `build_base_image.sh --help`
# a debootstrap). Scripts whose arguments are their own (not handed on to
# cmake, ctest or a program) also refuse an unknown flag with exit status 2 and
# a message on stderr.
#   help_all_scripts_test.sh SOURCE_DIR
set -uo pipefail
src=$1
work=$(mktemp -d "${TMPDIR:-/tmp}/pixyslam_help_scripts.XXXXXX")
trap 'rm -rf "$work"' EXIT
trap 'exit 130' INT TERM
own_arguments=(install_deps tool_help paper_experiments make_dds_security run_sanitizers fleet_scale stall_process
  build_base_image build_images)
fail=0 checked=0
for script in "$src"/scripts/*.sh "$src"/docker/*.sh "$src"/tests/fuzz/run_fuzz.sh; do
  name=$(basename "$script" .sh)
  checked=$((checked + 1))
  problems=()
  timeout 5 bash "$script" --help > "$work/out" 2> "$work/err"
  rc=$?
  ((rc == 0)) || problems+=("--help exited $rc")
  first=$(sed -n '2s/^# \{0,1\}//p' "$script")
  [[ $(head -1 "$work/out") == "$first" ]] || problems+=("--help did not print the header (first line: '$(head -1 "$work/out")')")
  if [[ " ${own_arguments[*]} " == *" $name "* ]]; then
    timeout 5 bash "$script" --no-such-flag-xyz > /dev/null 2> "$work/bad"
    bad_rc=$?
    ((bad_rc == 2)) || problems+=("an unknown flag exited $bad_rc (usage errors exit 2)")
    [[ -s $work/bad ]] || problems+=("an unknown flag printed nothing on stderr")
  fi
  if ((${#problems[@]})); then
    printf 'FAIL %s: %s\n' "$name" "${problems[*]}"
    fail=1
  else
    printf 'ok   %s\n' "$name"
  fi
done
if ((checked < 10)); then
  echo "FAIL: only $checked scripts in $src"
  fail=1
fi
((fail == 0)) && echo "PASS: $checked scripts"
exit "$fail"
