#!/usr/bin/env bash
# Installs the Debian 12 packages this project needs, and only those missing.
# Idempotent: a machine that has everything installs nothing. Uses sudo when not root.
set -euo pipefail
case ${1:-} in -h | --help) sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0"; exit 0 ;; esac
if (($#)); then echo "usage: scripts/install_deps.sh (no arguments; --help: more)" >&2; exit 2; fi

PACKAGES=(
  cmake g++ ninja-build pkg-config
  libeigen3-dev libyaml-cpp-dev libcli11-dev
  libgtest-dev libbenchmark-dev
  libfastrtps-dev libfastcdr-dev fastddsgen fastdds-tools default-jre-headless
  libzstd-dev liblz4-dev
  libopencv-dev
  libceres-dev
  openssl iproute2 tcpdump
  podman runc debootstrap
  clang-14 libclang-rt-14-dev
  cyclonedds-dev cyclonedds-tools
  libwebsocketpp-dev libasio-dev nlohmann-json3-dev
)
# Node.js and npm run the tests that use Foxglove's and MCAP's own npm clients;
# Debian's only where the machine has none (a newer one may be installed apart).
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then PACKAGES+=(nodejs npm); fi

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  echo "install_deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi
echo "install_deps: installing ${missing[*]}"
SUDO=""
if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
