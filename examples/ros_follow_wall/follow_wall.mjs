#!/usr/bin/env node
// SPDX-License-Identifier: GPL-2.0-or-later
// follow_wall.mjs: a small external controller for rfbsim's robot, to copy and change. It speaks rosbridge v2
// (JSON over a WebSocket) to sim_rfb --rosbridge-port, or to a lab's rosbridge_server: it subscribes to
// /scan and, on every scan, publishes a geometry_msgs/Twist on /cmd_vel that keeps a wall at a set distance
// on one side (a proportional law on the distance and on the angle to the wall) and stops and turns in
// place when something is close in front. It stops the robot and exits 0 after --duration seconds of
// simulated time (the scans' stamps), or at Ctrl-C.
//
//   node follow_wall.mjs --url ws://127.0.0.1:9090/ [--namespace /ns] [--side left|right] [--distance 0.6]
//                        [--speed 0.3] [--duration S] [--stamped yes|no]
//
// It needs the `ws` package: from a node_modules folder above this file, from NODE_PATH, or from rfbsim's
// web/node_modules (npm ci --prefix web). See README.md.

import { createRequire } from 'node:module';
import path from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const DEG = Math.PI / 180;

// ---------------------------------------------------------------------------------------------------------------
// The control law: a pure function of one scan, so it can be read (and tested) apart from the socket.
// ---------------------------------------------------------------------------------------------------------------

/// Default settings of the wall follower. Distances in metres from the lidar (the robot's centre), speeds
/// in m/s and rad/s, angles in radians.
export const DEFAULTS = {
  side: 'left',      // which side the wall is kept on
  distance: 0.6,     // wanted distance to the wall
  speed: 0.3,        // forward speed on a clear straight
  maxTurn: 1.0,      // largest turn rate
  stopFront: 0.5,    // closer than this ahead: stop and turn away from the wall
  slowFront: 1.3,    // closer than this ahead: slow down and start turning away
  lostWall: 2.5,     // no return nearer than this on the side: there is no wall there
  gainDistance: 0.8, // rad of approach angle per metre of distance error...
  maxApproach: 0.5,  // ...at most this steep (about 30 degrees)
  gainAngle: 1.5,    // rad/s of turn per radian between the heading wanted and the heading now
};

// The range along `angle` (rad, counter-clockwise from straight ahead), or Infinity when that beam saw
// nothing. rosbridge sends a non-finite float as null.
function rangeAt(scan, angle) {
  const n = scan.ranges.length;
  const fullCircle = Math.abs(n * scan.angle_increment - 2 * Math.PI) < 1e-3;
  let i = Math.round((angle - scan.angle_min) / scan.angle_increment);
  if (fullCircle) i = ((i % n) + n) % n;
  if (i < 0 || i >= n) return Infinity;
  const r = scan.ranges[i];
  return r === null || !Number.isFinite(r) || r < scan.range_min || r >= scan.range_max ? Infinity : r;
}

// The nearest return between two angles (rad, in either order).
function nearest(scan, from, to) {
  let best = Infinity;
  const step = Math.abs(scan.angle_increment);
  for (let a = Math.min(from, to); a <= Math.max(from, to) + 1e-9; a += step) best = Math.min(best, rangeAt(scan, a));
  return best;
}

