#!/usr/bin/env bash
# Emulates a host that leaves a process unscheduled now and then: stops every
# process named NAME (exact name, pgrep -x) with SIGSTOP for STOP_S seconds,
# continues it (SIGCONT), waits EVERY_S seconds and repeats, until no such
# process is left or DURATION_S seconds have passed. Serial bytes then come
# late and all at once, as on a loaded Pi or CI machine. Run it beside a
# system run, e.g. (docs/robustness.md, "A stalled host"):
#   ctest --test-dir build -R '^system_one_lap$' -V &
#   sleep 6; scripts/stall_process.sh robot_sim 1.0 3 60
#   scripts/stall_process.sh NAME STOP_S EVERY_S [DURATION_S]
# A stopped process is always continued, also when this script is interrupted.
# Exit status: 0 done, 2 usage.
set -euo pipefail
usage() { sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0"; }
case ${1:-} in -h | --help) usage; exit 0 ;; esac
(($# >= 3 && $# <= 4)) || { usage >&2; exit 2; }
name=$1 stop_s=$2 every_s=$3 duration_s=${4:-3600}
number='^[0-9]+([.][0-9]+)?$'
for v in "$stop_s" "$every_s" "$duration_s"; do
  [[ $v =~ $number ]] || { echo "stall_process.sh: '$v' is not a number of seconds" >&2; usage >&2; exit 2; }
done
stopped=()
resume() { ((${#stopped[@]})) && kill -CONT "${stopped[@]}" 2>/dev/null; stopped=(); }
trap resume EXIT
trap 'exit 130' INT TERM
end=$((SECONDS + ${duration_s%.*}))
stalls=0
while ((SECONDS < end)); do
  mapfile -t stopped < <(pgrep -x "$name" || true)
  ((${#stopped[@]})) || break
  kill -STOP "${stopped[@]}" 2>/dev/null || true
  sleep "$stop_s"
  resume
  stalls=$((stalls + 1))
  sleep "$every_s"
done
echo "stall_process.sh: stopped '$name' $stalls times for $stop_s s"
