// SPDX-License-Identifier: GPL-2.0-or-later
// ros_mcap_session: sim_rfb's session.mcap (docs/ros.md) read back by the npm readers that Foxglove and
// Lichtblick use. Two warehouse sessions run side by side: one for about 6 s, ended by SIGTERM, and one
// SIGKILLed after about 3 s.
//
// The finished bag: the streaming and the indexed reader both read it with CRCs checked (and the data
// section's CRC matches); it has the ros2 profile, ros2msg schemas, CDR channels, zstd chunks at most about
// 1 s long each, a chunk index with message indexes per chunk, and /map offered transient-local. Statistics
// equal what both readers counted (per channel, in all, first and last time, chunks, channels, schemas).
// Log times never go back within a channel, within a chunk, or from one chunk to the next; publish time
// equals log time and every header stamp (and /clock) equals it too. Every message decodes with the schema
// in the file. /clock has every tick from 0 to the session's end_tick; /scan has the scenario's beam count
// and angle_max = angle_min + (n - 1) * increment; /map and /scene_markers come once; /events repeats
// events.jsonl line for line. Every row of trajectories.csv equals the bag at that tick within 1e-6:
// the robot's pose /tf map->robot_truth, the avatar's and each person's /tf map->avatar / map->person_<id>
// and their position in /people.
//
// The killed bag: the streaming reader reads its complete chunks without error, at least 1 s of messages,
// all of which decode; the indexed reader refuses it (no summary, no footer: expected after a SIGKILL).

import fs from 'node:fs';
import path from 'node:path';

import { loadBagPackages, readIndexed, readStreamed, schemaDecoders, tickNs, yawOf } from './ros_bag.mjs';
import { Sim, angleDiff, check, log, parseArgs, readEvents, readTrajectories, runTest, sleep } from './ros_e2e_support.mjs';

const FULL_RUN_MS = 6000;     // wall time of the finished session
const KILLED_RUN_MS = 3000;   // wall time before the SIGKILL
const POSE_TOLERANCE = 1e-6;  // m and rad: trajectories.csv has six decimals
const TOPICS = ['/clock', '/tf', '/odom', '/scan', '/map', '/scene_markers', '/cmd_vel', '/people', '/plan',
                '/goal_pose', '/events'];

// The lidar's beam count from the scenario file (robot.nav.lidar.beams), else the default (lidar.hpp: 360).
function expectedBeams(yaml, scenarioFile) {
  const scenario = yaml.parse(fs.readFileSync(scenarioFile, 'utf8'));
  return scenario?.robot?.nav?.lidar?.beams ?? 360;
}

// Groups messages by channel topic: Map topic -> [{ record, msg }] in file order, decoding each.
function decodeAll(stream, decoders) {
  const byTopic = new Map(TOPICS.map((t) => [t, []]));
  for (const record of stream.messages) {
    const channel = stream.channels.get(record.channelId);
    check(channel, `a message on channel ${record.channelId}, which no Channel record declared`);
    let msg;
    try {
      msg = decoders.get(channel.schemaId)(record.data);
    } catch (err) {
      throw new Error(`${channel.topic} at ${record.logTime}: does not decode as CDR: ${err.message}`);
    }
    byTopic.get(channel.topic)?.push({ record, msg });
  }
  return byTopic;
}

// A builtin_interfaces/Time as ns; the CDR reader names its second field nsec (as ROS 1 did), rosbridge nanosec.
function timeNs(stamp) {
  return BigInt(stamp.sec) * 1_000_000_000n + BigInt(stamp.nanosec ?? stamp.nsec);
}

