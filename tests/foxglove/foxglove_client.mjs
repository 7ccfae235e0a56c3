// Foxglove's own client libraries against pixyslam (ctest foxglove_client):
//   node foxglove_client.mjs live ws://127.0.0.1:PORT SECONDS EXPECT_TOPICS...
//     connects with @foxglove/ws-protocol's FoxgloveClient, checks the
//     advertised channels, subscribes to all, sends malformed requests (each
//     must be answered with a status, and data must keep flowing), and decodes
//     every message with @foxglove/omgidl-serialization from the advertised schema.
//   node foxglove_client.mjs mcap FILE.mcap EXPECT_TOPICS...
//     reads a `pixyslam_log foxglove` output with @mcap/core and decodes every
//     message of every channel the same way.
// Both check: every expected topic seen and decoded; header seq strictly
// increasing per topic; each pixyslam/viz/landmarks SceneUpdate has one entity
// per landmark of the MapState of the same stamp, and each pixyslam/viz/tf the
// MapState's mean pose. Prints one line per topic; exit 1 on any failure.
// The packages come from FOXGLOVE_NODE_MODULES (the test's npm ci), else beside this file.
import { readFileSync } from "node:fs";
import { createRequire } from "node:module";
import path from "node:path";
const modules = process.env.FOXGLOVE_NODE_MODULES ?? path.join(path.dirname(new URL(import.meta.url).pathname), "node_modules");
const require = createRequire(path.join(modules, "..", "package.json"));
const { FoxgloveClient } = require("@foxglove/ws-protocol");
const { parseIDL } = require("@foxglove/omgidl-parser");
const { MessageReader } = require("@foxglove/omgidl-serialization");
const { McapStreamReader } = require("@mcap/core");
const WebSocket = require("ws");

const failures = [];
const fail = (text) => { if (failures.length < 20) console.log(`FAIL ${text}`); failures.push(text); };

function makeReader(schemaName, schema, encoding, schemaEncoding) {
  if (encoding !== "cdr" || schemaEncoding !== "omgidl") throw new Error(`encoding ${encoding}/${schemaEncoding}`);
  return new MessageReader(schemaName, parseIDL(schema));
}

// Per topic: count, decode failures, last seq; MapStates by stamp for the cross-checks.
const stats = new Map();
const mapStates = new Map();
const pendingViz = [];
function stat(topic) {
  if (!stats.has(topic)) stats.set(topic, { count: 0, undecodable: 0, seqErrors: 0 });
  return stats.get(topic);
}
const stampKey = (t) => `${t.sec}.${t.nsec}`;
const nsKey = (ns) => { const b = BigInt(ns); return `${b / 1000000000n}.${b % 1000000000n}`; };

const lastSeq = new Map();  // per writer: topic, robot, frame (diagnostics: one per process)
function onDecoded(topic, message) {
  const s = stat(topic);
  s.count++;
  if (message.header !== undefined) {
    const writer = `${topic} ${message.header.robot_id} ${message.header.frame_id}`;
    const seq = BigInt(message.header.seq);
    if (seq <= (lastSeq.get(writer) ?? 0n)) s.seqErrors++;
    lastSeq.set(writer, seq);
  }
  if (topic === "pixyslam/map_state") mapStates.set(nsKey(message.header.stamp_ns), message);
  if (topic === "pixyslam/viz/landmarks" || topic === "pixyslam/viz/tf") pendingViz.push({ topic, message });
}

function decode(topic, reader, bytes) {
  let message;
  try {
    message = reader.readMessage(bytes);
  } catch (e) {
    stat(topic).undecodable++;
    fail(`${topic}: does not decode: ${e.message}`);
    return;
  }
  onDecoded(topic, message);
}

function crossCheck() {
  let checked = 0;
  for (const { topic, message } of pendingViz) {
    const key = stampKey(topic === "pixyslam/viz/tf" ? message.timestamp : (message.entities[0]?.timestamp ?? message.deletions[0].timestamp));
    const state = mapStates.get(key);
    if (state === undefined) continue;  // its MapState was not received (subscribed later)
    checked++;
    if (topic === "pixyslam/viz/tf") {
      if (message.translation.x !== state.mean_pose.x_m || message.translation.y !== state.mean_pose.y_m ||
          message.parent_frame_id !== "map" || message.child_frame_id !== "base_link") {
        fail(`viz/tf at ${key}: (${message.translation.x}, ${message.translation.y}) is not the mean pose`);
      }
    } else {
      const want = state.landmarks.map((l) => `landmark_${l.landmark_id}`).sort().join(",");
      const got = message.entities.map((e) => e.id).sort().join(",");
      if (want !== got) fail(`viz/landmarks at ${key}: entities [${got}] != landmarks [${want}]`);
      for (const e of message.entities) {
        const c = e.cylinders[0];
        if (c === undefined || !(c.size.x > 0) || !(c.size.y > 0) || c.size.y > c.size.x) fail(`viz/landmarks ${e.id}: bad ellipse`);
      }
    }
  }
  return checked;
}

