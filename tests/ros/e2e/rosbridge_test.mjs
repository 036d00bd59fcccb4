// SPDX-License-Identifier: GPL-2.0-or-later
// ros_rosbridge: sim_rfb's rosbridge v2 server (docs/ros.md) with a Node `ws` client over loopback.
//
// Under --robot-control external (warehouse, no crowd, the robot at cross_west facing the open cross aisle):
// subscribing to /scan, /odom, /tf and /clock brings each topic's messages; 1.5 s of Twist (v 0.3, 20 Hz)
// moves the robot forward at 0.3 m/s along its heading in trajectories.csv; 1.5 s of TwistStamped
// (v 0.2, w 0.5) turns it counter-clockwise; when the commands stop, the watchdog stops the robot 0.5 s
// later (events.jsonl's `robot` event) and it stays still. Every command is in events.jsonl as a
// `robot_command` with its v, w and source. Malformed JSON, an unknown op, a field of the wrong type and a
// /cmd_vel message of the wrong shape each get an error status; a 2 MiB message gets one and the close
// (1009); a second connection is served after all that.
//
// sim_replay then rebuilds the externally driven session from its robot_command events, and every pose comes out
// the same (it exits non-zero when one differs).
//
// Under --robot-control builtin: /cmd_vel publishes get one warning status (never an error) and no
// robot_command is recorded.

import { execFileSync } from 'node:child_process';
import path from 'node:path';

import { Rosbridge, Sim, angleDiff, check, log, parseArgs, readEvents, robotRows, runTest,
         sleep } from './ros_e2e_support.mjs';

const SEND_HZ = 20;
const SENDS_PER_PHASE = 30;  // 1.5 s at 20 Hz
const STALE_DETAIL = 'external control: no command for 0.50 s, stopped';
const TICK_HZ = 60;

const twist = (v, w) => ({ linear: { x: v, y: 0, z: 0 }, angular: { x: 0, y: 0, z: w } });

// Publishes `msg` on /cmd_vel SENDS_PER_PHASE times at SEND_HZ.
async function publishPhase(bridge, msg) {
  for (let i = 0; i < SENDS_PER_PHASE; ++i) {
    bridge.send({ op: 'publish', topic: '/cmd_vel', msg });
    await sleep(1000 / SEND_HZ);
  }
}

// Subscribes to the sensor topics and checks one message of each.
async function checkSubscriptions(bridge) {
  const from = bridge.mark();
  bridge.send({ op: 'subscribe', id: 's1', topic: '/scan', type: 'sensor_msgs/msg/LaserScan' });
  bridge.send({ op: 'subscribe', id: 's2', topic: '/odom', type: 'nav_msgs/Odometry' });
  bridge.send({ op: 'subscribe', id: 's3', topic: '/tf' });
  bridge.send({ op: 'subscribe', id: 's4', topic: '/clock' });
  const scan = (await bridge.waitForPublish('/scan', 3000, from)).msg;
  check(scan.ranges.length === 360 && scan.header.frame_id === 'base_link',
        `/scan: ${scan.ranges.length} ranges in frame '${scan.header.frame_id}'`);
  const odom = (await bridge.waitForPublish('/odom', 3000, from)).msg;
  check(odom.header.frame_id === 'odom' && odom.child_frame_id === 'base_link', `/odom frames ${odom.header.frame_id}`);
  const tf = (await bridge.waitForPublish('/tf', 3000, from)).msg;
  const frames = tf.transforms.map((t) => t.child_frame_id);
  check(['odom', 'base_link', 'robot_truth', 'avatar'].every((f) => frames.includes(f)), `/tf frames ${frames}`);
  const clock = (await bridge.waitForPublish('/clock', 3000, from)).msg;
  check(Number.isInteger(clock.clock.sec) && Number.isInteger(clock.clock.nanosec), `/clock ${JSON.stringify(clock)}`);
  for (const topic of ['/scan', '/odom', '/tf', '/clock']) bridge.send({ op: 'unsubscribe', topic });
  check(bridge.statuses('error', from).length === 0, `errors: ${JSON.stringify(bridge.statuses('error', from))}`);
  log('subscribed: /scan (360 beams), /odom, /tf and /clock each arrived');
}

