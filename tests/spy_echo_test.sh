#!/usr/bin/env bash
# Integration test of pixyslam_spy on loopback, on a DDS domain of its own:
# spy_test_publisher publishes Odometry whose values follow from header.seq;
# `echo --json --count 3` must print exactly those values (every field),
# `echo` (YAML) one document, `echo` of a topic with a kept history (30
# MapStates) the newest, `participants` the publisher with its pid and
# host, `topics` its writer with the QoS of the profile, `hz` a rate; with
# --json the same facts as JSON lines (parsed with python3's json); `record`
# of two topics by pattern holds the publisher's samples and the kept history.
#   spy_echo_test.sh SPY PUBLISHER CONFIG_DIR
set -euo pipefail
spy=$1 publisher=$2 config=$3
work=$(mktemp -d /tmp/pixyslam_spy_test.XXXXXX)
pub_pid=""
cleanup() {
  if [[ -n "$pub_pid" ]] && kill -0 "$pub_pid" 2>/dev/null; then
    kill -TERM "$pub_pid" 2>/dev/null || true
    wait "$pub_pid" 2>/dev/null || true
  fi
  rm -rf "$work"
}
trap cleanup EXIT
trap 'exit 130' INT TERM  # a killed test still cleans up (the EXIT trap)
cp -r "$config" "$work/config"
domain=$((20 + $$ % 100))
sed -i "s/^  domain_id: 0/  domain_id: $domain/" "$work"/config/*.yaml
cfg="$work/config/encoder_bridge.yaml"
fail() { echo "FAIL: $*"; exit 1; }

"$publisher" --config "$cfg" --rate-hz 20 --map-states 30 > "$work/publisher.log" 2>&1 &
pub_pid=$!
for _ in $(seq 100); do  # its participant and writer exist once it says so
  grep -q "publishing on domain" "$work/publisher.log" && break
  kill -0 "$pub_pid" 2>/dev/null || break
  sleep 0.1
done
grep -q "publishing on domain" "$work/publisher.log" || { cat "$work/publisher.log"; fail "publisher did not start"; }

echo "== participants"
"$spy" participants --config "$cfg" --duration 4 | tee "$work/participants.txt"
grep -Eq "^spy_test_publisher +[0-9a-f.]+ +$(hostname | cut -c1-15)[^ ]* +$pub_pid +spy_test_publis" \
  "$work/participants.txt" || fail "participants does not show spy_test_publisher with pid $pub_pid"

echo "== participants --json"
"$spy" participants --config "$cfg" --duration 3 --json | tee "$work/participants.json"
python3 -c 'import json, sys
rows = [json.loads(l) for l in open(sys.argv[1])]
assert any(r["name"] == "spy_test_publisher" and r["pid"] == sys.argv[2] for r in rows), rows' \
  "$work/participants.json" "$pub_pid" || fail "participants --json does not list spy_test_publisher with pid $pub_pid"

echo "== echo --json --count 3"
"$spy" echo pixyslam/odometry --config "$cfg" --json --count 3 --duration 20 | tee "$work/echo.json"
[[ $(wc -l < "$work/echo.json") -eq 3 ]] || fail "expected 3 JSON lines"
previous=0
while IFS= read -r line; do
  seq=$(grep -oE '"seq":[0-9]+' <<< "$line" | cut -d: -f2)
  [[ -n "$seq" && "$seq" -gt "$previous" ]] || fail "no increasing seq in: $line"
  previous=$seq
  expected="{\"header\":{\"stamp_ns\":$((1000000000000000000 + seq)),\"seq\":$seq,\"robot_id\":\"robot1\",\"frame_id\":\"base_link\"},\"v_mps\":$seq.5,\"w_radps\":-$seq.25,\"period_s\":0.1,\"distance_m\":$((2 * seq)),\"rotation_rad\":1e-09,\"encoder_samples\":$((seq + 3))}"
  [[ "$line" == "$expected" ]] || fail "echo printed
  $line
expected
  $expected"
done < "$work/echo.json"

echo "== echo (YAML) --count 1"
"$spy" echo pixyslam/odometry --domain "$domain" --count 1 --duration 20 | tee "$work/echo.yaml"
seq=$(grep -oE '^  seq: [0-9]+' "$work/echo.yaml" | grep -oE '[0-9]+')
[[ -n "$seq" ]] || fail "no header.seq in the YAML document"
grep -qx -- "---" "$work/echo.yaml" || fail "no YAML document start"
grep -qx "v_mps: $seq.5" "$work/echo.yaml" || fail "v_mps of seq $seq"
grep -qx "encoder_samples: $((seq + 3))" "$work/echo.yaml" || fail "encoder_samples of seq $seq"

echo "== echo of a kept history (30 MapStates, transient local) --count 1: the newest"
"$spy" echo pixyslam/map_state --domain "$domain" --json --count 1 --duration 20 | tee "$work/map.json"
grep -q '"seq":30,' "$work/map.json" || fail "echo printed another MapState than the newest (seq 30)"

echo "== topics"
"$spy" topics --config "$cfg" --duration 4 | tee "$work/topics.txt"
grep -q "^pixyslam/odometry  \[pixyslam::msg::Odometry\]" "$work/topics.txt" || fail "topics: no odometry topic"
grep -Eq "^  writer +spy_test_publisher \(pid $pub_pid\) +reliable +volatile +history keep_all" "$work/topics.txt" \
  || fail "topics: no writer line of the publisher"

echo "== topics --json"
"$spy" topics --config "$cfg" --duration 3 --json | tee "$work/topics.json"
python3 -c 'import json, sys
rows = [json.loads(l) for l in open(sys.argv[1])]
odo = [r for r in rows if r["topic"] == "pixyslam/odometry"]
assert odo and odo[0]["type"] == "pixyslam::msg::Odometry" and odo[0]["writers"] >= 1, rows
w = [e for e in odo[0]["endpoints"] if e["kind"] == "writer" and "spy_test_publisher" in e["participant"]]
assert w and w[0]["reliability"] == "reliable" and w[0]["durability"] == "volatile", odo' \
  "$work/topics.json" || fail "topics --json: no odometry writer of the publisher"

echo "== hz --json"
"$spy" hz pixyslam/odometry --config "$cfg" --duration 2.5 --json | tee "$work/hz.json"
python3 -c 'import json, sys
rows = [json.loads(l) for l in open(sys.argv[1])]
assert len(rows) >= 2 and "last_second" in rows[0], rows
assert rows[-1]["topic"] == "pixyslam/odometry" and 5 < rows[-1]["rate_hz"] < 40, rows[-1]' \
  "$work/hz.json" || fail "hz --json: no per-second line or no rate near 20 Hz"

echo "== hz"
"$spy" hz pixyslam/odometry --config "$cfg" --duration 2 | tee "$work/hz.txt"
rate=$(grep -oE 'rate [0-9.]+' "$work/hz.txt" | grep -oE '[0-9.]+' || true)
[[ -n "$rate" ]] || fail "hz printed no rate"
awk -v r="$rate" 'BEGIN { exit !(r > 5 && r < 40) }' || fail "hz rate $rate Hz not near 20 Hz"

echo "== record (like ros2 bag record): two topics by pattern, --duration"
"$spy" record 'pixyslam/*' '!pixyslam/diagnostics' '!pixyslam/ground_truth' '!pixyslam/landmark_observation' \
  '!pixyslam/optimised_map' '!pixyslam/robot_sighting' '!pixyslam/fleet_map' --domain "$domain" --duration 4 \
  --out "$work/rec.mcap" 2> "$work/record.log" \
  || { status=$?; cat "$work/record.log"; fail "record exited $status"; }
cat "$work/record.log"
grep -q "recording 2 topics to $work/rec.mcap" "$work/record.log" || fail "record did not select 2 topics"
grep -q "stopped after 4 s" "$work/record.log" || fail "record did not stop after --duration"
"$spy" print "$work/rec.mcap" --json > "$work/rec.json"
python3 -c 'import json, sys
rows = [json.loads(l) for l in open(sys.argv[1])]
odo = [r for r in rows if r["topic"] == "pixyslam/odometry"]
maps = [r for r in rows if r["topic"] == "pixyslam/map_state"]
assert len(odo) >= 20, len(odo)  # 20 Hz for 4 s, of which discovery may take up to 3 s on a loaded machine
for r in odo:
    m = r["message"]; s = m["header"]["seq"]
    assert m["v_mps"] == s + 0.5 and m["encoder_samples"] == s + 3, m
assert [r["message"]["header"]["seq"] for r in maps] == list(range(1, 31)), maps  # the kept history' \
  "$work/rec.json" || fail "the recording does not hold the publisher's samples"
status=0
"$spy" record pixyslam/nothing --domain "$domain" --duration 1 --out "$work/bad.mcap" 2>/dev/null || status=$?
[[ $status -eq 2 && ! -e "$work/bad.mcap" ]] || fail "record of an unknown topic gave $status, expected 2 and no file"

echo "== unknown topic"
status=0
"$spy" echo pixyslam/nothing --config "$cfg" --count 1 --duration 1 2>/dev/null || status=$?
[[ $status -eq 2 ]] || fail "unknown topic gave exit status $status, expected 2"
echo "PASS"
