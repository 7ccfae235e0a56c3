#!/usr/bin/env bash
# The system across three "hosts": network namespaces robot, laptop and
# server made by this test, each with one veth into a bridge (in a fourth
# namespace, the "switch"), addresses 10.200.N.1-3/24. pixyslam_launch runs
# with a deployment file per host: simulator and bridges on robot; estimator,
# logger, evaluator and map view on laptop; `fastdds discovery` on server for
# the discovery_client profile. Mid-run the robot's link goes down for 5 s.
# Passes if: every launcher ends cleanly (evaluator ATE within MAX_ATE, log
# check, final map), the log on the laptop holds every message each robot
# publisher sent (seq 1..N: nothing lost over the cut), MapState resumes within
# 5 s of the link coming back, and a capture on the robot's link shows the
# payload in the clear (plain profiles) or never (secure; where also a
# participant without a valid certificate must receive nothing).
# LINK_SCHEDULE=T:LOSS:DELAY_MS,... (with LINK_EMULATOR=path): the robot's link
# is a TAP pair joined by link_emulator, which drops and delays frames by that
# schedule (tc netem's job, on kernels without it), and there is no cut; then
# MapState must keep arriving in every phase (no gap over 3 s) instead.
# RUNNER=podman: the same with every host a container (images from
# docker/build_images.sh) in its namespace: hosts robot, estimator, logger
# and viewer, one per image, sharing one run folder.
# Needs root (ip netns); exits 77 (skip) without it. Removes all it made.
#   [RUNNER=podman] run_distributed_test.sh BIN_DIR CONFIG_DIR SCRIPTS_DIR PROFILE [MAX_ATE_M]
set -euo pipefail
bin=$1 config=$2 scripts=$3 profile=$4 max_ate=${5:-0.15}
source "$(dirname "$0")/support/netns_lib.sh"
runner=${RUNNER:-native}
sim_s=30 cut_at_s=12 cut_s=5

if [[ $(id -u) -ne 0 ]] || ! command -v ip >/dev/null || ! ip netns list >/dev/null 2>&1; then
  echo "SKIP: needs root and iproute2 (network namespaces)"
  exit 77
fi
capture_tool=""
if command -v tcpdump >/dev/null; then capture_tool=tcpdump; elif command -v tshark >/dev/null; then capture_tool=tshark; fi

tag=pxs$$
net=$((10 + $$ % 240))
if [[ $runner == podman ]]; then
  hosts=(robot estimator logger viewer)
  stop_order=(estimator logger viewer)  # the logger after the estimator, the final map after the log
  log_host=logger log_addr=10.200.$net.3
  command -v podman >/dev/null || { echo "SKIP: podman is not installed"; exit 77; }
  export CONTAINERS_CONF=${CONTAINERS_CONF:-$scripts/../docker/containers.conf}
  for role in robot estimator logger viewer; do
    podman image exists "localhost/pixyslam-$role:latest" ||
      { echo "SKIP: image pixyslam-$role missing (docker/build_images.sh)"; exit 77; }
  done
else
  hosts=(robot laptop server)
  stop_order=(laptop server)
  log_host=laptop log_addr=10.200.$net.2
fi
work=$(mktemp -d /tmp/pixyslam_distributed.XXXXXX)
if [[ $runner == podman ]]; then
  # The containers run as their packages' user: they read the config and write the run folder.
  chmod 755 "$work"
  install -d -m 1777 "$work/run"
fi
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill -INT "$pid" 2>/dev/null || true; done
  sleep 1
  for pid in "${pids[@]}"; do kill -KILL "$pid" 2>/dev/null || true; done
  if [[ $runner == podman ]]; then
    for h in "${hosts[@]}"; do podman rm -f "${tag}_$h" > /dev/null 2>&1 || true; done
  fi
  netns_remove "$tag" "${hosts[@]}"
  rm -rf "$work"
}
trap cleanup EXIT
trap 'exit 130' INT TERM  # a killed test still cleans up (the EXIT trap)

