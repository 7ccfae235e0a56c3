#!/usr/bin/env bash
# Builds pixyslam-{robot,estimator,logger,viewer} from docker/Dockerfile on the
# local base image (docker/build_base_image.sh) and prints their sizes.
#   docker/build_images.sh [podman|docker] [--from-source] [--build-dir DIR]
# Default: from the packages of this checkout's build (cpack of build/, or of
# --build-dir: the programs the tests ran); --from-source: the Dockerfile's
# builder stage compiles the checkout (no host build needed). Exit 77: no such
# engine here.
set -euo pipefail
engine=podman from_source=0 build_dir=""
while (($#)); do
  case $1 in
    --from-source) from_source=1 ;;
    --build-dir) build_dir=${2:?--build-dir needs a folder}; shift ;;
    podman|docker) engine=$1 ;;
    -h|--help) sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0"; exit 0 ;;
    *) echo "build_images: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
  shift
done
command -v "$engine" >/dev/null || { echo "SKIP: $engine is not installed"; exit 77; }
root=$(cd "$(dirname "$0")/.." && pwd)
export CONTAINERS_CONF=${CONTAINERS_CONF:-$root/docker/containers.conf}
packages=builder packages_id="" robot_depends="" station_depends=""
if ((from_source == 0)); then
  build_dir=${build_dir:-$root/build}
  [[ -f $build_dir/CPackConfig.cmake ]] || { echo "$build_dir is not configured: run scripts/build.sh first (or --from-source)" >&2; exit 1; }
  # The build context holds build/packages/ (.dockerignore): that build's packages go there.
  rm -rf "$root/build/packages"
  cpack --config "$build_dir/CPackConfig.cmake" -G DEB -B "$root/build/packages" > /dev/null
  rm -rf "$root/build/packages/_CPack_Packages"
  packages=context
  packages_id=$(cat "$root"/build/packages/pixyslam-*.deb | sha256sum | cut -c1-16)
  # The Debian packages each .deb depends on (first of alternatives, no versions): installed
  # in a layer of their own, reused from the last build while the list is the same.
  depends_of() {
    dpkg-deb -f "$1" Depends | tr ',' '\n' | sed -E 's/\|.*//; s/\(.*\)//; s/^ +//; s/ +$//' |
      grep -v -e '^pixyslam' -e '^$' | sort -u | tr '\n' ' '
  }
  robot_depends=$(depends_of "$root"/build/packages/pixyslam-robot_*.deb)
  station_depends=$(depends_of "$root"/build/packages/pixyslam-station_*.deb)
else
  packages_id="source-$(date +%s)"  # the builder stage's packages are new: install them again
fi
"$root/docker/build_base_image.sh" "$engine"
start=$(date +%s)
for role in robot estimator logger viewer; do
  # --network host: only for apt inside the build (the images run without it).
  "$engine" build --network host -q -f "$root/docker/Dockerfile" --target "$role" \
    --build-arg BASE_IMAGE=localhost/pixyslam-base:bookworm --build-arg PACKAGES=$packages \
    --build-arg PACKAGES_ID="$packages_id" --build-arg ROBOT_DEPENDS="$robot_depends" \
    --build-arg STATION_DEPENDS="$station_depends" \
    -t "localhost/pixyslam-$role:latest" "$root" > /dev/null
done
# The previous builds' images, untagged now: only ours (the Dockerfile's label), nobody else's.
"$engine" image prune -f --filter label=org.pixyslam.image > /dev/null || true
echo "build_images: packages from $packages ($packages_id), $(($(date +%s) - start)) s"
"$engine" images --format '{{.Repository}}:{{.Tag}} {{.Size}}' | grep "pixyslam-" | sort