// Bad input on one connection: an error status for each, a close for the oversized one.
async function checkBadInput(WebSocket, url) {
  const bad = await Rosbridge.connect(WebSocket, url, 'bad client');
  const cases = [
    ['malformed JSON', () => bad.sendText('{"op": "subscribe", "topic": ')],
    ['an unknown op', () => bad.send({ op: 'frobnicate', id: 'x1' })],
    ['a topic that is a number', () => bad.send({ op: 'subscribe', topic: 42 })],
    ['a /cmd_vel of the wrong shape', () => bad.send({ op: 'publish', topic: '/cmd_vel', type: 'geometry_msgs/Twist',
                                                       msg: { linear: { x: 'fast' }, angular: { z: [] } } })],
  ];
  for (const [what, send] of cases) {
    const from = bad.mark();
    send();
    const status = await bad.waitForStatus('error', 3000, from);
    log(`${what}: error status '${status.msg}'`);
  }
  const from = bad.mark();
  bad.sendText(JSON.stringify({ op: 'publish', topic: '/cmd_vel', msg: { pad: 'x'.repeat(2 << 20) } }));
  const closed = await Promise.race([bad.closed, sleep(5000).then(() => null)]);
  check(closed !== null, 'a 2 MiB message did not close the connection');
  check(closed.code === 1009, `a 2 MiB message closed the connection with ${closed.code}, expected 1009`);
  check(bad.statuses('error', from).length === 1, 'no error status before the oversize close');
  check(bad.badFrames.length === 0, `frames that are not JSON: ${bad.badFrames}`);

  const again = await Rosbridge.connect(WebSocket, url, 'second client');
  again.send({ op: 'subscribe', topic: '/clock' });
  await again.waitForPublish('/clock', 3000);
  log('oversized message: error status and close 1009; a second connection is still served');
}

// Robot rows of trajectories.csv with first <= tick <= last.
const rowsBetween = (rows, first, last) => rows.filter((r) => r.tick >= first && r.tick <= last);
const speed = (row) => Math.hypot(row.vx, row.vy);