# The network: one bridge, one veth per host (the robot's link emulated when asked).
link_schedule=${LINK_SCHEDULE:-}
netns_switch "$tag"
i=0
for h in "${hosts[@]}"; do
  i=$((i + 1))
  if [[ -n $link_schedule && $h == robot ]]; then
    netns_add "${tag}_$h"
    "$LINK_EMULATOR" --a "${tag}_robot:eth0" --b "${tag}_sw:v_robot" --schedule "$link_schedule" \
      > "$work/link_emulator.log" 2>&1 &
    emulator=$!
    pids+=($emulator)
    for _ in $(seq 50); do grep -q ready "$work/link_emulator.log" && break; sleep 0.1; done
    grep -q ready "$work/link_emulator.log" || { cat "$work/link_emulator.log"; echo "FAIL: link_emulator"; exit 1; }
    netns_attach "$tag" "$h" "10.200.$net.$i/24"
  else
    netns_host "$tag" "$h" "10.200.$net.$i/24"
  fi
done
echo "namespaces ${tag}_{${hosts[*]}, sw}, network 10.200.$net.0/24, profile $profile, runner $runner"

cp -r "$config" "$work/config"
sed -i "s/^  duration_s: [0-9.]* /  duration_s: $sim_s /" "$work/config/robot_sim.yaml"
sed -i -E "s/--max-ate, '[0-9.]+'/--max-ate, '$max_ate'/" "$work/config/launch_sim.yaml"
extra=""
if [[ $profile == discovery_client ]]; then extra="  discovery_server: {host: server, port: 11811, id: 0}"; fi
if [[ $profile == secure ]]; then
  "$scripts/make_dds_security.sh" "$work/security" > /dev/null
  "$scripts/make_dds_security.sh" "$work/intruder" pixyslam_spy > /dev/null  # another CA
  extra="  security_dir: $work/security"
fi
if [[ $runner == podman ]]; then
  assignment="    robot:     {address: 10.200.$net.1, processes: [encoder_bridge, pixy_bridge, robot_sim]}
    estimator: {address: 10.200.$net.2, processes: [slam_estimator]}
    logger:    {address: 10.200.$net.3, processes: [logger, evaluator, map_optimizer, log_check]}
    viewer:    {address: 10.200.$net.4, processes: [map_view, final_map]}"
else
  assignment="    robot:  {address: 10.200.$net.1, processes: [encoder_bridge, pixy_bridge, robot_sim]}
    laptop: {address: 10.200.$net.2, processes: [logger, slam_estimator, map_optimizer, evaluator, map_view, log_check, final_map]}
    server: {address: 10.200.$net.3, processes: []}"
fi
cat > "$work/deploy.yaml" <<EOF
deployment:
  profile: $profile
  domain_id: 0
$extra
  hosts:
$assignment
EOF

declare -A launcher_of
launch() {  # launch HOST: that host's share, in its namespace, in the background
  if [[ $runner == podman ]]; then
    # One run folder for all (the viewer renders the logger's file); the
    # container's programs are its own (its packages', run as user pixyslam,
    # who writes the run folder).
    podman run --rm --name "${tag}_$1" --network "ns:/run/netns/${tag}_$1" -v "$work:$work" \
      "localhost/pixyslam-$1:latest" "$work/config/launch_sim.yaml" --deployment "$work/deploy.yaml" \
      --host "$1" --run-dir "$work/run" > "$work/$1.log" 2>&1 &
  else
    ip netns exec "${tag}_$1" "$bin/pixyslam_launch" "$work/config/launch_sim.yaml" \
      --deployment "$work/deploy.yaml" --host "$1" --run-dir "$work/$1" > "$work/$1.log" 2>&1 &
  fi
  pids+=($!)
  launcher_of[$1]=$!
}
if [[ -n $capture_tool ]]; then
  if [[ $capture_tool == tcpdump ]]; then
    ip netns exec "${tag}_sw" tcpdump -i v_robot -U -w "$work/robot_link.pcap" > "$work/capture.log" 2>&1 &
  else
    ip netns exec "${tag}_sw" tshark -i v_robot -w "$work/robot_link.pcap" > "$work/capture.log" 2>&1 &
  fi
  capture=$!
  pids+=($capture)
fi
for h in "${stop_order[@]}"; do launch "$h"; done
sleep 2
launch robot
robot_launcher=${launcher_of[robot]}
start=$(date +%s)

