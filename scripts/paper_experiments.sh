#!/usr/bin/env bash
# The seed paper's corner and corridor experiments and a loop-closure world,
# simulated (three runs each): OUT_DIR/report.md in the paper's Table 1 form
# and a map picture per experiment. Usage: scripts/paper_experiments.sh [OUT_DIR]
set -euo pipefail
case ${1:-} in -h | --help) sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0"; exit 0 ;; esac
if (($# > 1)) || [[ ${1:-} == -* ]]; then
  echo "usage: scripts/paper_experiments.sh [OUT_DIR] (--help: more)" >&2
  exit 2
fi
root=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$root/build/paper_experiments}
"$root/scripts/build.sh" >/dev/null
"${BUILD_DIR:-$root/build}/bin/paper_experiments" --config-dir "$root/config" --out-dir "$out" --check
