// SPDX-License-Identifier: GPL-2.0-or-later
// Every schema rfbsim writes parses with @foxglove/rosmsg (ROS 2 mode), and every CDR message decodes with
// @foxglove/rosmsg2-serialization's MessageReader to the values of rfbsim's rosbridge JSON: the same field
// names, the same numbers (float32 fields compared after rounding to float32; JSON null = NaN or infinite).
// These are the readers Foxglove and Lichtblick use for ros2msg/cdr channels.
//
// usage: node ros_msgs_decode.mjs SAMPLES_EXECUTABLE WEB_DIR

import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { createRequire } from 'node:module';
import path from 'node:path';

const [samplesExe, webDir] = process.argv.slice(2);
if (!samplesExe || !webDir) {
  console.error('usage: node ros_msgs_decode.mjs SAMPLES_EXECUTABLE WEB_DIR');
  process.exit(2);
}
const require = createRequire(path.join(path.resolve(webDir), 'package.json'));
let parse, MessageReader;
try {
  ({ parse } = require('@foxglove/rosmsg'));
  ({ MessageReader } = require('@foxglove/rosmsg2-serialization'));
} catch (e) {
  console.error(`ros_msgs_decode: the npm ROS readers are missing from ${webDir}/node_modules ` +
                `(npm ci --prefix web): ${e.message}`);
  process.exit(1);
}

// Decoded values in plain form: typed arrays as arrays; a Time as {sec, nanosec} whichever name the reader uses.
function plain(value) {
  if (ArrayBuffer.isView(value)) return Array.from(value, plain);
  if (Array.isArray(value)) return value.map(plain);
  if (value && typeof value === 'object') {
    const out = {};
    for (const [k, v] of Object.entries(value)) out[k === 'nsec' ? 'nanosec' : k] = plain(v);
    return out;
  }
  return typeof value === 'bigint' ? Number(value) : value;
}

// Compares decoded `got` with rfbsim's JSON `want` at `where`; throws naming the first difference.
function same(got, want, where) {
  if (want === null) {
    assert.ok(typeof got === 'number' && !Number.isFinite(got), `${where}: JSON null, but decoded ${got}`);
    return;
  }
  if (Array.isArray(want)) {
    assert.ok(Array.isArray(got), `${where}: expected an array, decoded ${JSON.stringify(got)}`);
    assert.equal(got.length, want.length, `${where}: length`);
    want.forEach((w, i) => same(got[i], w, `${where}[${i}]`));
    return;
  }
  if (typeof want === 'object') {
    assert.ok(got && typeof got === 'object', `${where}: expected an object, decoded ${got}`);
    assert.deepEqual(Object.keys(got).sort(), Object.keys(want).sort(), `${where}: field names`);
    for (const k of Object.keys(want)) same(got[k], want[k], `${where}.${k}`);
    return;
  }
  if (typeof want === 'number' && typeof got === 'number' && got !== want) {
    // A float32 field decodes to the float32 value; the JSON holds the same float32 widened to a double.
    assert.equal(Math.fround(got), Math.fround(want), `${where}: ${got} != ${want}`);
    assert.equal(got, Math.fround(want), `${where}: ${got} != ${want}`);
    return;
  }
  assert.equal(got, want, where);
}

const output = execFileSync(samplesExe, { encoding: 'utf8', maxBuffer: 64 << 20 });
const samples = output.split('\n').filter((line) => line.length > 0).map((line) => JSON.parse(line));
const types = new Set();
for (const sample of samples) {
  const where = `${sample.name} (${sample.type})`;
  const definitions = parse(sample.schema, { ros2: true });
  assert.ok(definitions.length > 0, `${where}: the schema parsed to nothing`);
  const reader = new MessageReader(definitions);
  const decoded = plain(reader.readMessage(Buffer.from(sample.cdr, 'hex')));
  same(decoded, sample.json, where);
  types.add(sample.type);
}

// Every published type and the stamped velocity command were checked, both hand-made and sampled.
const expected = ['rosgraph_msgs/msg/Clock', 'tf2_msgs/msg/TFMessage', 'nav_msgs/msg/Odometry',
  'sensor_msgs/msg/LaserScan', 'nav_msgs/msg/OccupancyGrid', 'visualization_msgs/msg/MarkerArray',
  'geometry_msgs/msg/Twist', 'people_msgs/msg/People', 'nav_msgs/msg/Path', 'geometry_msgs/msg/PoseStamped',
  'std_msgs/msg/String', 'geometry_msgs/msg/TwistStamped'];
assert.deepEqual([...types].sort(), expected.sort());
const sampledTopics = samples.filter((s) => s.name.startsWith('sampled ')).map((s) => s.name.slice(8));
assert.deepEqual(sampledTopics.sort(), ['/clock', '/cmd_vel', '/events', '/goal_pose', '/map', '/odom', '/people',
  '/plan', '/scan', '/scene_markers', '/tf'].sort());
console.log(`ros_msgs_decode: ${samples.length} messages of ${types.size} types decode to their JSON`);
