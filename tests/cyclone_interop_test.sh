#!/usr/bin/env bash
# Another vendor's DDS with its default configuration, both directions, every
# topic. Two network namespaces made by this test, joined by a veth pair
# (10.201.N.1 and .2, multicast routed on it): in "fast", mcap_sample_publisher
# writes N samples of every topic (Diagnostics too) on domain D with the
# shipped lan_multicast profile and the project's default settings (only the
# interface named), and `pixyslam_log record` records domain D ("direct") and
# domain D+1 ("relayed"); in "cyc", cyclone_relay (Cyclone DDS, no
# CYCLONEDDS_URI: its default configuration) reads every topic on D and writes
# each sample on D+1. Passes if every topic holds seq 1..N in both recordings
# and the relayed samples equal the direct ones field by field.
# Needs root (ip netns); exits 77 (skip) without it or without cyclone_relay.
#   cyclone_interop_test.sh BIN_DIR RELAY CONFIG_DIR [N]
set -euo pipefail
bin=$1 relay=$2 config=$3 count=${4:-200}
if [[ $(id -u) -ne 0 ]] || ! command -v ip >/dev/null || ! ip netns list >/dev/null 2>&1; then
  echo "SKIP: needs root and iproute2 (network namespaces)"
  exit 77
fi
[[ -x $relay ]] || { echo "SKIP: no cyclone_relay (apt install cyclonedds-dev cyclonedds-tools, then rebuild)"; exit 77; }

source "$(dirname "$0")/support/netns_lib.sh"
tag=pxc$$
net=$((10 + $$ % 240))
domain=$((100 + $$ % 60))
work=$(mktemp -d /tmp/pixyslam_cyclone.XXXXXX)
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill -INT "$pid" 2>/dev/null || true; done
  sleep 0.5
  for pid in "${pids[@]}"; do kill -KILL "$pid" 2>/dev/null || true; done
  netns_remove "$tag" fast cyc
  rm -rf "$work"
}
trap cleanup EXIT
trap 'exit 130' INT TERM
fail() { echo "FAIL: $*"; for f in "$work"/*.log; do echo "== $f"; cat "$f"; done; exit 1; }

netns_add "${tag}_fast"
netns_add "${tag}_cyc"
ip link add eth0 netns "${tag}_fast" type veth peer name eth0 netns "${tag}_cyc"
i=1
for h in fast cyc; do
  ip -n "${tag}_$h" link set lo up
  ip -n "${tag}_$h" addr add "10.201.$net.$i/24" dev eth0
  ip -n "${tag}_$h" link set eth0 up
  ip -n "${tag}_$h" route add 224.0.0.0/4 dev eth0
  i=$((i + 1))
done
fast=(ip netns exec "${tag}_fast" env PIXYSLAM_DDS_PROFILE=lan_multicast PIXYSLAM_DDS_INTERFACES=10.201.$net.1
  PIXYSLAM_DDS_PROFILES_FILE="$config/dds/profiles.xml")
echo "namespaces ${tag}_fast (Fast DDS, lan_multicast) and ${tag}_cyc (Cyclone DDS defaults), domains $domain -> $((domain + 1))"

record() {  # record DOMAIN NAME: every topic, no diagnostics of its own
  "${fast[@]}" "$bin/pixyslam_log" record --domain "$1" --out "$work/$2.mcap" \
    --set dds.diagnostics_period_s=0 > "$work/$2.log" 2>&1 &
  pids+=($!)
}
record "$domain" direct
record $((domain + 1)) relayed
# The relay is ready once its writers matched the relayed recorder's readers;
# the publisher then waits for two readers per topic: the direct recorder's and the relay's.
ip netns exec "${tag}_cyc" env -u CYCLONEDDS_URI "$relay" "$domain" $((domain + 1)) 90 > "$work/relay.log" 2>&1 &
pids+=($!)
relay_pid=$!
for _ in $(seq 400); do grep -q ready "$work/relay.log" && break; kill -0 "$relay_pid" 2>/dev/null || break; sleep 0.1; done
grep -q ready "$work/relay.log" || fail "cyclone_relay did not match the recorder on domain $((domain + 1))"
"${fast[@]}" "$bin/mcap_sample_publisher" --profiles "$config/dds/profiles.xml" --domain "$domain" \
  --count "$count" --rate-hz 100 --topics all --diagnostics --readers 2 --wait-readers 30 > "$work/publisher.log" 2>&1 ||
  fail "publisher (no Cyclone reader matched, or samples not acknowledged)"
sleep 1  # the last samples reach the relay
# The relay first: it waits for the relayed recorder's acknowledgments.
kill -INT "$relay_pid" 2>/dev/null || true
status=0
wait "$relay_pid" || status=$?
((status == 0)) || fail "cyclone_relay exited $status (its samples not all acknowledged?)"
kill -INT "${pids[@]:0:2}" 2>/dev/null || true
for pid in "${pids[@]:0:2}"; do status=0; wait "$pid" || status=$?; ((status == 0)) || fail "a recorder exited $status"; done
pids=()
cat "$work/relay.log"

topics=(pixyslam/odometry pixyslam/landmark_observation pixyslam/map_state pixyslam/ground_truth
  pixyslam/diagnostics pixyslam/optimised_map pixyslam/robot_sighting pixyslam/fleet_map)
expect=()
for t in "${topics[@]}"; do expect+=(--expect "$t=$count"); done
for name in direct relayed; do
  "$bin/pixyslam_log" check "$work/$name.mcap" "${expect[@]}" > "$work/check_$name.log" 2>&1 ||
    fail "$name recording: not seq 1..$count on every topic"
done
for t in "${topics[@]}"; do
  "$bin/pixyslam_log" compare "$work/direct.mcap" "$work/relayed.mcap" --topic "$t" > "$work/compare.log" 2>&1 ||
    fail "$t: the samples Cyclone relayed differ from the ones Fast DDS wrote"
  echo "$t: $count samples Fast DDS -> Cyclone -> Fast DDS, every field equal"
done
echo "PASS"