/// One step of the wall follower: a sensor_msgs/LaserScan (as rosbridge sends it) in, { v, w, why } out.
export function followWall(scan, settings = DEFAULTS) {
  const s = settings.side === 'right' ? -1 : 1;  // mirror every angle and the turn for a wall on the right
  const clamp = (x, lo, hi) => Math.min(hi, Math.max(lo, x));
  const deg = (d) => s * d * DEG;

  // Something close ahead, or at the robot's shoulders: stop and turn away from the wall.
  const front = nearest(scan, -20 * DEG, 20 * DEG);
  const shoulders = Math.min(nearest(scan, 20 * DEG, 60 * DEG), nearest(scan, -60 * DEG, -20 * DEG));
  if (front < settings.stopFront || shoulders < 0.6 * settings.stopFront) {
    return { v: 0, w: -s * settings.maxTurn, why: 'blocked ahead: turning away from the wall' };
  }

  // The wall from two beams: square to our side (a, 90 deg) and 40 deg ahead of that (b, 50 deg). Their hits
  // give the wall's angle to our heading (0 when parallel, > 0 when it bends away from us) and our distance
  // to it. Too far, we head toward it, too near away from it, at most maxApproach; the turn steers the
  // heading there.
  const a = rangeAt(scan, deg(90));
  const b = rangeAt(scan, deg(50));
  let w;
  let why;
  if (a <= settings.lostWall) {
    const seen = b <= settings.lostWall / Math.sin(50 * DEG);
    const wallAngle = seen ? Math.atan2(b * Math.sin(50 * DEG) - a, b * Math.cos(50 * DEG)) : 0;
    const distance = a * Math.cos(wallAngle);
    const approach = clamp(settings.gainDistance * (distance - settings.distance), -settings.maxApproach, settings.maxApproach);
    w = s * settings.gainAngle * (wallAngle + approach);
    why = seen ? `wall at ${distance.toFixed(2)} m, ${(wallAngle / DEG).toFixed(0)} deg` : 'wall ends ahead';
  } else if (nearest(scan, deg(100), deg(160)) <= settings.lostWall) {
    // The wall ended just behind us (an outer corner): go round its end at the wanted distance.
    w = s * settings.speed / settings.distance;
    why = 'rounding the end of the wall';
  } else {
    w = 0;  // no wall at all: straight on until one comes up ahead, then turn to put it on our side
    why = 'looking for a wall';
  }

  // Something ahead, not yet close: turn away from the wall in proportion, and slow down.
  const closing = (settings.slowFront - front) / (settings.slowFront - settings.stopFront);
  if (closing > 0) w -= s * settings.maxTurn * closing;
  w = clamp(w, -settings.maxTurn, settings.maxTurn);
  const v = settings.speed * clamp(1 - closing, 0.2, 1) * Math.max(0.25, 1 - Math.abs(w) / settings.maxTurn);
  return { v, w, why };
}

// ---------------------------------------------------------------------------------------------------------------
// The command line and the rosbridge conversation.
// ---------------------------------------------------------------------------------------------------------------

const USAGE = 'usage: node follow_wall.mjs --url ws://HOST:PORT/ [--namespace /ns] [--side left|right] ' +
              '[--distance M] [--speed M_PER_S] [--duration S] [--stamped yes|no]';