// The container: profile, schemas, channels, chunks, indexes, CRCs, Statistics against both readers.
function checkContainer(idx, st) {
  check(st.error === null, `streaming reader: ${st.error}`);
  check(st.complete, 'streaming reader: the file does not end with a footer and magic');
  check(st.header.profile === 'ros2', `header profile '${st.header.profile}', expected 'ros2'`);
  check(idx.dataSectionCrc !== undefined && idx.dataCrcOk, `data section CRC ${idx.dataSectionCrc} is missing or wrong`);
  for (const schema of st.schemas.values()) {
    check(schema.encoding === 'ros2msg', `schema ${schema.name}: encoding '${schema.encoding}'`);
    check(/^[a-z0-9_]+\/msg\/[A-Za-z0-9]+$/.test(schema.name), `schema name '${schema.name}' is not pkg/msg/Type`);
  }
  const topics = [...st.channels.values()].map((c) => c.topic).sort();
  check(JSON.stringify(topics) === JSON.stringify([...TOPICS].sort()), `channels ${topics.join(' ')}`);
  for (const channel of st.channels.values()) {
    check(channel.messageEncoding === 'cdr', `${channel.topic}: message encoding '${channel.messageEncoding}'`);
    // rosbag2's QoS YAML: Humble writes the rmw enums as numbers (durability 1 transient-local, 2 volatile),
    // later releases as names.
    const qos = channel.metadata.get('offered_qos_profiles') ?? '';
    const durability = /durability: *(\w+)/.exec(qos)?.[1];
    check(durability !== undefined, `${channel.topic}: no durability in offered_qos_profiles '${qos}'`);
    const transientLocal = durability === '1' || durability === 'transient_local';
    const latched = channel.topic === '/map' || channel.topic === '/scene_markers' || channel.topic === '/goal_pose';
    if (channel.topic === '/map') check(transientLocal, `/map is not offered transient-local: durability ${durability}`);
    if (!latched) check(!transientLocal, `${channel.topic} is offered transient-local`);
  }

  // Chunks: zstd, CRC'd, about a second each, indexed with a message index per channel in them.
  const stats = st.statistics;
  check(stats, 'no Statistics record');
  check(st.chunks.length >= 3, `${st.chunks.length} chunks in ${FULL_RUN_MS} ms, expected one about every second`);
  check(idx.reader.chunkIndexes.length === st.chunks.length && stats.chunkCount === st.chunks.length,
        `${st.chunks.length} chunks, ${idx.reader.chunkIndexes.length} chunk indexes, Statistics says ${stats.chunkCount}`);
  st.chunks.forEach(({ chunk, messages }, i) => {
    check(chunk.compression === 'zstd', `chunk ${i}: compression '${chunk.compression}'`);
    check(chunk.uncompressedCrc !== 0, `chunk ${i}: no CRC`);
    check(messages.length > 0, `chunk ${i}: empty`);
    const times = messages.map((m) => m.logTime);
    const first = times.reduce((a, b) => (b < a ? b : a));
    const last = times.reduce((a, b) => (b > a ? b : a));
    check(chunk.messageStartTime === first && chunk.messageEndTime === last,
          `chunk ${i}: start/end ${chunk.messageStartTime}/${chunk.messageEndTime}, its messages ${first}/${last}`);
    check(last - first <= 1_200_000_000n, `chunk ${i} spans ${Number(last - first) / 1e9} s (about 1 s expected)`);
    const channelsIn = new Set(messages.map((m) => m.channelId));
    const indexed = idx.reader.chunkIndexes[i].messageIndexOffsets;
    for (const id of channelsIn) check(indexed.has(id), `chunk ${i}: no message index for channel ${id}`);
  });

  // Statistics against what both readers counted.
  const count = (messages) => {
    const counts = new Map();
    for (const m of messages) counts.set(m.channelId, (counts.get(m.channelId) ?? 0n) + 1n);
    return counts;
  };
  const streamed = count(st.messages);
  const indexed = count(idx.messages);
  check(stats.messageCount === BigInt(st.messages.length) && idx.messages.length === st.messages.length,
        `Statistics ${stats.messageCount} messages, streamed ${st.messages.length}, indexed ${idx.messages.length}`);
  check(stats.channelCount === st.channels.size && stats.schemaCount === st.schemas.size,
        `Statistics ${stats.channelCount} channels / ${stats.schemaCount} schemas, file ${st.channels.size} / ${st.schemas.size}`);
  for (const [id, channel] of st.channels) {
    const want = stats.channelMessageCounts.get(id) ?? 0n;
    check(want === (streamed.get(id) ?? 0n) && want === (indexed.get(id) ?? 0n),
          `${channel.topic}: Statistics ${want}, streamed ${streamed.get(id) ?? 0n}, indexed ${indexed.get(id) ?? 0n}`);
  }
  check(stats.messageStartTime === st.chunks[0].chunk.messageStartTime &&
        stats.messageEndTime === st.chunks[st.chunks.length - 1].chunk.messageEndTime,
        `Statistics times ${stats.messageStartTime}..${stats.messageEndTime} are not the chunks' first and last`);
  log(`finished bag: ${st.messages.length} messages in ${st.chunks.length} zstd chunks, ${st.channels.size} ` +
      `channels; Statistics, indexes and CRCs agree`);
}

