// SPDX-License-Identifier: GPL-2.0-or-later
// ros_roslib: sim_rfb's rosbridge server as roslibjs (npm roslib, the library most browser tools and lab
// scripts use) sees it, through roslib's own helpers rather than hand-written ops.
//
// Under --robot-control external (warehouse, no crowd, the robot at cross_west facing the open cross aisle):
//   - Ros.getTopics lists /scan, /odom, /tf and /clock with their types; getTopicType('/odom') names
//     nav_msgs' Odometry; getServices lists rosapi's services; getNodes names /rfbsim; getTopicsAndRawTypes
//     hands out /odom's definition, getMessageDetails its fields down to pose.pose.position.x. roslib names these services without the leading slash (rosapi/topics).
//   - A ROSLIB.Service call of a service we do not offer fails through its failed callback.
//   - Action.sendGoal's failed callback fires within 3 s (we offer no actions).
//   - Publishing Twists through a ROSLIB.Topic on /cmd_vel (v 0.3, 1.5 s at 20 Hz) moves the robot, as
//     /odom, subscribed through another ROSLIB.Topic, shows.
// roslib runs on Node's global WebSocket where there is one, else on `ws` (both in web/node_modules).

import path from 'node:path';
import { pathToFileURL } from 'node:url';

import { CheckFailed, Sim, atEnd, check, log, parseArgs, poll, runTest, sleep } from './ros_e2e_support.mjs';

// Resolves with what `start(resolve, reject)` hands its success callback; CheckFailed when it hands its failure
// callback something, or neither within `timeoutMs`.
function answer(what, start, timeoutMs = 3000) {
  let timer;
  return new Promise((resolve, reject) => {
    timer = setTimeout(() => reject(new CheckFailed(`${what}: no answer within ${timeoutMs} ms`)), timeoutMs);
    start(resolve, (err) => reject(new CheckFailed(`${what} failed: ${err}`)));
  }).finally(() => clearTimeout(timer));
}

// Resolves with what `start(resolve, reject)` hands its failure callback; CheckFailed when it succeeds or
// neither comes within `timeoutMs`.
function failure(what, start, timeoutMs = 3000) {
  let timer;
  return new Promise((resolve, reject) => {
    timer = setTimeout(() => reject(new CheckFailed(`${what}: no failure within ${timeoutMs} ms`)), timeoutMs);
    start((value) => reject(new CheckFailed(`${what} succeeded (${JSON.stringify(value)}), expected a failure`)),
          (err) => resolve(err));
  }).finally(() => clearTimeout(timer));
}

// Discovery through Ros's helpers, each a rosapi call named without the leading slash.
async function checkDiscovery(ROSLIB, ros) {
  const { topics, types } = await answer('getTopics', (ok, bad) => ros.getTopics(ok, bad));
  for (const name of ['/scan', '/odom', '/tf', '/clock']) {
    check(topics.includes(name), `getTopics lists no ${name}: ${JSON.stringify(topics)}`);
  }
  check(types.length === topics.length, `getTopics: ${topics.length} topics but ${types.length} types`);
  log(`getTopics: ${topics.length} topics (${topics.join(', ')})`);

  const odomType = await answer('getTopicType', (ok, bad) => ros.getTopicType('/odom', ok, bad));
  check(/^nav_msgs\/(msg\/)?Odometry$/.test(odomType), `getTopicType('/odom') is '${odomType}'`);
  check(types[topics.indexOf('/odom')] === odomType, 'getTopics and getTopicType disagree on /odom');

  const services = await answer('getServices', (ok, bad) => ros.getServices(ok, bad));
  check(Array.isArray(services) && services.includes('/rosapi/topics'), `getServices: ${JSON.stringify(services)}`);
  const nodes = await answer('getNodes', (ok, bad) => ros.getNodes(ok, bad));
  check(JSON.stringify(nodes) === JSON.stringify(['/rfbsim']), `getNodes: ${JSON.stringify(nodes)}`);

  const raw = await answer('getTopicsAndRawTypes', (ok, bad) => ros.getTopicsAndRawTypes(ok, bad));
  const odomDefinition = raw.typedefs_full_text[raw.topics.indexOf('/odom')] ?? '';
  check(odomDefinition.includes('pose') && odomDefinition.includes('twist'),
        `getTopicsAndRawTypes: /odom's definition is '${odomDefinition.slice(0, 200)}'`);
  log(`getTopicType('/odom') ${odomType}; getServices ${services.length}; getNodes ${nodes}; ` +
      `getTopicsAndRawTypes ${raw.topics.length} definitions`);

  // getMessageDetails, read back through roslib's own decodeTypeDefs down to a nested primitive.
  const typedefs = await answer('getMessageDetails', (ok, bad) => ros.getMessageDetails(odomType, ok, bad));
  const decoded = ros.decodeTypeDefs(typedefs);
  check(decoded?.pose?.pose?.position?.x === 'float64' && decoded?.child_frame_id === 'string',
        `getMessageDetails('${odomType}') decodes to ${JSON.stringify(decoded)}`);
  check(Array.isArray(decoded.pose.covariance), `/odom's pose.covariance is not an array: ${JSON.stringify(decoded)}`);
  log(`getMessageDetails: ${typedefs.length} typedefs, decoded fields ${Object.keys(decoded).join(', ')}`);

  // A service we do not offer, named either way, fails through the failed callback.
  for (const name of ['rosapi/get_param', '/spawn_entity']) {
    const service = new ROSLIB.Service({ ros, name, serviceType: 'std_srvs/srv/Trigger' });
    const why = await failure(`Service ${name}`, (ok, bad) => service.callService({}, ok, bad));
    log(`Service ${name}: failed with '${why}'`);
  }
  return odomType;
}

