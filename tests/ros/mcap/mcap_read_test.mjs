// SPDX-License-Identifier: GPL-2.0-or-later
// The bag read back by the readers ROS tools build on: @mcap/core's indexed reader (the summary, chunk
// indexes and message indexes, as Foxglove/Lichtblick open a file) and its streaming reader with CRC checks
// (as a reader of a growing or crashed file goes), each message decoded by @foxglove/rosmsg2-serialization
// from the bag's own ros2msg schemas. ros_mcap_sample writes message i with values that are a function of i;
// this test recomputes them. A SIGKILLed bag reads with the streaming reader up to its last whole chunk.
//
//   node mcap_read_test.mjs ROS_MCAP_SAMPLE WEB_NODE_MODULES
import { execFileSync, spawnSync } from "node:child_process";
import { mkdtempSync, readFileSync, rmSync } from "node:fs";
import { open } from "node:fs/promises";
import { createRequire } from "node:module";
import { tmpdir } from "node:os";
import path from "node:path";
import assert from "node:assert/strict";

const [sample, nodeModules] = process.argv.slice(2);
if (!sample || !nodeModules) {
  console.error("usage: node mcap_read_test.mjs ROS_MCAP_SAMPLE WEB_NODE_MODULES");
  process.exit(2);
}
// Packages resolve from web/node_modules, wherever this test lives.
const require = createRequire(path.join(path.resolve(nodeModules), "resolve-from-here.js"));
const { McapIndexedReader, McapStreamReader } = require("@mcap/core");
const fzstd = require("fzstd");
const { parse } = require("@foxglove/rosmsg");
const { MessageReader } = require("@foxglove/rosmsg2-serialization");

const decompressHandlers = { zstd: (buffer, size) => fzstd.decompress(buffer, new Uint8Array(Number(size))) };
const START_NS = 1_000_000_000n;
const STEP_NS = 10_000_000n;

// Message i as ros_mcap_sample wrote it on `topic`.
function checkValue(topic, i, msg, logTime) {
  if (topic === "/chatter") {
    assert.equal(msg.data, `message ${i}`);
  } else if (topic === "/cmd_vel") {
    assert.deepEqual(msg, { linear: { x: i * 0.5, y: -i, z: 0.25 }, angular: { x: 0, y: 0, z: i / 8 } });
  } else if (topic === "/scan") {
    assert.equal(msg.header.stamp.sec, Number(logTime / 1_000_000_000n));
    // The deserializer reads builtin_interfaces/Time as its own time type: { sec, nsec }.
    assert.equal(msg.header.stamp.nsec, Number(logTime % 1_000_000_000n));
    assert.equal(msg.header.frame_id, "laser");
    const f = Math.fround;
    assert.deepEqual(
      [msg.angle_min, msg.angle_max, msg.angle_increment, msg.time_increment, msg.scan_time, msg.range_min,
        msg.range_max],
      [f(-1.5), f(1.5), f(0.25), 0, f(0.1), f(0.1), f(10)]);
    assert.deepEqual(Array.from(msg.ranges), Array.from({ length: 1 + (i % 5) }, (_, k) => f((i + k) * 0.5)));
    assert.equal(msg.intensities.length, 0);
  } else {
    assert.fail(`unexpected topic ${topic}`);
  }
}

// Checks a run of messages (in the order a reader gave them): times monotonic, sequences per channel from
// 0 without gaps, each message on the topic of its index with its values. Returns counts per channel.
function checkMessages(messages, channelsById, schemasById) {
  const readers = new Map();
  for (const [id, schema] of schemasById) {
    assert.equal(schema.encoding, "ros2msg");
    readers.set(id, new MessageReader(parse(new TextDecoder().decode(schema.data), { ros2: true })));
  }
  const counts = new Map();
  let lastTime = -1n;
  for (const m of messages) {
    assert.ok(m.logTime >= lastTime, `log time ${m.logTime} after ${lastTime}`);
    lastTime = m.logTime;
    assert.equal(m.publishTime, m.logTime);
    const channel = channelsById.get(m.channelId);
    assert.ok(channel, `message on unknown channel ${m.channelId}`);
    assert.equal(channel.messageEncoding, "cdr");
    const seen = counts.get(m.channelId) ?? 0;
    assert.equal(m.sequence, seen, `sequence on ${channel.topic}`);
    counts.set(m.channelId, seen + 1);
    const i = Number((m.logTime - START_NS) / STEP_NS);
    assert.equal(channel.topic, ["/chatter", "/cmd_vel", "/scan"][i % 3]);
    checkValue(channel.topic, i, readers.get(channel.schemaId).readMessage(m.data), m.logTime);
  }
  return counts;
}

