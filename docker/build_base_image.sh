#!/usr/bin/env bash
# Builds the base image pixyslam's images start from, without a registry:
# debootstrap a minimal Debian 12 root from the machine's own apt mirror and
# import it as localhost/pixyslam-base:bookworm. Skipped when it exists.
# With a registry, `--build-arg BASE_IMAGE=debian:bookworm-slim` works the same.
#   docker/build_base_image.sh [podman|docker]
set -euo pipefail
case ${1:-} in -h | --help) sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0"; exit 0 ;; esac
engine=${1:-podman}
if (($# > 1)) || [[ $engine != podman && $engine != docker ]]; then
  echo "usage: docker/build_base_image.sh [podman|docker] (--help: more)" >&2
  exit 2
fi
image=localhost/pixyslam-base:bookworm
if "$engine" image exists "$image" 2>/dev/null || "$engine" image inspect "$image" >/dev/null 2>&1; then
  echo "build_base_image: $image exists"
  exit 0
fi
command -v debootstrap >/dev/null || { echo "debootstrap missing (apt-get install debootstrap)" >&2; exit 1; }
# The mirror apt already uses (no other network here).
mirror=$(grep -hoE '^(URIs:|deb) +https?://[^ ]+' /etc/apt/sources.list /etc/apt/sources.list.d/*.sources 2>/dev/null |
  grep -v security | head -1 | awk '{print $2}' || true)
mirror=${mirror:-http://deb.debian.org/debian}
root=$(mktemp -d /tmp/pixyslam_rootfs.XXXXXX)
trap 'rm -rf "$root"' EXIT
echo "build_base_image: debootstrap bookworm from $mirror"
debootstrap --variant=minbase bookworm "$root" "$mirror" > "$root.log" 2>&1 ||
  { tail -20 "$root.log"; rm -f "$root.log"; exit 1; }
rm -f "$root.log"
rm -rf "$root"/var/cache/apt/archives/*.deb "$root"/var/lib/apt/lists/*
tar -C "$root" -c . | "$engine" import - "$image" > /dev/null
echo "build_base_image: $image $("$engine" image inspect "$image" --format '{{.Size}}') bytes"
