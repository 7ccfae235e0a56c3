#!/usr/bin/env bash
# The seed paper's corner and corridor experiments and a loop-closure world,
# simulated (three runs each): OUT_DIR/report.md in the paper's Table 1 form
# and a map picture per experiment. Usage: scripts/paper_experiments.sh [OUT_DIR]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$root/build/paper_experiments}
"$root/scripts/build.sh" >/dev/null
"${BUILD_DIR:-$root/build}/bin/paper_experiments" --config-dir "$root/config" --out-dir "$out" --check