// Log times never go back: per channel, within each chunk, and from a chunk to the next; publish = log.
function checkOrder(st) {
  const lastPerChannel = new Map();
  let previousChunkEnd = -1n;
  st.chunks.forEach(({ chunk, messages }, i) => {
    check(chunk.messageStartTime >= previousChunkEnd,
          `chunk ${i} starts at ${chunk.messageStartTime}, before chunk ${i - 1} ended (${previousChunkEnd})`);
    previousChunkEnd = chunk.messageEndTime;
    let previous = -1n;
    for (const m of messages) {
      const topic = st.channels.get(m.channelId).topic;
      check(m.logTime >= previous, `chunk ${i}: ${topic} at ${m.logTime} after a message at ${previous}`);
      check(m.logTime >= (lastPerChannel.get(m.channelId) ?? -1n), `${topic}: log time ${m.logTime} goes back`);
      check(m.publishTime === m.logTime, `${topic}: publish time ${m.publishTime} != log time ${m.logTime}`);
      previous = m.logTime;
      lastPerChannel.set(m.channelId, m.logTime);
    }
  });
}

// What the messages say: stamps, ticks, the scan's shape, latched topics once, /events = events.jsonl.
function checkContent(byTopic, dir, beams) {
  // /clock: every tick from 0 to end_tick, once each, and its value is its log time.
  const session = JSON.parse(fs.readFileSync(path.join(dir, 'session.json'), 'utf8'));
  const clocks = byTopic.get('/clock');
  check(clocks.length === session.end_tick + 1, `${clocks.length} /clock messages for end_tick ${session.end_tick}`);
  clocks.forEach(({ record, msg }, tick) => {
    check(record.logTime === tickNs(tick) && timeNs(msg.clock) === record.logTime,
          `/clock #${tick}: log time ${record.logTime}, clock ${timeNs(msg.clock)}, expected ${tickNs(tick)}`);
  });
  const poseTicks = Math.floor(session.end_tick / 2) + 1;  // 30 Hz at 60 ticks/s
  for (const topic of ['/tf', '/odom', '/people']) {
    check(byTopic.get(topic).length === poseTicks, `${byTopic.get(topic).length} ${topic} messages, expected ${poseTicks}`);
  }

  // /scan: the configured beams, a consistent angle_max, ten sweeps a second.
  const scans = byTopic.get('/scan');
  const sweeps = session.end_tick / 6;
  check(Math.abs(scans.length - sweeps) <= 2, `${scans.length} /scan messages in ${session.end_tick} ticks (10 Hz)`);
  for (const { msg } of scans) {
    const n = msg.ranges.length;
    check(n === beams, `/scan has ${n} ranges, the scenario's lidar ${beams} beams`);
    const angleMax = msg.angle_min + (n - 1) * msg.angle_increment;
    check(Math.abs(msg.angle_max - angleMax) <= 1e-6,
          `/scan angle_max ${msg.angle_max}, angle_min + (n-1) * increment = ${angleMax}`);
  }

  // Latched topics once; /map's grid is whole.
  for (const topic of ['/map', '/scene_markers']) check(byTopic.get(topic).length === 1, `${topic} ${byTopic.get(topic).length} times`);
  const map = byTopic.get('/map')[0].msg;
  check(map.data.length === map.info.width * map.info.height && map.data.length > 0,
        `/map: ${map.data.length} cells for ${map.info.width} x ${map.info.height}`);

  // /events: events.jsonl, line for line.
  const lines = fs.readFileSync(path.join(dir, 'events.jsonl'), 'utf8').split('\n').filter((l) => l.length > 0);
  const events = byTopic.get('/events').map(({ msg }) => msg.data);
  check(events.length === lines.length, `${events.length} /events messages, ${lines.length} events.jsonl lines`);
  events.forEach((data, i) => check(data === lines[i], `/events #${i} '${data}' != events.jsonl '${lines[i]}'`));
  check(readEvents(dir).length === lines.length, 'events.jsonl does not parse');
  log(`content: ${clocks.length} ticks, ${scans.length} scans of ${beams} beams, ${events.length} events`);
}

