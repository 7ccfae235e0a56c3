#!/usr/bin/env bash
# Prints docs/tools.md: every shipped executable's --help text, from the build.
#   scripts/tool_help.sh > docs/tools.md      (after scripts/build.sh)
set -euo pipefail
case ${1:-} in -h | --help) sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0"; exit 0 ;; esac
if (($#)); then echo "usage: scripts/tool_help.sh > docs/tools.md (no arguments; --help: more)" >&2; exit 2; fi
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${BUILD_DIR:-$root/build}/bin
tools=(encoder_bridge pixy_bridge slam_estimator map_optimizer logger foxglove_bridge pixyslam_launch pixyslam_spy pixyslam_play
  map_view robot_sim sim_evaluator slam_offline mrclam_eval pixyslam_calibrate paper_experiments camera_eval
  dataset_bridge fleet_map bench_latency bench_logger_throughput bench_map_optimizer bench_mrclam_frame link_emulator)
cat <<'TEXT'
# Every executable's command line

What each program prints for `--help` (exit 0, nothing started: ctest `help_all_executables` checks
that for every executable of the build, and that an unknown flag exits 2). Exit codes everywhere:
0 ok; 1 runtime failure, also an input (a recording, a data set) that is missing or does not
read, or a check that failed (`sim_evaluator`, `mrclam_eval`, `paper_experiments --check`,
`pixyslam_spy check`); 2 usage or configuration error (a bad flag or value, a config file that is
missing or wrong); the evaluations and benchmarks on the MRCLAM data set (`mrclam_eval`,
`bench_mrclam_frame`, `bench_map_optimizer`) exit 77 when it is absent (skipped).
Flags mean the same everywhere: `--config FILE` (the process's YAML; for the inspection tools one
with a `dds:` mapping), `--domain N`, `--set KEY=VALUE` (a parameter of the config, listed under
`--help`), `--out FILE`, `--out-dir DIR`, `--duration S` (how long: wall seconds for a live tool,
recorded or simulated seconds for one that plays or simulates: `pixyslam_play`, `dataset_bridge`,
`robot_sim`, `slam_offline`), `--json`, `--verbose`, `--rate R` (a
speed factor: recorded seconds per wall or video second), `--rate-hz HZ` (messages per second),
`--robot N` (an MRCLAM robot number), `--robot-id ID` (a `dds.robot_id`).
`pixyslam_log` is `pixyslam_spy` under its old name. Regenerate with
`scripts/tool_help.sh > docs/tools.md`.
TEXT
for tool in "${tools[@]}"; do
  [[ -x $bin/$tool ]] || continue  # optional parts (map_view, the optimiser) may be off
  printf '\n## `%s`\n\n```\n' "$tool"
  "$bin/$tool" --help 2>&1 | sed "s#$root#<checkout>#g"
  printf '```\n'
  # The subcommands it lists under "Subcommands:", each one's own --help.
  for sub in $("$bin/$tool" --help | sed -n '/^Subcommands:/,/^$/s/^  \([a-z_-]*\) .*/\1/p'); do
    printf '\n### `%s %s`\n\n```\n' "$tool" "$sub"
    "$bin/$tool" "$sub" --help 2>&1 | sed "s#$root#<checkout>#g"
    printf '```\n'
  done
done
