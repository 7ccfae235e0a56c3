# Sourced by the tests that build a small switched network of "hosts": one
# network namespace per host (TAG_HOST, its eth0 at an address of the test's
# /24) and one for the switch (TAG_sw, a bridge br0 without multicast
# snooping, one v_HOST port per host). Root needed; nothing leaves them.

# netns_add NAME: a new namespace NAME. One of that name left by a run that was
# killed before its cleanup (a ctest timeout; the tag comes from a pid, which
# recurs) is emptied and deleted first.
netns_add() {
  if ip netns list | grep -x "$1\( .*\)\{0,1\}" > /dev/null; then
    echo "removing namespace $1, left by an earlier run"
    ip netns pids "$1" 2>/dev/null | xargs -r kill -KILL 2>/dev/null || true
    ip netns del "$1"
  fi
  ip netns add "$1"
}

# netns_switch TAG: the switch's namespace and bridge.
netns_switch() {
  netns_add "$1_sw"
  ip -n "$1_sw" link add br0 type bridge mcast_snooping 0
  ip -n "$1_sw" link set br0 up
}

# netns_attach TAG HOST ADDRESS/PREFIX: HOST's namespace, whose eth0 is joined
# to the switch's v_HOST (made by the caller), is addressed and up, with
# multicast routed through eth0.
netns_attach() {
  local tag=$1 host=$2 address=$3
  ip -n "${tag}_sw" link set "v_$host" master br0 up
  ip -n "${tag}_$host" link set lo up
  ip -n "${tag}_$host" addr add "$address" dev eth0
  ip -n "${tag}_$host" link set eth0 up
  ip -n "${tag}_$host" route add 224.0.0.0/4 dev eth0
}

# netns_host TAG HOST ADDRESS/PREFIX: a host joined to the switch by a veth pair.
netns_host() {
  local tag=$1 host=$2
  netns_add "${tag}_$host"
  ip link add "v_$host" netns "${tag}_sw" type veth peer name eth0 netns "${tag}_$host"
  netns_attach "$@"
}

# netns_remove TAG HOST...: kills what still runs in the hosts' and the
# switch's namespaces and deletes them (for cleanup traps; never fails).
netns_remove() {
  local tag=$1 h
  shift
  for h in "$@" sw; do ip netns pids "${tag}_$h" 2>/dev/null | xargs -r kill -KILL 2>/dev/null || true; done
  for h in "$@" sw; do ip netns del "${tag}_$h" 2>/dev/null || true; done
}
