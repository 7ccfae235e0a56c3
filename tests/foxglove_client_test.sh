#!/usr/bin/env bash
# ctest foxglove_client: Foxglove's own client and decoders (npm, pinned in
# tests/foxglove/package-lock.json, installed in this test's temp dir) against
#  live: foxglove_bridge on a DDS domain of its own (loopback profile, port
#        chosen by the kernel). mcap_sample_publisher writes every topic;
#        @foxglove/ws-protocol's client subscribes to every advertised channel
#        and @foxglove/omgidl-serialization decodes every message from the
#        advertised OMG IDL schema; a second connection sends 7 malformed
#        requests, each answered by a status while data keeps flowing.
#  log:  the same samples recorded by `pixyslam_log record`, converted by
#        `pixyslam_log foxglove`, read with @mcap/core and decoded the same way.
# Both cross-check each viz/landmarks and viz/tf message against the MapState
# of the same stamp (tests/foxglove/foxglove_client.mjs).
# Exit 77 (ctest SKIP) when node/npm are missing or `npm ci` fails.
#   foxglove_client_test.sh BIN_DIR SOURCE_DIR
set -euo pipefail
bin=$1 source_dir=$2
config=$source_dir/config
domain=$((60 + $$ % 40))

if ! command -v node > /dev/null || ! command -v npm > /dev/null; then
  echo "SKIP: node/npm not installed"
  exit 77
fi
work=$(mktemp -d "${TMPDIR:-/tmp}/pixyslam_foxglove.XXXXXX")
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill -INT "$pid" 2>/dev/null || true; done
  sleep 0.5
  for pid in "${pids[@]}"; do kill -KILL "$pid" 2>/dev/null || true; done
  wait 2>/dev/null || true
  if [[ -n ${KEEP_WORK:-} ]]; then echo "kept $work"; else rm -rf "$work"; fi
}
trap cleanup EXIT
trap 'exit 130' INT TERM
fail() { echo "FAIL: $*"; for f in "$work"/*.log; do echo "== $f"; tail -n 20 "$f"; done; exit 1; }

mkdir -p "$work/npm"
cp "$source_dir/tests/foxglove/package.json" "$source_dir/tests/foxglove/package-lock.json" "$work/npm/"
if ! (cd "$work/npm" && timeout 180 npm ci --no-audit --no-fund --loglevel=error --fetch-retries=1 \
        --fetch-retry-mintimeout=2000 --fetch-retry-maxtimeout=5000 --fetch-timeout=30000 > ../npm.out 2>&1); then
  echo "SKIP: npm ci failed (no registry?):"
  tail -n 5 "$work/npm.out" || true
  exit 77
fi
export FOXGLOVE_NODE_MODULES=$work/npm/node_modules
export FOXGLOVE_LAYOUT=$source_dir/docs/foxglove_layout.json
client=$source_dir/tests/foxglove/foxglove_client.mjs
data_topics=(pixyslam/odometry pixyslam/landmark_observation pixyslam/map_state pixyslam/ground_truth
             pixyslam/diagnostics pixyslam/optimised_map)
viz_topics=(pixyslam/viz/landmarks pixyslam/viz/estimate pixyslam/viz/path pixyslam/viz/tf
            pixyslam/viz/true_path pixyslam/viz/true_landmarks)

# The log exists before the bridge starts: the loop below may read it before the
# background shell has opened it.
: > "$work/bridge.log"
"$bin/foxglove_bridge" --config "$config/foxglove_bridge.yaml" --port 0 --domain "$domain" \
  > "$work/bridge.log" 2>&1 &
bridge_pid=$!
pids+=("$bridge_pid")
port=""
for _ in $(seq 100); do
  port=$(sed -n 's|.*channels on ws://127\.0\.0\.1:\([0-9]*\).*|\1|p' "$work/bridge.log")
  [[ -n $port ]] && break
  kill -0 "$bridge_pid" 2>/dev/null || fail "foxglove_bridge exited at start"
  sleep 0.1
done
[[ -n $port ]] || fail "foxglove_bridge did not say its port"
echo "foxglove_bridge on port $port, DDS domain $domain"

"$bin/pixyslam_log" record --out "$work/recording.mcap" --domain "$domain" > "$work/record.log" 2>&1 &
record_pid=$!
pids+=("$record_pid")

node "$client" live "ws://127.0.0.1:$port" 8 "${data_topics[@]}" "${viz_topics[@]}" > "$work/live.out" 2>&1 &
client_pid=$!
pids+=("$client_pid")
sleep 1
# Two readers per topic: the bridge and the recorder.
"$bin/mcap_sample_publisher" --profiles "$config/dds/profiles.xml" --domain "$domain" --count 200 --rate-hz 30 \
  --diagnostics --wait-readers 10 --readers 2 > "$work/publisher.log" 2>&1 || fail "mcap_sample_publisher failed"
live_status=0
wait "$client_pid" || live_status=$?
echo "== live (foxglove_bridge -> @foxglove/ws-protocol client)"
cat "$work/live.out"
[[ $live_status -eq 0 ]] || fail "live client: exit $live_status"

kill -INT "$record_pid" 2>/dev/null || true
wait "$record_pid" || fail "pixyslam_log record: exit $?"
kill -INT "$bridge_pid" 2>/dev/null || true
bridge_status=0
wait "$bridge_pid" || bridge_status=$?
tail -n 1 "$work/bridge.log"
[[ $bridge_status -eq 0 ]] || fail "foxglove_bridge: exit $bridge_status after SIGINT"
grep -q "(1 refused, 7 bad requests)" "$work/bridge.log" || fail "foxglove_bridge did not count the refused client and the 7 malformed requests"

"$bin/pixyslam_log" foxglove "$work/recording.mcap" "$work/foxglove.mcap" --compression none \
  > "$work/convert.log" 2>&1 || fail "pixyslam_log foxglove failed"
cat "$work/convert.log"
echo "== log (pixyslam_log foxglove -> @mcap/core + @foxglove/omgidl-serialization)"
node "$client" mcap "$work/foxglove.mcap" "${data_topics[@]}" "${viz_topics[@]}" || fail "log client"
echo "PASS"
