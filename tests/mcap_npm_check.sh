#!/usr/bin/env bash
# ctest logger_mcap_npm_check: files written by the `logger` process, read by
# the reference TypeScript reader @mcap/core (npm, installed in this test's own
# temp dir). Two recordings on a DDS domain of their own (loopback profile):
#   A: zstd, 8 KiB chunks, rotate_size_bytes 131072 -> several files
#   B: lz4, default chunks, one file
# mcap_sample_publisher sends N messages of every topic; the logger is stopped
# with SIGINT. Checked with @mcap/core: every record of every file front to
# back with CRCs (McapStreamReader), the indexed view (McapIndexedReader,
# summary, chunk and message indexes, CRCs) = the stream = Statistics = the
# logger's own per-file count (scripts/mcap_check.mjs); per topic, the
# messages over all files = the logger's "written" count = its "received"
# count, and received + seq gaps = N (every message written or counted lost).
# Topics whose writer keeps all (config/dds/profiles.xml) lose none: seq 1..N
# in order. The state topics keep the last few (fleet_map: 8), so at 1000 Hz on
# a loaded host the writer may overwrite one before the logger took it: their
# seqs need only increase, and each loss must show in "seq gaps".
# Exit 77 (ctest SKIP) when node/npm are missing or `npm install` fails.
#   mcap_npm_check.sh LOGGER PUBLISHER SOURCE_DIR
set -euo pipefail
logger=$1 publisher=$2 source_dir=$3
count=${COUNT:-1000}
domain=$((150 + $$ % 80))

if ! command -v node > /dev/null || ! command -v npm > /dev/null; then
  echo "SKIP: node/npm not installed"
  exit 77
fi
work=$(mktemp -d "${TMPDIR:-/tmp}/pixyslam_mcap_npm.XXXXXX")
logger_pid=""
cleanup() {
  [[ -n $logger_pid ]] && kill -9 "$logger_pid" 2>/dev/null || true
  wait 2>/dev/null || true
  if [[ -n ${KEEP_WORK:-} ]]; then echo "kept $work"; else rm -rf "$work"; fi
}
trap cleanup EXIT
trap 'exit 130' INT TERM  # a killed test still cleans up (the EXIT trap)

mkdir -p "$work/npm"
if ! (cd "$work/npm" && echo '{"private": true}' > package.json &&
      timeout 180 npm install --no-audit --no-fund --loglevel=error --fetch-retries=1 \
        --fetch-retry-mintimeout=2000 --fetch-retry-maxtimeout=5000 --fetch-timeout=30000 @mcap/core fzstd lz4js > ../npm.log 2>&1); then
  echo "SKIP: npm install @mcap/core fzstd lz4js failed (no network?):"
  tail -n 5 "$work/npm.log" || true
  exit 77
fi
export MCAP_NODE_MODULES=$work/npm/node_modules
echo "@mcap/core $(node -p "require('$work/npm/node_modules/@mcap/core/package.json').version")"

# Every record of every file, CRCs on; per-topic totals against the expectation.
cat > "$work/check_topics.mjs" <<'JS'
import { readFileSync } from "node:fs";
import { createRequire } from "node:module";
import path from "node:path";
const require = createRequire(path.join(process.env.MCAP_NODE_MODULES, "..", "package.json"));
const { McapStreamReader } = require("@mcap/core");
const fzstd = require("fzstd");
const lz4 = require("lz4js");
const decompressHandlers = {
  zstd: (b, size) => fzstd.decompress(b, new Uint8Array(Number(size))),
  lz4: (b, size) => lz4.decompress(b, Number(size)),
};
const [expectedJson, ...files] = process.argv.slice(2);
const expected = JSON.parse(expectedJson);
const seqs = {};
let failures = 0;
for (const file of files) {
  const reader = new McapStreamReader({ decompressHandlers, validateCrcs: true });
  reader.append(readFileSync(file));
  const topics = new Map();
  const types = {};
  for (let record; (record = reader.nextRecord()); ) {
    types[record.type] = (types[record.type] ?? 0) + 1;
    if (record.type === "Channel") topics.set(record.id, record.topic);
    if (record.type === "Message") (seqs[topics.get(record.channelId)] ??= []).push(record.sequence);
  }
  if (!reader.done()) { console.log(`FAIL ${file}: stream not done`); ++failures; }
  if (!types.Footer || !types.DataEnd || !types.Header) { console.log(`FAIL ${file}: incomplete`); ++failures; }
  console.log(`${file}: records ${JSON.stringify(types)}`);
}
// expected: topic -> [messages written, messages sent (N), lossless].
for (const [topic, [want, sent, lossless]] of Object.entries(expected)) {
  const got = seqs[topic] ?? [];
  const inOrder = lossless ? got.every((s, i) => s === i + 1)
                           : got.every((s, i) => s >= 1 && s <= sent && (i === 0 || s > got[i - 1]));
  const ok = got.length === want && inOrder;
  const order = lossless ? "seq 1..N in order" : `seq increasing within 1..${sent}`;
  console.log(`${ok ? "ok  " : "FAIL"} ${topic}: ${got.length} messages over ${files.length} file(s), expected ${want}` +
    `, ${inOrder ? "" : "NOT "}${order}`);
  if (!ok) ++failures;
}
process.exit(failures === 0 ? 0 : 1);
JS

