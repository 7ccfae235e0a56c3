#!/usr/bin/env bash
# Fault test of the whole system on loopback (a DDS domain of its own): the
# simulated robot, both bridges, the estimator (with a checkpoint file), the
# logger and the evaluator, each started by this script so that it can kill
# them. During a 60 s run:
#   encoder_bridge, pixy_bridge, slam_estimator and logger are each killed
#   with SIGKILL and restarted a second later (the logger into a new file);
#   both serial devices vanish for 1 s and come back (robot_sim unplug_at_s);
#   a second logger (logger_full) records to a disk that fills up: every file
#   it writes fails at FULL_KB (ulimit -f, SIGXFSZ ignored: writes fail like
#   on a full disk), and it retries a new file every 2 s.
# Passes if: every process runs to the end and exits 0 on SIGINT (logger_full:
# 1, naming its write failures, and every file it wrote readable); the killed
# logger's file is readable (only its open chunk lost) and so is the new one;
# no MapState holds NaN or inf; after each fault a MapState follows within
# RESUME_S of the restart; the restarted estimator resumed from its checkpoint
# with the map it had; the evaluator's ATE over the whole run is under MAX_ATE.
#   run_fault_test.sh BIN_DIR CONFIG_DIR [MAX_ATE_M]
set -euo pipefail
bin=$1 config=$2 max_ate=${3:-0.25}
resume_s=5
sim_s=60 unplug_at_s=40 unplug_for_s=1
work=$(mktemp -d /tmp/pixyslam_fault_test.XXXXXX)
declare -A pid_of
cleanup() {
  for p in "${pid_of[@]}"; do kill -KILL "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  if [[ -n ${KEEP_WORK:-} ]]; then echo "kept $work"; else rm -rf "$work"; fi
}
trap cleanup EXIT
trap 'exit 130' INT TERM  # a killed test still cleans up (the EXIT trap)