// trajectories.csv and events.jsonl after the drive: forward, turning, stopped by the watchdog.
function checkDrive(dir) {
  const events = readEvents(dir);
  const commands = events.filter((e) => e.type === 'robot_command');
  const forward = commands.filter((c) => c.v === 0.3 && c.w === 0);
  const turning = commands.filter((c) => c.v === 0.2 && c.w === 0.5);
  // sim_rfb records only the last command taken in per pass of its loop, so two sends that a loaded machine
  // delivers together count once: most, not all, of them are recorded, and each as it was sent.
  const most = (n) => n >= 0.8 * SENDS_PER_PHASE && n <= SENDS_PER_PHASE;
  check(most(forward.length) && most(turning.length) && commands.length === forward.length + turning.length,
        `robot_command events: ${forward.length} Twist, ${turning.length} TwistStamped, ${commands.length} in all`);
  check(commands.every((c) => c.source === 'rosbridge'), `sources ${[...new Set(commands.map((c) => c.source))]}`);
  const ramp = Math.round(0.6 * TICK_HZ);  // 0.3 m/s at 1 m/s^2 takes 0.3 s: twice that, to be sure
  // A stall of this test or of sim_rfb longer than the watchdog's 0.5 s stops the robot mid-phase, as it should;
  // the rows until it is back up to speed are not judged.
  const stalls = events.filter((e) => e.type === 'robot' && e.detail === STALE_DETAIL).map((e) => e.tick);
  const rows = robotRows(dir).filter((r) => !stalls.some((t) => r.tick >= t && r.tick <= t + 2 * ramp) ||
                                             r.tick > commands[commands.length - 1].tick);
  if (stalls.length > 1) log(`note: the watchdog also fired mid-drive at ticks ${stalls.slice(0, -1)} (a stall)`);

  // Forward: 0.3 m/s along its heading once up to speed, and moved that way.
  const [a0, a1] = [forward[0].tick, forward[forward.length - 1].tick];
  const cruising = rowsBetween(rows, a0 + ramp, a1);
  check(cruising.length >= 5, `only ${cruising.length} rows while cruising (ticks ${a0 + ramp}..${a1})`);
  for (const r of cruising) {
    const along = (r.vx * Math.cos(r.yaw) + r.vy * Math.sin(r.yaw)) / Math.max(speed(r), 1e-9);
    check(Math.abs(speed(r) - 0.3) <= 0.03 && along > 0.99,
          `tick ${r.tick}: speed ${speed(r).toFixed(3)} m/s, cos(angle to heading) ${along.toFixed(3)}`);
  }
  const start = rowsBetween(rows, 0, a0).pop();
  const end = rowsBetween(rows, a1, Infinity)[0];
  const [dx, dy] = [end.x - start.x, end.y - start.y];
  const ahead = dx * Math.cos(start.yaw) + dy * Math.sin(start.yaw);
  check(ahead > 0.3 && ahead > 0.95 * Math.hypot(dx, dy), `forward phase moved (${dx.toFixed(3)}, ${dy.toFixed(3)}), ` +
        `${ahead.toFixed(3)} m along the heading`);
  log(`Twist v 0.3: ${cruising.length} rows at 0.3 m/s, ${ahead.toFixed(2)} m ahead`);

  // Turning: yaw grows at about 0.5 rad/s.
  const [b0, b1] = [turning[0].tick, turning[turning.length - 1].tick];
  for (const r of rowsBetween(rows, b0 + ramp, b1)) {
    check(Math.abs(speed(r) - 0.2) <= 0.03, `tick ${r.tick}: speed ${speed(r).toFixed(3)} m/s while turning`);
  }
  const before = rowsBetween(rows, 0, b0).pop();
  const after = rowsBetween(rows, b1, Infinity)[0];
  const turned = angleDiff(after.yaw, before.yaw);
  const expected = 0.5 * (after.tick - before.tick) / TICK_HZ;
  check(turned > 0.6 * expected && turned < 1.1 * expected, `TwistStamped w 0.5 turned ${turned.toFixed(3)} rad ` +
        `over ticks ${before.tick}..${after.tick} (${expected.toFixed(3)} at full rate)`);
  log(`TwistStamped w 0.5: turned ${turned.toFixed(2)} rad counter-clockwise`);

  // Stale: the watchdog's event 0.5 s after the last command, and no motion once braked.
  const stale = events.find((e) => e.type === 'robot' && e.detail === STALE_DETAIL && e.tick > b1);
  check(stale, `no robot event '${STALE_DETAIL}' after the last command (tick ${b1})`);
  check(stale.tick - b1 >= 28 && stale.tick - b1 <= 34, `the watchdog fired ${stale.tick - b1} ticks after the last command`);
  const stopped = rowsBetween(rows, stale.tick + ramp, Infinity);
  check(stopped.length >= 3, `only ${stopped.length} rows after the robot stopped`);
  stopped.forEach((r, i) => {
    check(speed(r) < 0.005, `tick ${r.tick}: still moving at ${speed(r).toFixed(4)} m/s after the watchdog`);
    if (i > 0) check(Math.abs(angleDiff(r.yaw, stopped[i - 1].yaw)) < 1e-4, `tick ${r.tick}: still turning`);
  });
  log(`stale commands: stopped ${stale.tick - b1} ticks after the last one, still for ${stopped.length} rows`);
}