// Every topic docs/foxglove_layout.json names (3D topics, plot paths, raw
// message paths) must be one this run decoded: the layout cannot rot.
function checkLayout() {
  const file = process.env.FOXGLOVE_LAYOUT;
  if (!file) return;
  const layout = JSON.parse(readFileSync(file, "utf8"));
  const named = new Set();
  for (const panel of Object.values(layout.configById)) {
    for (const topic of Object.keys(panel.topics ?? {})) named.add(topic);
    for (const p of panel.paths ?? []) named.add(p.value.split(".")[0]);
    if (panel.topicPath) named.add(panel.topicPath.split(".")[0]);
  }
  for (const topic of named) if (!stats.has(topic)) fail(`layout ${file} names ${topic}, which was not received`);
  console.log(`layout: ${named.size} topics named, all received: ${[...named].every((t) => stats.has(t))}`);
}

function report(expected) {
  checkLayout();
  for (const topic of expected) {
    const s = stats.get(topic);
    if (s === undefined || s.count === 0) fail(`${topic}: no message decoded`);
  }
  for (const [topic, s] of [...stats.entries()].sort()) {
    if (s.seqErrors > 0) fail(`${topic}: header.seq not increasing ${s.seqErrors} times`);
    console.log(`${topic}: ${s.count} messages decoded, ${s.undecodable} undecodable`);
  }
  const checked = crossCheck();
  console.log(`cross-checked ${checked} viz messages against the MapState of the same stamp`);
  if (checked === 0) fail("no viz message could be cross-checked");
  console.log(failures.length === 0 ? "PASS" : `FAIL: ${failures.length} problems`);
  process.exit(failures.length === 0 ? 0 : 1);
}

