#!/usr/bin/env bash
# ctest launcher_signals: pixyslam_launch killed by SIGHUP (terminal or SSH
# closed) and by SIGKILL leaves no process of its run behind.
# The launcher is started in the background of this non-interactive script, so
# it inherits an ignored SIGINT; its children must start with default
# dispositions. The run's processes (each a `sleep` with a marker argument):
#   plain      a sleep
#   escaper    a direct child that calls setsid (leaves the launcher's process group)
#   stubborn   ignores SIGINT (needs the SIGKILL after stop_timeout_s)
#   orphaner   (SIGHUP run) starts a grandchild in a new session and exits:
#              the launcher adopts it as subreaper and stops it
# After the signal, no process with the marker may remain within 10 s.
#   launcher_signal_test.sh LAUNCHER
set -euo pipefail
launcher=$1
command -v perl >/dev/null || { echo "SKIP: perl (for setsid) not found"; exit 77; }
work=$(mktemp -d "${TMPDIR:-/tmp}/pixyslam_launcher_signals.XXXXXX")
tag=$$
launcher_pid=""

# PIDs of the processes whose command line matches the regular expression $1
# (which does not match its own text). grep exits 2 when a process listed by
# the glob is gone before it is read (pipefail would end the script): ignored.
pids_matching() { grep -las -E "$1" /proc/[0-9]*/cmdline | sed 's#/proc/\([0-9]*\)/cmdline#\1#' || true; }
# The run's processes: command line holds "sleep 40<k>.<tag>".
marked() { pids_matching "40[0-9][0-9]\.${tag}"; }
cleanup() {
  [[ -n $launcher_pid ]] && kill -9 "$launcher_pid" 2>/dev/null || true
  for pid in $(marked); do kill -9 "$pid" 2>/dev/null || true; done
  wait 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

run_case() {
  local signal=$1 base=$2 orphaner=$3
  local file=$work/launch_$signal.yaml
  cat > "$file" <<YAML
launch:
  stop_timeout_s: 1
  processes:
    - name: plain
      command: [/bin/sleep, '$((base + 1)).$tag']
    - name: escaper
      command: [perl, -e, 'use POSIX; POSIX::setsid(); exec("/bin/sleep", "$((base + 2)).$tag")']
    - name: stubborn
      command: [/bin/sh, -c, "trap '' INT; exec /bin/sleep $((base + 3)).$tag"]
YAML
  local expected=3
  if [[ $orphaner == yes ]]; then
    cat >> "$file" <<YAML
    - name: orphaner
      command: [/bin/sh, -c, "perl -e 'use POSIX; POSIX::setsid(); exec(\"/bin/sleep\", \"$((base + 4)).$tag\")' & exit 0"]
YAML
    expected=4
  fi
  "$launcher" "$file" --run-dir "$work/run_$signal" > "$work/launch_$signal.log" 2>&1 &
  launcher_pid=$!
  local n=0
  for _ in $(seq 100); do
    n=$(marked | wc -l)
    [[ $n -ge $expected ]] && break
    sleep 0.1
  done
  if [[ $n -lt $expected ]]; then
    cat "$work/launch_$signal.log"
    echo "FAIL ($signal): $n of $expected processes started"
    exit 1
  fi
  # Children start with default dispositions: SIGINT (bit 2) not ignored by
  # the plain sleep although the launcher was started with it ignored.
  local plain_pid
  plain_pid=$(pids_matching "40[0-9]1\.${tag}" | sed -n 1p)
  local ignored
  ignored=$(awk '/^SigIgn:/ {print $2}' "/proc/$plain_pid/status")
  if (( (16#$ignored & 2) != 0 )); then
    echo "FAIL ($signal): the child ignores SIGINT (SigIgn $ignored)"
    exit 1
  fi
  kill "-$signal" "$launcher_pid"
  local left=""
  for _ in $(seq 100); do
    left=$(marked)
    if [[ -z $left ]] && ! kill -0 "$launcher_pid" 2>/dev/null; then break; fi
    sleep 0.1
  done
  wait "$launcher_pid" 2>/dev/null || true
  launcher_pid=""
  left=$(marked)
  if [[ -n $left ]]; then
    cat "$work/launch_$signal.log"
    for pid in $left; do echo "left: $pid $(tr '\0' ' ' < "/proc/$pid/cmdline" 2>/dev/null)"; done
    echo "FAIL ($signal): $(echo "$left" | wc -w) process(es) of the run left behind"
    exit 1
  fi
  echo "OK ($signal): launcher and its $expected processes gone"
}

run_case HUP 4000 yes
# SIGKILL: the children get SIGTERM from the kernel (PR_SET_PDEATHSIG). A
# grandchild that left its session is not covered (it has no such signal).
run_case KILL 4010 no
echo "PASS"