// Streams `bytes` through McapStreamReader with CRC checks; returns the records and whether it reached the end.
function streamRecords(bytes) {
  const reader = new McapStreamReader({ decompressHandlers, validateCrcs: true });
  reader.append(bytes);
  const records = [];
  for (let record; (record = reader.nextRecord()); ) records.push(record);
  return { records, done: reader.done() };
}

async function checkIndexed(file, expectedMessages) {
  const handle = await open(file, "r");
  try {
    const readable = {
      size: async () => BigInt((await handle.stat()).size),
      read: async (offset, size) => {
        const buffer = Buffer.alloc(Number(size));
        await handle.read(buffer, 0, buffer.length, Number(offset));
        return new Uint8Array(buffer.buffer, buffer.byteOffset, buffer.length);
      },
    };
    const reader = await McapIndexedReader.Initialize({ readable, decompressHandlers });
    assert.equal(reader.header.profile, "ros2");
    assert.equal(reader.schemasById.size, 3);
    assert.deepEqual([...reader.channelsById.values()].map((c) => c.topic), ["/chatter", "/cmd_vel", "/scan"]);
    const stats = reader.statistics;
    assert.ok(stats, "no Statistics record");
    assert.equal(stats.messageCount, BigInt(expectedMessages));
    assert.equal(stats.chunkCount, reader.chunkIndexes.length);
    assert.ok(reader.chunkIndexes.length > 5, `only ${reader.chunkIndexes.length} chunks`);
    assert.equal(stats.messageStartTime, START_NS);
    assert.equal(stats.messageEndTime, START_NS + BigInt(expectedMessages - 1) * STEP_NS);
    const messages = [];
    for await (const m of reader.readMessages()) messages.push(m);
    const counts = checkMessages(messages, reader.channelsById, reader.schemasById);
    assert.equal(messages.length, expectedMessages);
    for (const [id, count] of counts) assert.equal(stats.channelMessageCounts.get(id), BigInt(count));
    assert.equal(stats.channelMessageCounts.size, counts.size);
    return reader.chunkIndexes.length;
  } finally {
    await handle.close();
  }
}

function checkStreamed(file, expectedMessages, expectComplete) {
  const { records, done } = streamRecords(readFileSync(file));
  assert.equal(done, expectComplete, expectComplete ? "the stream ends with the footer" : "the stream is cut");
  const schemasById = new Map(records.filter((r) => r.type === "Schema").map((r) => [r.id, r]));
  const channelsById = new Map(records.filter((r) => r.type === "Channel").map((r) => [r.id, r]));
  const messages = records.filter((r) => r.type === "Message");
  const counts = checkMessages(messages, channelsById, schemasById);
  assert.equal(messages.length, expectedMessages);
  const types = new Set(records.map((r) => r.type));
  assert.equal(types.has("DataEnd"), expectComplete);
  assert.equal(types.has("Statistics"), expectComplete);
  if (expectComplete) {
    const stats = records.find((r) => r.type === "Statistics");
    for (const [id, count] of counts) assert.equal(stats.channelMessageCounts.get(id), BigInt(count));
  }
}

const dir = mkdtempSync(path.join(tmpdir(), "rfbsim_mcap_npm_"));
try {
  // A finished bag: both readers, every message.
  const finished = path.join(dir, "session.mcap");
  const written = JSON.parse(execFileSync(sample, [finished, "--messages", "900"], { encoding: "utf8" }));
  assert.equal(written.messages, 900);
  const chunks = await checkIndexed(finished, 900);
  checkStreamed(finished, 900, true);
  console.log(`finished bag: 900 messages in ${chunks} chunks read by the indexed and the streaming reader`);

  // A killed bag: the streaming reader gets every message of the whole chunks; the indexed one refuses it.
  const killed = path.join(dir, "killed.mcap");
  const run = spawnSync(sample, [killed, "--kill-after-chunks", "3"], { encoding: "utf8" });
  assert.equal(run.signal, "SIGKILL", `the sample should kill itself: ${run.stderr}`);
  const report = JSON.parse(run.stdout);
  assert.equal(report.in_chunks, 180);
  checkStreamed(killed, 180, false);
  const handle = await open(killed, "r");
  try {
    const readable = {
      size: async () => BigInt((await handle.stat()).size),
      read: async (offset, size) => {
        const buffer = Buffer.alloc(Number(size));
        await handle.read(buffer, 0, buffer.length, Number(offset));
        return new Uint8Array(buffer.buffer, buffer.byteOffset, buffer.length);
      },
    };
    await assert.rejects(McapIndexedReader.Initialize({ readable, decompressHandlers }));
  } finally {
    await handle.close();
  }
  console.log(`killed bag: ${report.in_chunks} of ${report.messages} messages read back by the streaming reader`);
} finally {
  rmSync(dir, { recursive: true, force: true });
}
