#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test (ctest). Extra arguments
# go to ctest, e.g. scripts/run_tests.sh -L unit.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/install_deps.sh"
"$root/scripts/build.sh"
build_dir=${BUILD_DIR:-$root/build}
ctest --test-dir "$build_dir" --output-on-failure --parallel "$(nproc)" --timeout 600 "$@"