// An action goal fails at once through sendGoal's failed callback (rfbsim serves no actions).
async function checkAction(ROSLIB, ros) {
  const started = Date.now();
  const action = new ROSLIB.Action({ ros, name: '/navigate_to_pose', actionType: 'nav2_msgs/action/NavigateToPose' });
  const why = await failure('Action.sendGoal', (ok, bad) => action.sendGoal({ pose: {} }, ok, () => {}, bad));
  check(String(why).includes('/navigate_to_pose'), `sendGoal's failure does not name the action: '${why}'`);
  log(`Action.sendGoal: failed after ${Date.now() - started} ms with '${why}'`);
}

// Drives the robot through a ROSLIB.Topic and watches /odom through another.
async function checkDrive(ROSLIB, ros, odomType) {
  let latest = null;
  let fastest = 0;
  const odom = new ROSLIB.Topic({ ros, name: '/odom', messageType: odomType });
  odom.subscribe((msg) => {
    latest = msg;
    fastest = Math.max(fastest, msg.twist.twist.linear.x);
  });
  atEnd(() => odom.unsubscribe());
  const before = await poll('a first /odom message', 5000, 50, () => latest);
  const from = before.pose.pose.position;

  const cmdVel = new ROSLIB.Topic({ ros, name: '/cmd_vel', messageType: 'geometry_msgs/Twist' });
  const twist = { linear: { x: 0.3, y: 0, z: 0 }, angular: { x: 0, y: 0, z: 0 } };
  for (let i = 0; i < 30; i++) {
    cmdVel.publish(twist);
    await sleep(50);
  }
  await sleep(1000);  // the watchdog (0.5 s) and braking
  const to = latest.pose.pose.position;
  const moved = Math.hypot(to.x - from.x, to.y - from.y);
  log(`drive: /odom moved ${moved.toFixed(3)} m, fastest ${fastest.toFixed(3)} m/s`);
  check(moved > 0.15, `/odom moved only ${moved.toFixed(3)} m after 1.5 s at 0.3 m/s`);
  check(fastest > 0.1, `/odom's speed never passed 0.1 m/s (${fastest})`);
}

runTest('ros_roslib', 60_000, async () => {
  const env = parseArgs('roslib');
  const ROSLIB = await import(pathToFileURL(path.join(env.nodeModules, 'roslib', 'dist', 'RosLib.js')).href);
  const sim = await Sim.start(env.simPath, ['--scenario', 'warehouse', '--port', '0', '--rfb-only', '--crowd', '0',
                                            '--rosbridge-port', '0', '--robot-start', 'cross_west',
                                            '--robot-control', 'external', '--data-dir', env.artifacts],
                              env.artifacts, 'sim');
  const url = await sim.rosbridgeUrl();

  const ros = new ROSLIB.Ros();
  const connected = new Promise((resolve, reject) => {
    ros.once('connection', resolve);
    ros.once('error', (err) => reject(new CheckFailed(`roslib could not connect to ${url}: ${err?.message ?? err}`)));
  });
  await ros.connect(url);
  atEnd(() => ros.close());
  await connected;
  log(`roslib ${ROSLIB.REVISION} connected to ${url} (${typeof WebSocket === 'function' ? 'global WebSocket' : 'ws'})`);

  const odomType = await checkDiscovery(ROSLIB, ros);
  await checkAction(ROSLIB, ros);
  await checkDrive(ROSLIB, ros, odomType);

  check(sim.alive, 'sim_rfb died');
  ros.close();
  await sim.stopCleanly();
});