# keeps_all TOPIC: its data_writer profile keeps every sample (KEEP_ALL).
keeps_all() {
  grep -A1 "<data_writer profile_name=\"$1\">" "$source_dir/config/dds/profiles.xml" | grep -q '<kind>KEEP_ALL</kind>'
}

# record NAME COMPRESSION ROTATE_SIZE CHUNK_SIZE: one recording, checked.
record() {
  local name=$1 compression=$2 rotate=$3 chunk=$4
  local dir=$work/$name
  mkdir -p "$dir"
  cat > "$dir/logger.yaml" <<YAML
logger:
  output_file: $dir/run.mcap
  topics: ['pixyslam/*', '!pixyslam/diagnostics']  # what mcap_sample_publisher sends
  compression: $compression
  chunk_size_bytes: $chunk
  rotate_size_bytes: $rotate
  flush_period_s: 0.5
dds:
  domain_id: $domain
  profiles_file: $source_dir/config/dds/profiles.xml
  robot_id: npm_check
YAML
  "$logger" --config "$dir/logger.yaml" > "$dir/logger.out" 2> "$dir/logger.err" &
  logger_pid=$!
  if ! "$publisher" --profiles "$source_dir/config/dds/profiles.xml" --domain "$domain" --count "$count" \
      --rate-hz 1000 > "$dir/publisher.out" 2> "$dir/publisher.err"; then
    echo "FAIL $name: publisher failed"; cat "$dir/publisher.err" "$dir/logger.err"; return 1
  fi
  sleep 0.5
  kill -INT "$logger_pid" 2>/dev/null || true
  local rc=0
  wait "$logger_pid" || rc=$?
  logger_pid=""
  cat "$dir/logger.err"
  [[ $rc -eq 0 ]] || { echo "FAIL $name: logger exit status $rc"; return 1; }

  # The logger's own counts: per topic "received R, written W, ..., seq gaps G",
  # per file "M messages".
  local expected="{" files=() checks=() topic received written gaps lossless path messages
  while read -r topic received written gaps; do
    lossless=false
    keeps_all "$topic" && lossless=true
    if [[ $written -ne $received ]] || ((received + gaps != count)) || { $lossless && ((gaps != 0)); }; then
      echo "FAIL $name: $topic: logger received $received, wrote $written, seq gaps $gaps of $count sent" \
        "(writer keeps all: $lossless)"
      return 1
    fi
    ((gaps == 0)) || echo "note $name: $topic: $gaps of $count overwritten in the writer's history before the logger took them"
    expected+="\"$topic\": [$written, $count, $lossless],"
  done < <(sed -n 's/^logger: \(pixyslam\/[a-z_]*\): received \([0-9]*\), written \([0-9]*\),.* seq gaps \([0-9]*\),.*/\1 \2 \3 \4/p' \
             "$dir/logger.err")
  expected="${expected%,}}"
  while read -r path messages; do
    files+=("$path")
    checks+=("$path:$messages")
  done < <(sed -n 's/^logger: file \(.*\): \([0-9]*\) messages,.*/\1 \2/p' "$dir/logger.err")
  [[ ${#files[@]} -gt 0 && $expected != "{}" ]] || { echo "FAIL $name: no counts in the logger's output"; return 1; }
  echo "== $name: ${#files[@]} file(s), expected per topic $expected"
  node "$source_dir/scripts/mcap_check.mjs" "${checks[@]}"
  node "$work/check_topics.mjs" "$expected" "${files[@]}"
}

record rotated zstd 131072 8192
record single lz4 0 1048576
echo "logger_mcap_npm_check: all files read clean by @mcap/core"