cp -r "$config" "$work/config"
domain=$((20 + $$ % 200))
sed -i "s/^  domain_id: 0/  domain_id: $domain/" "$work"/config/*.yaml
sed -i -e "s/^  duration_s: [0-9.]* /  duration_s: $sim_s /" -e "s/^  unplug_at_s: [0-9.]* /  unplug_at_s: $unplug_at_s /" \
  -e "s/^  unplug_for_s: [0-9.]* /  unplug_for_s: $unplug_for_s /" "$work/config/robot_sim.yaml"
grep -q "unplug_at_s: $unplug_at_s " "$work/config/robot_sim.yaml" || { echo "FAIL: cannot set unplug_at_s"; exit 1; }
cfg=$work/config dev=$work/dev
mkdir -p "$dev"
full_kb=${FULL_KB:-150}
sed -e "s/^  retry_period_s: [0-9.]* /  retry_period_s: 2 /" -e "s/^  flush_period_s: [0-9.]* /  flush_period_s: 0.5 /" \
  "$cfg/logger.yaml" > "$cfg/logger_full.yaml"
grep -q "retry_period_s: 2 " "$cfg/logger_full.yaml" || { echo "FAIL: cannot set retry_period_s"; exit 1; }

now_ns() { date +%s%N; }
logger_runs=0
start() {  # start NAME: the process NAME in the background, output appended to NAME.log
  local name=$1
  case $name in
    logger) logger_runs=$((logger_runs + 1))
            set -- "$bin/logger" --config "$cfg/logger.yaml" --out "$work/run_$logger_runs.mcap" ;;
    logger_full) mkdir -p "$work/full"
            set -- bash -c "trap '' XFSZ; ulimit -f $full_kb; exec \"\$@\"" logger_full \
              "$bin/logger" --config "$cfg/logger_full.yaml" --out "$work/full/run.mcap" ;;
    slam_estimator) set -- "$bin/slam_estimator" --config "$cfg/slam_estimator.yaml" --out-dir "$work/estimator" \
                      --checkpoint "$work/checkpoint.yaml" ;;
    evaluator) set -- "$bin/sim_evaluator" --config "$cfg/slam_estimator.yaml" --out-dir "$work/evaluator" \
                 --max-ate "$max_ate" ;;
    encoder_bridge) set -- "$bin/encoder_bridge" --config "$cfg/encoder_bridge.yaml" --device "$dev/arduino" ;;
    pixy_bridge) set -- "$bin/pixy_bridge" --config "$cfg/pixy_bridge.yaml" --device "$dev/pixy" ;;
    robot_sim) set -- "$bin/robot_sim" --config "$cfg/robot_sim.yaml" --arduino-link "$dev/arduino" \
                 --pixy-link "$dev/pixy" ;;
  esac
  echo "=== start $(now_ns)" >> "$work/$name.log"
  "$@" >> "$work/$name.log" 2>&1 &
  pid_of[$name]=$!
}
fail() { echo "FAIL: $*"; exit 1; }
alive() { kill -0 "${pid_of[$1]}" 2>/dev/null; }

for p in logger logger_full slam_estimator evaluator encoder_bridge pixy_bridge; do start "$p"; done
sleep 1
start robot_sim
t0=$(date +%s.%N)
at() {  # at SECONDS: sleep until SECONDS after the robot started
  local wait_s
  wait_s=$(awk -v t0="$t0" -v now="$(date +%s.%N)" -v at="$1" 'BEGIN { d = t0 + at - now; print (d > 0 ? d : 0) }')
  sleep "$wait_s"
}

faults=()   # "name restart_ns"
kill_and_restart() {  # kill_and_restart NAME AT_S DOWN_S
  at "$2"
  alive "$1" || fail "$1 died before its fault (see below)"
  kill -KILL "${pid_of[$1]}"
  wait "${pid_of[$1]}" 2>/dev/null || true
  sleep "$3"
  start "$1"
  faults+=("$1 $(now_ns)")
  echo "t $2 s: $1 killed (SIGKILL), restarted $3 s later"
}
kill_and_restart encoder_bridge 8 1
kill_and_restart pixy_bridge 14 1
# As systemd's Restart=always with RestartSec=0.2 would: the robot moves on
# meanwhile, and the resumed pose's uncertainty grows with the gap.
kill_and_restart slam_estimator 20 0.2
kill_and_restart logger 27 1
at $((unplug_at_s + unplug_for_s))
faults+=("serial_unplug $(now_ns)")
echo "t $((unplug_at_s + unplug_for_s)) s: serial devices back"

robot_status=0
wait "${pid_of[robot_sim]}" || robot_status=$?
sleep 2  # the last samples reach the estimator, evaluator and logger
declare -A status_of
for p in encoder_bridge pixy_bridge slam_estimator evaluator logger logger_full; do
  alive "$p" || { tail -20 "$work/$p.log"; fail "$p is not running at the end of the run"; }
  kill -INT "${pid_of[$p]}"
  status_of[$p]=0
  wait "${pid_of[$p]}" || status_of[$p]=$?
done
for p in robot_sim encoder_bridge pixy_bridge slam_estimator evaluator logger logger_full; do
  grep -v "robot_sim: t [0-9]* s, \|status: " "$work/$p.log" | sed "s/^/[$p] /"
done
[[ $robot_status -eq 0 ]] || fail "robot_sim exited with $robot_status"
for p in "${!status_of[@]}"; do
  [[ $p == logger_full ]] && continue
  [[ ${status_of[$p]} -eq 0 ]] || fail "$p exited with ${status_of[$p]}"
done

# The logger on the full disk: ran to the end, exit 1 naming the failures, and
# every file it wrote readable up to its failure.
[[ ${status_of[logger_full]} -eq 1 ]] || fail "logger_full exited with ${status_of[logger_full]} (expected 1)"
grep -q "write failure(s), samples lost while not recording" "$work/logger_full.log" ||
  fail "logger_full did not report its write failures"
full_files=0 full_states=0
for f in "$work"/full/run*.mcap; do
  n=$("$bin/pixyslam_log" print "$f" --topics pixyslam/map_state --json 2>/dev/null | wc -l || true)
  [[ $n -gt 0 ]] || fail "$f (written on the full disk) holds no readable MapState"
  full_files=$((full_files + 1)) full_states=$((full_states + n))
done
[[ $full_files -ge 3 ]] || fail "logger_full wrote $full_files file(s): expected a new one after each failure"
echo "full disk: $full_files files of at most $full_kb KB, $full_states MapStates readable, $(grep -c 'logger: ERROR' "$work/logger_full.log") write failures"

# Both logs readable: the killed logger's file loses at most its open chunk.
for f in "$work/run_1.mcap" "$work/run_2.mcap"; do
  "$bin/pixyslam_log" info "$f" > "$work/info.txt" 2>&1 || { cat "$work/info.txt"; fail "$f is not readable"; }
  echo "$(basename "$f"): $(grep -ciE "recovered|chunk" "$work/info.txt" || true) info lines on recovery; $(head -c 300 "$work/info.txt" | tr '\n' ' ')"
  "$bin/pixyslam_log" print "$f" --topics pixyslam/map_state --json >> "$work/map_states.jsonl" ||
    fail "cannot print the MapStates of $f"
done
states=$(wc -l < "$work/map_states.jsonl")
[[ $states -gt 100 ]] || fail "only $states MapStates logged"
if grep -qiE '(nan|inf)[,}\]]' "$work/map_states.jsonl"; then fail "a MapState holds NaN or inf"; fi
echo "MapStates logged: $states, none with NaN or inf"

# After each fault a MapState within resume_s.
printf '%-16s %s\n' fault "first MapState after the restart"
log_times=$(grep -oE '"log_time_ns":[0-9]+' "$work/map_states.jsonl" | grep -oE '[0-9]+' | sort -n)
for f in "${faults[@]}"; do
  name=${f% *} restart_ns=${f#* }
  first=$(awk -v t="$restart_ns" '$1 > t { print; exit }' <<< "$log_times")
  [[ -n $first ]] || fail "no MapState after $name came back"
  ms=$(( (first - restart_ns) / 1000000 ))
  printf '%-16s %d ms\n' "$name" "$ms"
  [[ $ms -le $((resume_s * 1000)) ]] || fail "MapState resumed only $ms ms after $name came back"
done

# The estimator restarted from its checkpoint, with the map it had.
grep -q "slam_estimator: resumed from $work/checkpoint.yaml" "$work/slam_estimator.log" ||
  fail "the restarted estimator did not resume from its checkpoint"
resumed_landmarks=$(grep -oE "resumed from .*: [0-9.]+ s old, [0-9]+ landmarks" "$work/slam_estimator.log" |
  grep -oE '[0-9]+ landmarks' | grep -oE '[0-9]+')
[[ $resumed_landmarks -ge 5 ]] || fail "the estimator resumed with only $resumed_landmarks landmarks"
# The bridges saw their devices hang up and reopened them.
for p in encoder_bridge pixy_bridge; do
  grep -q "hung up" "$work/$p.log" || fail "$p did not notice its device going away"
done
ate=$(grep -oE "pose ATE RMSE +[0-9.]+" "$work/evaluator.log" | tail -1 | grep -oE '[0-9.]+$')
echo "evaluator ATE over the whole run: $ate m (limit $max_ate m)"
echo "PASS"