function parseOptions(argv) {
  const options = { url: null, namespace: '', duration: Infinity, stamped: false, ...DEFAULTS };
  const number = (flag, text, min) => {
    const value = Number(text);
    if (!Number.isFinite(value) || value <= min) throw new Error(`${flag} wants a number above ${min}, not '${text}'`);
    return value;
  };
  for (let i = 0; i < argv.length; i += 2) {
    const [flag, value] = [argv[i], argv[i + 1]];
    if (value === undefined) throw new Error(`${flag} needs a value`);
    if (flag === '--url') options.url = value;
    else if (flag === '--namespace') options.namespace = value.replace(/\/+$/, '');
    else if (flag === '--side' && (value === 'left' || value === 'right')) options.side = value;
    else if (flag === '--distance') options.distance = number(flag, value, 0.2);
    else if (flag === '--speed') options.speed = number(flag, value, 0);
    else if (flag === '--duration') options.duration = number(flag, value, 0);
    else if (flag === '--stamped' && (value === 'yes' || value === 'no')) options.stamped = value === 'yes';
    else throw new Error(`unknown option or value: ${flag} ${value}`);
  }
  if (!/^wss?:\/\//.test(options.url ?? '')) throw new Error('--url ws://HOST:PORT/ is required');
  if (options.namespace !== '' && !options.namespace.startsWith('/')) throw new Error('--namespace must start with /');
  return options;
}

// The `ws` package: beside this file or on NODE_PATH first, else rfbsim's web/node_modules.
function loadWebSocket() {
  for (const from of [import.meta.url, path.join(here, '..', '..', 'web', 'package.json')]) {
    try {
      return createRequire(from)('ws');
    } catch {
      // try the next place
    }
  }
  throw new Error("cannot find the 'ws' package: npm install ws, set NODE_PATH, or run npm ci --prefix web in rfbsim");
}

function run(options) {
  const WebSocket = loadWebSocket();
  const scanTopic = `${options.namespace}/scan`;
  const cmdTopic = `${options.namespace}/cmd_vel`;
  const ws = new WebSocket(options.url);
  let firstStamp = null;
  let scans = 0;
  let lastReport = -1;
  let finished = false;

  const plainTwist = (v, w) => ({ linear: { x: v, y: 0, z: 0 }, angular: { x: 0, y: 0, z: w } });
  // Jazzy-era stacks (nav2, ros2_control's diff drive) take /cmd_vel as TwistStamped: --stamped yes.
  let lastStamp = { sec: 0, nanosec: 0 };
  const twist = (v, w) => (options.stamped ? { header: { stamp: lastStamp, frame_id: 'base_link' }, twist: plainTwist(v, w) }
                                           : plainTwist(v, w));
  const cmdType = options.stamped ? 'geometry_msgs/msg/TwistStamped' : 'geometry_msgs/msg/Twist';
  const send = (op) => ws.send(JSON.stringify(op));

  // Stop the robot, then leave (the close waits for the stop to be sent).
  const finish = (code, message) => {
    if (finished) return;
    finished = true;
    clearTimeout(noScan);
    console.log(`follow_wall: ${message}`);
    if (ws.readyState === WebSocket.OPEN) {
      send({ op: 'publish', topic: cmdTopic, msg: twist(0, 0) });
      send({ op: 'unsubscribe', topic: scanTopic });
      ws.close(1000);
    }
    process.exitCode = code;
    setTimeout(() => process.exit(code), 2000).unref();
  };

  const noScan = setTimeout(() => finish(1, `no ${scanTopic} within 10 s`), 10_000);
  ws.on('open', () => {
    console.log(`follow_wall: connected to ${options.url}; keeping the wall on the ${options.side} at ${options.distance} m`);
    send({ op: 'advertise', topic: cmdTopic, type: cmdType });
    send({ op: 'subscribe', topic: scanTopic, type: 'sensor_msgs/msg/LaserScan' });
  });
  ws.on('message', (data) => {
    let op;
    try {
      op = JSON.parse(data.toString());
    } catch {
      console.log('follow_wall: the server sent something that is not JSON; ignored');
      return;
    }
    if (op.op === 'status' && (op.level === 'error' || op.level === 'warning')) {
      console.log(`follow_wall: server ${op.level}: ${op.msg}`);
    }
    if (op.op !== 'publish' || op.topic !== scanTopic || finished) return;
    clearTimeout(noScan);
    // Simulated time. ROS 2 stamps have sec/nanosec, ROS 1's (a Noetic rosbridge_server) secs/nsecs.
    const { sec = op.msg.header.stamp.secs, nanosec = op.msg.header.stamp.nsecs } = op.msg.header.stamp;
    const stamp = sec + nanosec * 1e-9;
    lastStamp = { sec, nanosec };
    firstStamp ??= stamp;
    const elapsed = stamp - firstStamp;
    if (elapsed >= options.duration) {
      finish(0, `done after ${elapsed.toFixed(1)} s of simulated time, ${scans} scans`);
      return;
    }
    const { v, w, why } = followWall(op.msg, options);
    send({ op: 'publish', topic: cmdTopic, msg: twist(v, w) });
    scans += 1;
    if (Math.floor(elapsed) !== lastReport) {
      lastReport = Math.floor(elapsed);
      console.log(`follow_wall: t ${elapsed.toFixed(1)} s  v ${v.toFixed(2)} m/s  w ${w.toFixed(2)} rad/s  (${why})`);
    }
  });
  ws.on('error', (err) => finish(1, `connection failed: ${err.message}`));
  ws.on('close', () => finish(finished ? process.exitCode : 1, 'the server closed the connection'));
  process.on('SIGINT', () => finish(0, 'interrupted'));
}

if (process.argv[1] && import.meta.url === pathToFileURL(path.resolve(process.argv[1])).href) {
  let options;
  try {
    options = parseOptions(process.argv.slice(2));
  } catch (err) {
    console.error(`follow_wall: ${err.message}\n${USAGE}`);
    process.exit(2);
  }
  run(options);
}