// Builtin control: a warning, once, and nothing recorded.
async function checkBuiltin(WebSocket, sim, dir) {
  const bridge = await Rosbridge.connect(WebSocket, await sim.rosbridgeUrl(), 'builtin client');
  bridge.send({ op: 'advertise', topic: '/cmd_vel', type: 'geometry_msgs/msg/Twist' });
  for (let i = 0; i < 5; ++i) {
    bridge.send({ op: 'publish', topic: '/cmd_vel', msg: twist(0.3, 0) });
    await sleep(50);
  }
  const warning = await bridge.waitForStatus('warning', 3000);
  await sleep(500);  // time for a second warning, which must not come
  check(bridge.statuses('warning').length === 1, `${bridge.statuses('warning').length} warnings, expected one`);
  check(bridge.statuses('error').length === 0, `errors under builtin control: ${JSON.stringify(bridge.statuses('error'))}`);
  await sim.stopCleanly();
  const recorded = readEvents(dir).filter((e) => e.type === 'robot_command');
  check(recorded.length === 0, `${recorded.length} robot_command events under builtin control`);
  log(`builtin control: one warning ('${warning.msg}'), no robot_command recorded`);
}

runTest('ros_rosbridge', 90_000, async () => {
  const env = parseArgs('rosbridge');
  const WebSocket = env.require('ws');
  const base = ['--scenario', 'warehouse', '--port', '0', '--rfb-only', '--crowd', '0', '--rosbridge-port', '0'];
  const externalDir = path.join(env.artifacts, 'external');
  const builtinDir = path.join(env.artifacts, 'builtin');
  const [external, builtin] = await Promise.all([
    Sim.start(env.simPath, [...base, '--robot-start', 'cross_west', '--robot-control', 'external',
                            '--data-dir', externalDir], env.artifacts, 'sim_external'),
    Sim.start(env.simPath, [...base, '--robot-control', 'builtin', '--data-dir', builtinDir], env.artifacts,
              'sim_builtin'),
  ]);
  await checkBuiltin(WebSocket, builtin, builtinDir);

  const url = await external.rosbridgeUrl();
  const bridge = await Rosbridge.connect(WebSocket, url, 'client');
  await checkSubscriptions(bridge);

  // Drive: Twist (the short type name), then TwistStamped (the long one), then nothing.
  const from = bridge.mark();
  bridge.send({ op: 'advertise', topic: '/cmd_vel', type: 'geometry_msgs/Twist' });
  await publishPhase(bridge, twist(0.3, 0));
  bridge.send({ op: 'advertise', topic: '/cmd_vel', type: 'geometry_msgs/msg/TwistStamped' });
  await publishPhase(bridge, { header: { stamp: { sec: 0, nanosec: 0 }, frame_id: 'base_link' }, twist: twist(0.2, 0.5) });
  check(bridge.statuses('error', from).length === 0 && bridge.statuses('warning', from).length === 0,
        `statuses while driving: ${JSON.stringify(bridge.statuses(null, from))}`);
  await sleep(1500);  // the watchdog (0.5 s) and braking, with rows to show it

  await checkBadInput(WebSocket, url);
  check(external.alive, 'sim_rfb died');
  await external.stopCleanly();
  checkDrive(externalDir);

  // The replay drives the robot as the controller did, from events.jsonl alone.
  const replayPath = process.argv[6];
  check(replayPath, 'usage: ... SIM_REPLAY (the 5th argument) is missing');
  let replayOutput = '';
  try {
    replayOutput = execFileSync(replayPath, [externalDir, '--check-only', '--out-dir', path.join(env.artifacts, 'replay')],
                                { encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'] });
  } catch (err) {
    check(false, `sim_replay of the externally driven session failed: ${err.stderr || err.message}`);
  }
  check(/poses match the log/.test(replayOutput), `sim_replay said: ${replayOutput}`);
  log(`replay: ${replayOutput.trim().split('\n')[0]}`);
});
