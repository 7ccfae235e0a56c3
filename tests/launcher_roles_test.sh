#!/usr/bin/env bash
# ctest launcher_roles: an optional process that fails is reported and
# restarted with back-off while the essential ones go on; an essential one that
# fails stops the run; an optional one exiting 2 (configuration error) is not
# restarted; with several processes marked ends_run (a for_each over robots),
# the run ends with the last of them. A file that uses ${input}: --show-args
# works without --input, a run without it exits 2 saying so. A program that is
# not there stops the run before anything starts (exit 2).
#   launcher_roles_test.sh LAUNCHER
set -euo pipefail
launcher=$1
work=$(mktemp -d "${TMPDIR:-/tmp}/pixyslam_launcher_roles.XXXXXX")
trap 'rm -rf "$work"' EXIT

cat > "$work/optional.yaml" <<'YAML'
launch:
  stop_timeout_s: 1
  processes:
    - name: flaky
      role: optional
      command: [/bin/sh, -c, "echo up; exit 1"]
    - name: misconfigured
      role: optional
      command: [/bin/sh, -c, "exit 2"]
    - name: essential
      command: [/bin/sh, -c, "sleep 5; echo essential done"]
      ends_run: true
YAML
fail() { echo "FAIL: $*"; exit 1; }
# run_launch NAME: runs $work/NAME.yaml into $work/NAME.log (printed); sets status and elapsed (s).
run_launch() {
  local start
  start=$(date +%s)
  status=0
  "$launcher" "$work/$1.yaml" --run-dir "$work/run_$1" > "$work/$1.log" 2>&1 || status=$?
  elapsed=$(( $(date +%s) - start ))
  cat "$work/$1.log"
}
run_launch optional
grep -q "\[essential\] essential done" "$work/optional.log" || fail "the essential process did not run to its end"
restarts=$(grep -c "restarting flaky" "$work/optional.log" || true)
# Back-off 1 + 2 s within the 5 s run: two restarts, at about 1 and 3 s (a third would come at 7 s).
[[ $restarts -ge 2 && $restarts -le 3 ]] || fail "flaky restarted $restarts times (expected 2-3 in 5 s)"
grep -q "restart in 1 s" "$work/optional.log" && grep -q "restart in 2 s" "$work/optional.log" ||
  fail "no back-off 1 s, 2 s"
grep -q "restarting misconfigured" "$work/optional.log" && fail "misconfigured (exit 2) was restarted"
grep -q "misconfigured is optional: the run goes on; not restarted" "$work/optional.log" || fail "exit 2 not reported"
[[ $status -eq 1 ]] || fail "exit code $status (expected 1: optional processes failed)"

cat > "$work/essential.yaml" <<'YAML'
launch:
  stop_timeout_s: 1
  processes:
    - name: sleeper
      command: [/bin/sleep, "30"]
    - name: broken
      command: [/bin/sh, -c, "sleep 0.5; exit 3"]
YAML
run_launch essential
grep -q "stopping after .* (a process failed)" "$work/essential.log" || fail "an essential failure did not stop the run"
[[ $elapsed -lt 10 && $status -eq 1 ]] || fail "essential failure: exit $status after $elapsed s"

cat > "$work/ends.yaml" <<'YAML'
launch:
  stop_timeout_s: 1
  arguments:
    robots: {default: '1,3', help: "robots"}
  processes:
    - name: robot${robot}
      for_each: {robot: '${robots}'}
      command: [/bin/sh, -c, "sleep ${robot}; echo robot ${robot} done"]
      ends_run: true
    - name: listener
      command: [/bin/sleep, "30"]
YAML
run_launch ends
grep -q "\[robot3\] robot 3 done" "$work/ends.log" || fail "the run ended before the last ends_run process"
grep -qF "robot1 finished; the run goes on until 1 more process(es) marked ends_run finish" "$work/ends.log" ||
  fail "the first ends_run process's end not reported"
[[ $elapsed -ge 3 && $elapsed -lt 10 && $status -eq 0 ]] || fail "ends_run: exit $status after $elapsed s"

cat > "$work/input.yaml" <<'YAML'
launch:
  arguments:
    rate: {default: '1', help: "the rate"}
  processes:
    - name: reader
      command: [/bin/echo, 'reading ${input}']
      ends_run: true
YAML
"$launcher" "$work/input.yaml" --show-args > "$work/show.log" 2>&1 || fail "--show-args without --input: $(cat "$work/show.log")"
grep -q "rate" "$work/show.log" || fail "--show-args printed no arguments: $(cat "$work/show.log")"
for shipped in launch_replay.yaml launch_mrclam.yaml; do
  "$launcher" "$(dirname "$0")/../config/$shipped" --show-args > /dev/null || fail "$shipped --show-args without --input"
done
run_launch input
grep -qF "this launch file needs --input FILE" "$work/input.log" && [[ $status -eq 2 ]] ||
  fail "a run using \${input} without --input: exit $status"
[[ ! -d $work/run_input ]] || fail "the run folder was made for a run that did not start"
"$launcher" "$work/input.yaml" --input "$work/data.txt" --run-dir "$work/run_input" > "$work/input.log" 2>&1 ||
  fail "with --input: $(cat "$work/input.log")"
grep -qF "reading $work/data.txt" "$work/input.log" || fail "\${input} not the file given: $(cat "$work/input.log")"

# A misspelt program: refused before anything starts (exit 2, naming the file
# and the process), so no process runs and no run folder is made.
cat > "$work/typo.yaml" <<YAML
launch:
  processes:
    - name: first
      command: [/bin/sh, -c, "touch $work/first_ran"]
    - name: second
      delay_s: 1
      command: [pixyslam_no_such_program, --help]
  after_run:
    - name: report
      command: [/bin/true]
YAML
run_launch typo
[[ $status -eq 2 ]] || fail "a misspelt program: exit $status, expected 2"
grep -qF "typo.yaml: launch.processes 'second': program 'pixyslam_no_such_program' not found" "$work/typo.log" ||
  fail "the error does not name the file, the process and the program"
[[ ! -e $work/first_ran && ! -d $work/run_typo ]] || fail "the run started before the misspelt program was found"
echo PASS
