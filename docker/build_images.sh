#!/usr/bin/env bash
# Builds pixyslam-{robot,estimator,logger,viewer} from docker/Dockerfile with
# the programs in build/bin (scripts/build.sh first), on the local base image
# (docker/build_base_image.sh), and prints their sizes.
#   docker/build_images.sh [podman|docker]      (exit 77: no such engine here)
set -euo pipefail
engine=${1:-podman}
command -v "$engine" >/dev/null || { echo "SKIP: $engine is not installed"; exit 77; }
root=$(cd "$(dirname "$0")/.." && pwd)
export CONTAINERS_CONF=${CONTAINERS_CONF:-$root/docker/containers.conf}
[[ -x $root/build/bin/slam_estimator ]] || { echo "build/bin is empty: run scripts/build.sh first" >&2; exit 1; }
"$root/docker/build_base_image.sh" "$engine"
for role in robot estimator logger viewer; do
  # --network host: only for apt inside the build (the images run without it).
  "$engine" build --network host -q -f "$root/docker/Dockerfile" --target "$role" \
    --build-arg BASE_IMAGE=localhost/pixyslam-base:bookworm -t "localhost/pixyslam-$role:latest" "$root" > /dev/null
done
"$engine" images --format '{{.Repository}}:{{.Tag}} {{.Size}}' | grep pixyslam | sort