if [[ $profile == secure ]]; then
  # Intruders on the laptop: no security at all, and certificates of another CA.
  sleep 4
  ip netns exec "${tag}_$log_host" env PIXYSLAM_DDS_PROFILE=lan_peers PIXYSLAM_DDS_INTERFACES=$log_addr \
    PIXYSLAM_DDS_PEERS=10.200.$net.1,$log_addr \
    "$bin/pixyslam_spy" echo pixyslam/odometry --count 1 --duration 5 > "$work/intruder_plain.txt" 2>&1 &
  plain=$!
  ip netns exec "${tag}_$log_host" env PIXYSLAM_DDS_PROFILE=secure PIXYSLAM_DDS_SECURITY_DIR="$work/intruder" \
    PIXYSLAM_DDS_INTERFACES=$log_addr PIXYSLAM_DDS_PEERS=10.200.$net.1,$log_addr \
    "$bin/pixyslam_spy" echo pixyslam/odometry --count 1 --duration 5 > "$work/intruder_ca.txt" 2>&1 &
  other_ca=$!
  plain_status=0; wait "$plain" || plain_status=$?
  ca_status=0; wait "$other_ca" || ca_status=$?
fi

# A process that crashes: a DDS participant on the robot, killed with SIGKILL
# after the link cut; the other hosts' launchers must report it LOST.
robot_env=(PIXYSLAM_DDS_PROFILE=$profile PIXYSLAM_DDS_INTERFACES=10.200.$net.1
           "PIXYSLAM_DDS_PEERS=$(grep -oE '10\.200\.[0-9]+\.[0-9]+' "$work/deploy.yaml" | paste -sd,)")
if [[ $profile == discovery_client ]]; then
  robot_env+=(PIXYSLAM_DDS_SERVER=10.200.$net.3:11811 PIXYSLAM_DDS_TYPE_INFORMATION=false)
fi
if [[ $profile == secure ]]; then robot_env+=(PIXYSLAM_DDS_SECURITY_DIR=$work/security); fi
ip netns exec "${tag}_robot" env "${robot_env[@]}" "$bin/pixyslam_spy" hz pixyslam/odometry --duration 60 \
  > "$work/doomed.log" 2>&1 &
doomed=$!
pids+=($doomed)

# Cut the robot's link for cut_s seconds (not when it is emulated).
# Late under load: no sleep rather than a negative one (`sleep -1` fails the test).
until_cut_s=$((cut_at_s - ($(date +%s) - start)))
((until_cut_s <= 0)) || sleep "$until_cut_s"
if [[ -z $link_schedule ]]; then
  ip -n "${tag}_sw" link set v_robot down
  cut_begin_ns=$(date +%s%N)
  sleep "$cut_s"
  ip -n "${tag}_sw" link set v_robot up
  cut_end_ns=$(date +%s%N)
  echo "link cut for $(( (cut_end_ns - cut_begin_ns) / 1000000 )) ms"
else
  sleep "$cut_s"
fi
sleep 1
kill -KILL "$doomed" 2>/dev/null || true

robot_status=0; wait "$robot_launcher" || robot_status=$?
sleep 4  # the last samples reach the other hosts
declare -A status_of
for h in "${stop_order[@]}"; do
  kill -INT "${launcher_of[$h]}" 2>/dev/null || true
  status_of[$h]=0
  wait "${launcher_of[$h]}" || status_of[$h]=$?
done
if [[ -n ${capture:-} ]]; then kill -INT "$capture" 2>/dev/null || true; wait "$capture" || true; fi
if [[ -n ${emulator:-} ]]; then kill -INT "$emulator" 2>/dev/null || true; wait "$emulator" || true; fi

# Each process's final status stays in (a failure is read from it): the bridges'
# timing counters, the estimator's late and gated samples.
for h in "${hosts[@]}"; do grep -v "robot_sim: t \|: status: \|^\[map_view\]   " "$work/$h.log" | sed "s/^/$h| /"; done
fail() { echo "FAIL ($profile, $runner): $*"; exit 1; }
[[ $robot_status -eq 0 ]] || fail "robot launcher exited with $robot_status"
for h in "${stop_order[@]}"; do
  # `fastdds discovery` (2.9) may crash when stopped: the server host may fail, no other.
  [[ ${status_of[$h]} -eq 0 || $h == server ]] || fail "$h launcher exited with ${status_of[$h]}"
done
if [[ $runner == podman ]]; then log="$work/run/run.mcap"; else log="$work/laptop/run.mcap"; fi