// docs/ros.md: every header stamp (and each /tf transform's) is the message's log time.
function checkStamps(byTopic) {
  const wrong = [];
  for (const [topic, entries] of byTopic) {
    const stamps = (msg) => (topic === '/tf' ? msg.transforms.map((t) => t.header.stamp) : msg.header ? [msg.header.stamp] : []);
    // A scan is stamped when the sweep was taken (as a driver stamps it) and published, hence logged, after the tick
    // that cast it: exactly one tick later. Every other stamp is its log time.
    const lag = topic === '/scan' ? tickNs(1) : 0n;
    const off = entries.filter(({ record, msg }) => stamps(msg).some((stamp) => timeNs(stamp) + lag !== record.logTime));
    if (off.length > 0) {
      const { record, msg } = off[0];
      wrong.push(`${topic} ${off.length} of ${entries.length} (first: stamp ${timeNs(stamps(msg)[0])}, log time ${record.logTime})`);
    }
  }
  check(wrong.length === 0, `header stamps that are not the log time (a tick before it for /scan): ${wrong.join('; ')}`);
}

// Every trajectories.csv row against /tf and /people at its tick.
function checkPoses(byTopic, dir) {
  const tfAt = new Map();  // log time -> Map child frame -> { x, y, yaw }
  for (const { record, msg } of byTopic.get('/tf')) {
    tfAt.set(record.logTime, new Map(msg.transforms.map((t) => [t.child_frame_id,
      { x: t.transform.translation.x, y: t.transform.translation.y, yaw: yawOf(t.transform.rotation) }])));
  }
  const peopleAt = new Map();  // log time -> Map name -> { x, y }
  for (const { record, msg } of byTopic.get('/people')) {
    peopleAt.set(record.logTime, new Map(msg.people.map((p) => [p.name, p.position])));
  }
  const rows = readTrajectories(dir);
  check(rows.length > 0, 'trajectories.csv is empty');
  const counts = { robot: 0, avatar: 0, person: 0 };
  for (const row of rows) {
    const where = `trajectories.csv ${row.kind} ${row.id} at tick ${row.tick}`;
    const frame = row.kind === 'robot' ? 'robot_truth' : row.kind === 'avatar' ? 'avatar' : `person_${row.id}`;
    const tf = tfAt.get(tickNs(row.tick))?.get(frame);
    check(tf, `${where}: no /tf map->${frame} at that tick`);
    check(Math.abs(tf.x - row.x) <= POSE_TOLERANCE && Math.abs(tf.y - row.y) <= POSE_TOLERANCE &&
          Math.abs(angleDiff(tf.yaw, row.yaw)) <= POSE_TOLERANCE,
          `${where}: (${row.x}, ${row.y}, ${row.yaw}), /tf says (${tf.x}, ${tf.y}, ${tf.yaw})`);
    if (row.kind !== 'robot') {
      const name = row.kind === 'avatar' ? 'avatar' : `person_${row.id}`;
      const p = peopleAt.get(tickNs(row.tick))?.get(name);
      check(p && Math.abs(p.x - row.x) <= POSE_TOLERANCE && Math.abs(p.y - row.y) <= POSE_TOLERANCE,
            `${where}: /people ${name} is ${JSON.stringify(p)}`);
    }
    counts[row.kind] += 1;
  }
  check(counts.robot > 0 && counts.avatar > 0 && counts.person > 0, `rows per kind ${JSON.stringify(counts)}`);
  log(`poses: ${rows.length} trajectories.csv rows equal the bag (${JSON.stringify(counts)})`);
}

