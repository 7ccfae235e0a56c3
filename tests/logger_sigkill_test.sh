#!/usr/bin/env bash
# ctest logger_sigkill: the logger process killed with SIGKILL mid-run loses
# only its open chunk. Starts `logger` (4 KiB chunks, zstd, flush every 0.2 s)
# on a DDS domain of its own with the loopback profile, publishes Odometry at
# RATE Hz (seq 1, 2, ...) with mcap_sample_publisher, kill -9s the logger after
# KILL_AFTER_S, then reads the file with McapReader (mcap_recovery_check): no
# chunk rejected, seq exactly 1..K in order, K >= sent - RATE*(flush+0.5 s).
#   logger_sigkill_test.sh LOGGER PUBLISHER RECOVERY_CHECK SOURCE_DIR
set -euo pipefail
logger=$1 publisher=$2 check=$3 source_dir=$4
rate=${RATE:-500}
kill_after_s=${KILL_AFTER_S:-3}
flush_period_s=0.2
domain=$((150 + $$ % 80))

work=$(mktemp -d "${TMPDIR:-/tmp}/pixyslam_sigkill.XXXXXX")
logger_pid="" publisher_pid=""
cleanup() {
  [[ -n $publisher_pid ]] && kill "$publisher_pid" 2>/dev/null || true
  [[ -n $logger_pid ]] && kill -9 "$logger_pid" 2>/dev/null || true
  wait 2>/dev/null || true
  if [[ -n ${KEEP_WORK:-} ]]; then echo "kept $work"; else rm -rf "$work"; fi
}
trap cleanup EXIT
trap 'exit 130' INT TERM  # a killed test still cleans up (the EXIT trap)

cat > "$work/logger.yaml" <<YAML
logger:
  output_file: $work/killed.mcap
  topics: [pixyslam/odometry]
  chunk_size_bytes: 4096
  compression: zstd
  flush_period_s: $flush_period_s
dds:
  domain_id: $domain
  profiles_file: $source_dir/config/dds/profiles.xml
  robot_id: sigkill_test
YAML

"$logger" --config "$work/logger.yaml" > "$work/logger.out" 2> "$work/logger.err" &
logger_pid=$!
"$publisher" --profiles "$source_dir/config/dds/profiles.xml" --domain "$domain" --topics odometry \
  --count $((rate * 60)) --rate-hz "$rate" > "$work/publisher.out" 2> "$work/publisher.err" &
publisher_pid=$!

# Publishing starts once the logger's reader matched: wait for the first progress line.
for _ in $(seq 200); do
  grep -q '^progress' "$work/publisher.out" 2>/dev/null && break
  kill -0 "$publisher_pid" 2>/dev/null || { cat "$work/publisher.err" "$work/logger.err"; exit 1; }
  sleep 0.1
done
grep -q '^progress' "$work/publisher.out" || { echo "publisher never started"; cat "$work/logger.err"; exit 1; }
sleep "$kill_after_s"
kill -9 "$logger_pid" 2>/dev/null || { echo "FAIL: the logger had exited before the kill"; cat "$work/logger.err"; exit 1; }
sent=$(grep '^progress' "$work/publisher.out" | tail -n 1 | cut -d' ' -f2)
wait "$logger_pid" 2>/dev/null || true
logger_pid=""
kill "$publisher_pid" 2>/dev/null || true
wait "$publisher_pid" 2>/dev/null || true
publisher_pid=""
# `sent` was read just after the kill: up to 10 more may have gone out before it (progress every 10).
sent=$((sent > 10 ? sent - 10 : 0))
max_loss=$(awk -v r="$rate" -v f="$flush_period_s" 'BEGIN { printf "%d", r * (f + 0.5) }')
echo "logger killed (SIGKILL) after ${kill_after_s} s at $rate Hz; at least $sent Odometry messages sent"
ls -l "$work/killed.mcap"
"$check" "$work/killed.mcap" --topic pixyslam/odometry --sent "$sent" --max-loss "$max_loss" --expect-footer 0