# Every message each robot-side publisher sent is in the laptop's log (seq 1..N).
count() { grep -oE "$1" "$work/robot.log" | tail -1 | grep -oE '[0-9]+' | head -1; }
odometry=$(count 'odometry published [0-9]+')
observations=$(count 'observations published [0-9]+')
truth=$(count '[0-9]+ ground truth messages')
for n in "$odometry" "$observations" "$truth"; do [[ -n $n && $n -gt 0 ]] || fail "a publisher count is missing"; done
"$bin/pixyslam_log" check "$log" --expect "pixyslam/odometry=$odometry" \
  --expect "pixyslam/landmark_observation=$observations" --expect "pixyslam/ground_truth=$truth" ||
  fail "the laptop's log does not hold every message the robot sent"

map_times() {
  "$bin/pixyslam_log" print "$log" --topics pixyslam/map_state --json | grep -oE '"log_time_ns":[0-9]+' | grep -oE '[0-9]+'
}
if [[ -n $link_schedule ]]; then
  # MapState all along: the longest gap between two in the laptop's log, and
  # what the link did in each phase.
  cat "$work/link_emulator.log"
  max_gap_ms=$(map_times | sort -n | awk 'NR > 1 && $1 - p > g { g = $1 - p } { p = $1 } END { print int(g / 1000000) }')
  echo "longest gap between MapStates on the laptop: $max_gap_ms ms"
  [[ $max_gap_ms -le 3000 ]] || fail "MapState stopped for $max_gap_ms ms on the impaired link"
  grep -q "loss 30 %.*dropped [1-9]" "$work/link_emulator.log" || fail "the emulated link dropped nothing at 30 %"
  echo "PASS ($profile, $runner, link $link_schedule)"
  exit 0
fi

# MapState after the link came back.
first_after=$(map_times | awk -v t="$cut_end_ns" '$1 > t && !found { print $1; found = 1 }')
[[ -n $first_after ]] || fail "no MapState after the link came back"
resume_ms=$(( (first_after - cut_end_ns) / 1000000 ))
echo "MapState resumed $resume_ms ms after the link came back"
[[ $resume_ms -le 5000 ]] || fail "MapState resumed only after $resume_ms ms"

if [[ -n $capture_tool ]]; then
  plaintext=$(grep -c -a -E "base_link|pixyslam/odometry" "$work/robot_link.pcap" || true)
  bytes=$(stat -c %s "$work/robot_link.pcap")
  echo "capture of the robot's link ($capture_tool): $bytes bytes, $plaintext packets with plaintext names"
  if [[ $profile == secure ]]; then
    [[ $plaintext -eq 0 ]] || fail "plaintext payload or topic names on the wire with the secure profile"
    [[ $bytes -gt 100000 ]] || fail "the capture is too small to mean anything"
  else
    [[ $plaintext -gt 0 ]] || fail "control: no plaintext seen without security (is the capture working?)"
  fi
else
  echo "no tcpdump/tshark: traffic capture not checked"
fi
# Health: the robot's processes seen from the log host, and the killed one LOST.
# With DDS Security the processes announce no identity (dds.announce_identity
# auto): they are seen, joining, leaving and lost, but not named.
if [[ $profile == secure ]]; then
  anonymous="'pixyslam' \(identity not announced: dds.announce_identity\)"
  encoder=$anonymous spy=$anonymous
  grep -qE "^\[health\] encoder_bridge@" "$work/$log_host.log" && fail "a secure process announced its identity"
else
  encoder="encoder_bridge@.*" spy="pixyslam_spy@.* pid $doomed"
fi
grep -qE "^\[health\] $encoder: joined" "$work/$log_host.log" || fail "no health report of the robot's encoder_bridge"
grep -qE "^\[health\] $encoder: left" "$work/$log_host.log" || fail "the robot's encoder_bridge stopping was not reported"
# Through a discovery server the lease expiry arrives as a removal: "left".
if [[ $profile == discovery_client ]]; then gone="(LOST|left)"; else gone="LOST"; fi
grep -qE "^\[health\] $spy: $gone" "$work/$log_host.log" ||
  fail "the killed process on the robot was not reported $gone"
echo "health: $(grep -cE '^\[health\]' "$work/$log_host.log") reports on $log_host, the killed robot process $gone"
if [[ $profile == secure ]]; then
  grep -q "seq:" "$work/intruder_plain.txt" && fail "a participant without security received samples"
  grep -q "seq:" "$work/intruder_ca.txt" && fail "a participant with another CA's certificate received samples"
  [[ $plain_status -ne 0 && $ca_status -ne 0 ]] || fail "an intruder's echo did not fail"
  echo "intruders (no security; another CA): 0 samples each"
fi
echo "PASS ($profile, $runner)"