async function checkFinished(pkgs, dir, beams) {
  const file = path.join(dir, 'session.mcap');
  check(fs.existsSync(file), `${file} was not written`);
  const idx = await readIndexed(pkgs, file);
  const st = readStreamed(pkgs, file);
  checkContainer(idx, st);
  checkOrder(st);
  const byTopic = decodeAll(st, schemaDecoders(pkgs, st.schemas));
  checkContent(byTopic, dir, beams);
  checkPoses(byTopic, dir);
  return byTopic;
}

async function checkKilled(pkgs, dir) {
  const file = path.join(dir, 'session.mcap');
  check(fs.existsSync(file), `${file} was not written`);
  const st = readStreamed(pkgs, file);
  check(st.error === null, `streaming reader on the killed bag: ${st.error}`);
  check(!st.complete, 'the killed bag has a footer: was it killed?');
  check(st.chunks.length >= 1 && st.messages.length > 0, `the killed bag has ${st.chunks.length} complete chunks`);
  const times = st.messages.map((m) => m.logTime);
  const span = times[times.length - 1] - times[0];
  check(span >= 1_000_000_000n, `the killed bag's complete chunks hold ${Number(span) / 1e9} s, expected >= 1 s`);
  decodeAll(st, schemaDecoders(pkgs, st.schemas));
  let indexedError = null;
  try {
    await readIndexed(pkgs, file);
  } catch (err) {
    indexedError = err.message;
  }
  check(indexedError !== null, 'the indexed reader read a bag that has no summary');
  log(`killed bag: ${st.chunks.length} complete chunks, ${Number(span) / 1e9} s of messages, all decode; ` +
      `the indexed reader refuses it as expected (${indexedError})`);
}

runTest('ros_mcap_session', 90_000, async () => {
  const env = parseArgs('mcap_session');
  const pkgs = loadBagPackages(env.require);
  const yaml = env.require('yaml');
  const base = ['--scenario', 'warehouse', '--port', '0', '--rfb-only'];
  const fullDir = path.join(env.artifacts, 'finished');
  const killedDir = path.join(env.artifacts, 'killed');

  // Both at once: the test takes as long as the longer one.
  const [full, killed] = await Promise.all([
    Sim.start(env.simPath, [...base, '--data-dir', fullDir], env.artifacts, 'sim_finished'),
    Sim.start(env.simPath, [...base, '--data-dir', killedDir], env.artifacts, 'sim_killed'),
  ]);
  await sleep(KILLED_RUN_MS);
  await killed.stop('SIGKILL');
  await sleep(FULL_RUN_MS - KILLED_RUN_MS);
  await full.stopCleanly();

  const session = JSON.parse(fs.readFileSync(path.join(fullDir, 'session.json'), 'utf8'));
  const byTopic = await checkFinished(pkgs, fullDir, expectedBeams(yaml, session.scenario_file));
  await checkKilled(pkgs, killedDir);
  checkStamps(byTopic);
});
