#!/usr/bin/env bash
# Every executable of the build (BIN_DIR, but the gtest binaries): `--help`
# prints to stdout and exits 0 within 1 s without opening a network socket
# (no DDS participant; checked with strace when it is installed), and an
# unknown flag exits 2 (usage error) with a message on stderr.
#   help_all_test.sh BIN_DIR
set -uo pipefail
bin=$1
work=$(mktemp -d "${TMPDIR:-/tmp}/pixyslam_help_all.XXXXXX")
trap 'rm -rf "$work"' EXIT
trap 'exit 130' INT TERM
have_strace=0
command -v strace > /dev/null && strace -f -o /dev/null true 2> /dev/null && have_strace=1
((have_strace)) || echo "note: strace not usable here: sockets not checked"

fail=0 checked=0
for exe in "$bin"/*; do
  name=$(basename "$exe")
  [[ -f $exe && -x $exe && $name != test_* ]] || continue
  checked=$((checked + 1))
  start=$(date +%s%N)
  if ((have_strace)); then
    timeout 10 strace -f -qq -e trace=socket -o "$work/$name.trace" "$exe" --help > "$work/$name.out" 2> "$work/$name.err"
  else
    timeout 10 "$exe" --help > "$work/$name.out" 2> "$work/$name.err"
  fi
  rc=$?
  elapsed_ms=$((($(date +%s%N) - start) / 1000000))
  problems=()
  ((rc == 0)) || problems+=("--help exited $rc")
  [[ -s $work/$name.out ]] || problems+=("--help printed nothing on stdout")
  # strace itself slows start-up: the time limit applies without it.
  ((have_strace || elapsed_ms < 1000)) || problems+=("--help took $elapsed_ms ms")
  if ((have_strace)) && grep -E 'socket\(AF_INET6?,' "$work/$name.trace" > /dev/null; then
    problems+=("--help opened a network socket: $(grep -m1 -E 'socket\(AF_INET' "$work/$name.trace")")
  fi
  timeout 10 "$exe" --no-such-flag-xyz > /dev/null 2> "$work/$name.bad"
  bad_rc=$?
  ((bad_rc == 2)) || problems+=("an unknown flag exited $bad_rc (usage errors exit 2)")
  [[ -s $work/$name.bad ]] || problems+=("an unknown flag printed nothing on stderr")
  if ((${#problems[@]})); then
    printf 'FAIL %s: %s\n' "$name" "${problems[*]}"
    fail=1
  else
    printf 'ok   %-26s --help in %d ms%s\n' "$name" "$elapsed_ms" "$( ((have_strace)) && echo ' (under strace)')"
  fi
done
if ((checked < 20)); then
  echo "FAIL: only $checked executables in $bin"
  fail=1
fi
if ((fail == 0)); then
  # The time limit without strace's overhead; the best of three runs, as the
  # machine may be busy with other tests.
  for exe in "$bin"/*; do
    name=$(basename "$exe")
    [[ -f $exe && -x $exe && $name != test_* ]] || continue
    best_ms=100000
    for _ in 1 2 3; do
      start=$(date +%s%N)
      timeout 10 "$exe" --help > /dev/null 2>&1
      elapsed_ms=$((($(date +%s%N) - start) / 1000000))
      ((elapsed_ms < best_ms)) && best_ms=$elapsed_ms
    done
    if ((best_ms >= 1000)); then
      echo "FAIL $name: --help took $best_ms ms (best of 3)"
      fail=1
    fi
  done
fi
((fail == 0)) && echo "PASS: $checked executables"
exit "$fail"
