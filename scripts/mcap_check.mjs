// Cross-checks MCAP files written by pixyslam_mcap with the reference
// TypeScript reader (@mcap/core): reads each file with McapIndexedReader
// (summary, chunk indexes, message indexes, CRCs) and McapStreamReader
// (front to back, CRCs), and compares the message counts with each other, with
// the Statistics record and with an optional expected count.
//
//   node scripts/mcap_check.mjs FILE[:EXPECTED_MESSAGES] ...
//
// Messages outside chunks are not indexed (spec), so for an unchunked file only
// the stream count is compared.
//
// @mcap/core (and optionally fzstd and lz4js, for "zstd" and "lz4" chunks) are resolved from
// $MCAP_NODE_MODULES when set, otherwise from the current directory
// (e.g. after `npm install @mcap/core fzstd lz4js` in a scratch directory).
// Exit status 0 when every file agrees, 1 otherwise, 2 on usage errors.

import { open } from "node:fs/promises";
import { createRequire } from "node:module";
import path from "node:path";

const base = process.env.MCAP_NODE_MODULES
  ? path.resolve(process.env.MCAP_NODE_MODULES, "..")
  : process.cwd();
const require = createRequire(path.join(base, "package.json"));
const { McapIndexedReader, McapStreamReader } = require("@mcap/core");

const decompressHandlers = {};
try {
  const fzstd = require("fzstd");
  decompressHandlers.zstd = (buffer, size) => fzstd.decompress(buffer, new Uint8Array(Number(size)));
} catch {
  // zstd chunks then fail to read, which is reported per file
}
try {
  const lz4 = require("lz4js");
  decompressHandlers.lz4 = (buffer, size) => lz4.decompress(buffer, Number(size));
} catch {
  // likewise for lz4 chunks
}

async function indexedCount(file) {
  const handle = await open(file, "r");
  try {
    const readable = {
      size: async () => BigInt((await handle.stat()).size),
      read: async (offset, size) => {
        const buffer = new Uint8Array(Number(size));
        await handle.read(buffer, 0, Number(size), Number(offset));
        return buffer;
      },
    };
    const reader = await McapIndexedReader.Initialize({ readable, decompressHandlers });
    let count = 0;
    const perTopic = {};
    for await (const message of reader.readMessages({ validateCrcs: true })) {
      ++count;
      const topic = reader.channelsById.get(message.channelId)?.topic ?? `#${message.channelId}`;
      perTopic[topic] = (perTopic[topic] ?? 0) + 1;
    }
    return {
      count,
      perTopic,
      statistics: reader.statistics ? Number(reader.statistics.messageCount) : undefined,
      chunks: reader.chunkIndexes.length,
      library: reader.header.library,
    };
  } finally {
    await handle.close();
  }
}

async function streamCount(file) {
  const handle = await open(file, "r");
  try {
    const reader = new McapStreamReader({ decompressHandlers, validateCrcs: true });
    const piece = new Uint8Array(4093); // odd size: records split across appends
    let count = 0;
    for (;;) {
      const { bytesRead } = await handle.read(piece, 0, piece.length, null);
      if (bytesRead === 0) break;
      reader.append(piece.slice(0, bytesRead));
      for (let record; (record = reader.nextRecord()); ) {
        if (record.type === "Message") ++count;
      }
    }
    return { count, done: reader.done() };
  } finally {
    await handle.close();
  }
}

const args = process.argv.slice(2);
if (args.length === 0) {
  console.error("usage: node scripts/mcap_check.mjs FILE[:EXPECTED_MESSAGES] ...");
  process.exit(2);
}
let failures = 0;
for (const arg of args) {
  const match = /^(.*?)(?::(\d+))?$/.exec(arg);
  const file = match[1];
  const expected = match[2] === undefined ? undefined : Number(match[2]);
  try {
    const indexed = await indexedCount(file);
    const stream = await streamCount(file);
    const indexedOk = indexed.chunks === 0 ? indexed.count === 0 : indexed.count === stream.count;
    const ok =
      indexedOk &&
      stream.done &&
      (indexed.statistics === undefined || indexed.statistics === stream.count) &&
      (expected === undefined || expected === stream.count);
    const indexedText = indexed.chunks === 0 ? "unindexed" : String(indexed.count);
    console.log(
      `${ok ? "ok  " : "FAIL"} ${file}: indexed ${indexedText}, stream ${stream.count}` +
        `${stream.done ? "" : " (stream not done)"}, statistics ${indexed.statistics}` +
        `${expected === undefined ? "" : `, expected ${expected}`}, chunks ${indexed.chunks},` +
        ` library "${indexed.library}", per topic ${JSON.stringify(indexed.perTopic)}`,
    );
    if (!ok) ++failures;
  } catch (error) {
    console.log(`FAIL ${file}: ${error instanceof Error ? error.message : String(error)}`);
    ++failures;
  }
}
console.log(`${args.length - failures} passed, ${failures} failed`);
process.exit(failures === 0 ? 0 : 1);
