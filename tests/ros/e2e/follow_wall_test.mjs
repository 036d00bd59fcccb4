// SPDX-License-Identifier: GPL-2.0-or-later
// ros_follow_wall: examples/ros_follow_wall/follow_wall.mjs, the example a lab copies, driving the robot.
//
// First its control law on hand-made scans (a wall too far, too near, parallel, something ahead); then the
// real thing: sim_rfb in the warehouse (no crowd; the robot at north_east, facing south down the corridor
// with the east wall on its left) under external control, the example keeping that wall at 0.6 m for
// 12 s of simulated time. The example exits 0, its commands drove the robot (robot_command events), the
// robot's path is longer than 1 m, and it never touched a wall or a shelf (no `contact` event between the
// robot and `static`).

import { spawn } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { pathToFileURL } from 'node:url';

import { Sim, check, log, parseArgs, readEvents, robotRows, runTest, sleep } from './ros_e2e_support.mjs';

const DURATION_S = 12;

// A 360-beam scan (beam 0 straight back, counter-clockwise, as sim_rfb lays it out) of a straight wall
// parallel to the heading at `wall` m on the left (side 1) or right (side -1), and of a wall across the way
// `front` m ahead.
function syntheticScan(wall, front = Infinity, side = 1) {
  const n = 360;
  const angleMin = -Math.PI;
  const increment = (2 * Math.PI) / n;
  const ranges = [];
  for (let i = 0; i < n; ++i) {
    const a = angleMin + i * increment;
    let r = Infinity;
    if (side * Math.sin(a) > 1e-6) r = Math.min(r, wall / (side * Math.sin(a)));
    if (Math.cos(a) > 1e-6) r = Math.min(r, front / Math.cos(a));
    ranges.push(r < 8 ? r : null);
  }
  return { angle_min: angleMin, angle_increment: increment, range_min: 0.05, range_max: 8, ranges };
}

function checkControlLaw(followWall, defaults) {
  const far = followWall(syntheticScan(1.2));
  const near = followWall(syntheticScan(0.35));
  const parallel = followWall(syntheticScan(0.6));
  const blocked = followWall(syntheticScan(0.6, 0.4));
  const right = followWall(syntheticScan(1.2, Infinity, -1), { ...defaults, side: 'right' });
  check(far.w > 0.3 && far.v > 0, `wall 1.2 m on the left: ${JSON.stringify(far)}, expected a left turn`);
  check(near.w < -0.2 && near.v > 0, `wall 0.35 m on the left: ${JSON.stringify(near)}, expected a right turn`);
  check(Math.abs(parallel.w) < 1e-6 && Math.abs(parallel.v - 0.3) < 1e-6, `wall at 0.6 m: ${JSON.stringify(parallel)}`);
  check(blocked.v === 0 && blocked.w < 0, `blocked ahead: ${JSON.stringify(blocked)}, expected a turn in place`);
  check(right.w < -0.3, `wall 1.2 m on the right, following it: ${JSON.stringify(right)}, expected a right turn`);
  log('control law: turns toward a far wall, away from a near one, straight when parallel, in place when blocked');
}

runTest('ros_follow_wall', 90_000, async () => {
  const env = parseArgs('follow_wall');
  const example = path.resolve(process.argv[5] ?? '');
  check(fs.existsSync(example), `the example is not at ${example} (4th argument)`);
  const { followWall, DEFAULTS } = await import(pathToFileURL(example).href);
  checkControlLaw(followWall, DEFAULTS);

  const dir = path.join(env.artifacts, 'session');
  const sim = await Sim.start(env.simPath, [
    '--scenario', 'warehouse', '--port', '0', '--rfb-only', '--crowd', '0', '--robot-start', 'north_east',
    '--robot-control', 'external', '--rosbridge-port', '0', '--data-dir', dir,
  ], env.artifacts, 'sim_follow_wall');
  const url = await sim.rosbridgeUrl();

  // The example, as a lab would run it; `ws` comes through NODE_PATH.
  const args = [example, '--url', url, '--side', 'left', '--distance', '0.6', '--duration', String(DURATION_S)];
  log(`running node ${args.map((a) => path.basename(a)).join(' ')}`);
  const logFile = fs.openSync(path.join(env.artifacts, 'follow_wall.log'), 'w');
  const child = spawn(process.execPath, args, { stdio: ['ignore', logFile, logFile],
                                                env: { ...process.env, NODE_PATH: env.nodeModules } });
  const exited = await Promise.race([
    new Promise((resolve) => child.on('exit', (code, signal) => resolve({ code, signal }))),
    sleep((DURATION_S + 25) * 1000).then(() => null),
  ]);
  if (exited === null) child.kill('SIGKILL');
  fs.closeSync(logFile);
  check(exited !== null, `follow_wall.mjs still running ${DURATION_S + 25} s after it started (see follow_wall.log)`);
  check(exited.code === 0, `follow_wall.mjs exited with ${JSON.stringify(exited)} (see follow_wall.log)`);
  await sim.stopCleanly();

  const events = readEvents(dir);
  const commands = events.filter((e) => e.type === 'robot_command');
  check(commands.length >= 8 * DURATION_S, `only ${commands.length} commands in ${DURATION_S} s (10 Hz expected)`);
  const touches = events.filter((e) => e.type === 'contact' &&
                                       ((e.a === 'robot' && e.b === 'static') || (e.a === 'static' && e.b === 'robot')));
  check(touches.length === 0, `the robot touched the walls: ${JSON.stringify(touches)}`);
  const rows = robotRows(dir);
  let travelled = 0;
  for (let i = 1; i < rows.length; ++i) travelled += Math.hypot(rows[i].x - rows[i - 1].x, rows[i].y - rows[i - 1].y);
  check(travelled > 1, `the robot travelled ${travelled.toFixed(2)} m`);
  const last = rows[rows.length - 1];
  log(`follow_wall.mjs: ${commands.length} commands, ${travelled.toFixed(2)} m without touching a wall, ending at ` +
      `(${last.x.toFixed(2)}, ${last.y.toFixed(2)})`);
});