async function live(url, seconds, expected) {
  const client = new FoxgloveClient({ ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
  const readers = new Map();  // subscription id -> { topic, reader }
  const statuses = [];
  let serverInfo;
  let advertised = [];
  let afterAbuse = 0;
  let abused = false;
  client.on("error", (e) => fail(`client error: ${e.message ?? e}`));
  client.on("serverInfo", (info) => { serverInfo = info; });
  client.on("status", (s) => statuses.push(s));
  client.on("advertise", (channels) => {
    advertised = advertised.concat(channels);
    for (const c of channels) {
      try {
        const reader = makeReader(c.schemaName, c.schema, c.encoding, c.schemaEncoding);
        readers.set(client.subscribe(c.id), { topic: c.topic, reader });
      } catch (e) {
        fail(`channel ${c.id} ${c.topic}: schema ${c.schemaName} does not parse: ${e.message}`);
      }
    }
    console.log(`advertised ${channels.length} channels: ${channels.map((c) => `${c.id} ${c.topic} (${c.schemaName})`).join(", ")}`);
  });
  client.on("message", ({ subscriptionId, data }) => {
    const entry = readers.get(subscriptionId);
    if (entry === undefined) { fail(`message on unknown subscription ${subscriptionId}`); return; }
    if (abused) afterAbuse++;
    decode(entry.topic, entry.reader, new Uint8Array(data.buffer, data.byteOffset, data.byteLength));
  });
  await new Promise((resolve) => setTimeout(resolve, seconds * 500));
  // Malformed requests on a second connection: each must get a status, and
  // this connection must keep receiving.
  abused = true;
  sendRaw(url);
  await new Promise((resolve) => setTimeout(resolve, seconds * 500));
  client.close();
  if (serverInfo === undefined) fail("no serverInfo");
  else console.log(`serverInfo: ${serverInfo.name}, metadata ${JSON.stringify(serverInfo.metadata)}`);
  for (const c of advertised) {
    if (c.encoding !== "cdr" || c.schemaEncoding !== "omgidl") fail(`${c.topic}: ${c.encoding}/${c.schemaEncoding}`);
  }
  for (const topic of expected) if (!advertised.some((c) => c.topic === topic)) fail(`${topic} not advertised`);
  console.log(`messages after the malformed requests: ${afterAbuse}`);
  if (afterAbuse === 0) fail("no message after the malformed requests");
  await abuseDone;
  report(expected);
}

// A second connection sends malformed requests and must get a status for each;
// then a connection without the subprotocol must be refused, and one sending a
// frame over the server's limit closed (code 1009), the first client unharmed.
let abuseDone = Promise.resolve();
function sendRaw(url) {
  abuseDone = malformedRequests(url).then(() => withoutSubprotocol(url)).then(() => oversizedFrame(url));
}

function withoutSubprotocol(url) {
  return new Promise((resolve) => {
    const ws = new WebSocket(url);
    ws.on("open", () => { fail("a connection without the foxglove.websocket.v1 subprotocol was accepted"); ws.close(); });
    ws.on("unexpected-response", (_req, res) => { console.log(`no subprotocol: refused with HTTP ${res.statusCode}`); resolve(); });
    ws.on("error", () => resolve());
    ws.on("close", () => resolve());
  });
}

function oversizedFrame(url) {
  return new Promise((resolve) => {
    const ws = new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
    const timer = setTimeout(() => { fail("oversized frame: connection not closed"); ws.terminate(); resolve(); }, 5000);
    ws.on("open", () => ws.send("x".repeat(200000)));
    ws.on("close", (code) => {
      clearTimeout(timer);
      console.log(`oversized frame: connection closed with code ${code}`);
      if (code !== 1009) fail(`oversized frame: close code ${code}, expected 1009 (message too big)`);
      resolve();
    });
    ws.on("error", () => {});
  });
}

function malformedRequests(url) {
  return new Promise((resolve) => {
    const ws = new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
    const requests = [
      "not json",
      "[1,2,3]",
      JSON.stringify({ op: "subscribe", subscriptions: [{ id: 1, channelId: 99999 }] }),
      JSON.stringify({ op: "subscribe", subscriptions: [{ id: -1, channelId: 1 }] }),
      JSON.stringify({ op: "unsubscribe", subscriptionIds: [424242] }),
      JSON.stringify({ op: "advertise", channels: [] }),
    ];
    let statuses = 0;
    ws.on("open", () => {
      for (const r of requests) ws.send(r);
      ws.send(Buffer.from([1, 0, 0, 0, 0, 9, 9]));
    });
    ws.on("message", (data, isBinary) => {
      if (isBinary) return;
      const m = JSON.parse(data.toString());
      if (m.op === "status") statuses++;
      if (statuses === requests.length + 1) { ws.close(); }
    });
    ws.on("close", () => {
      console.log(`malformed requests: ${requests.length + 1} sent, ${statuses} status replies`);
      if (statuses !== requests.length + 1) fail(`${statuses} status replies to ${requests.length + 1} malformed requests`);
      resolve();
    });
    ws.on("error", (e) => { fail(`abuse connection: ${e.message}`); resolve(); });
    const timer = setTimeout(() => ws.close(), 5000);
    ws.on("close", () => clearTimeout(timer));
  });
}

function mcap(file, expected) {
  const reader = new McapStreamReader({ validateCrcs: true });
  reader.append(readFileSync(file));
  const schemas = new Map();
  const channels = new Map();
  for (let record; (record = reader.nextRecord()); ) {
    if (record.type === "Schema") schemas.set(record.id, record);
    if (record.type === "Channel") {
      const s = schemas.get(record.schemaId);
      try {
        channels.set(record.id, { topic: record.topic, reader: makeReader(s.name, new TextDecoder().decode(s.data), record.messageEncoding, s.encoding) });
      } catch (e) {
        fail(`${record.topic}: schema does not parse: ${e.message}`);
      }
    }
    if (record.type === "Message") {
      const c = channels.get(record.channelId);
      if (c !== undefined) decode(c.topic, c.reader, record.data);
    }
  }
  if (!reader.done()) fail(`${file}: not a complete MCAP`);
  report(expected);
}

const [mode, target, ...rest] = process.argv.slice(2);
if (mode === "live") {
  const [seconds, ...expected] = rest;
  await live(target, Number(seconds), expected);
} else if (mode === "mcap") {
  mcap(target, rest);
} else {
  console.log("usage: foxglove_client.mjs live URL SECONDS TOPIC... | mcap FILE TOPIC...");
  process.exit(2);
}
