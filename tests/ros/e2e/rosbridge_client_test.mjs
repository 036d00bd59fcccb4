// SPDX-License-Identifier: GPL-2.0-or-later
// ros_rosbridge_client: sim_rfb dialling out (--rosbridge-connect) to a lab's rosbridge_server, played here
// by a Node `ws` server on loopback that checks the bearer token as a reverse proxy in front of
// rosbridge_server would.
//
// The server first expects another token: sim_rfb's attempt carries `Authorization: Bearer <the token
// file's first line>` and is refused with 401; sim_rfb tries again by itself, and once the server takes
// that token it connects, advertises every topic under its namespace (/lab1/...), subscribes to
// /lab1/cmd_vel and publishes, /lab1/scan among the rest. The server's /lab1/cmd_vel publishes (Twist,
// v 0.3, 1.5 s at 20 Hz) drive the robot (external control): every one is in events.jsonl as a
// robot_command from "rosbridge-client", and the robot moves forward in trajectories.csv. Like
// rosbridge_server, the stand-in hands a publish to every subscriber of its topic, sim_rfb included: sim_rfb's
// own /lab1/cmd_vel must not come back as commands, and the watchdog stops the robot once the lab goes quiet.

import fs from 'node:fs';
import http from 'node:http';
import path from 'node:path';

import { Sim, atEnd, check, log, parseArgs, poll, readEvents, robotRows, runTest, sleep } from './ros_e2e_support.mjs';

// Long, as a JWT can be: sim_rfb must send it whole (it takes up to 4096 characters).
const TOKEN = `lab-token-7f3a.${'x'.repeat(2000)}`;
const NAMESPACE = '/lab1';
const TOPICS = ['/clock', '/tf', '/odom', '/scan', '/map', '/scene_markers', '/cmd_vel', '/people', '/plan',
                '/goal_pose', '/events'];
const SENDS = 30;  // 1.5 s at 20 Hz

// The stand-in for the lab's rosbridge_server: { port, attempts (each upgrade's Authorization and whether it
// was let in), ops (every op sim_rfb sent), sockets, expected (the token it lets in), publish(topic, msg) }.
async function startLabServer(WebSocketServer) {
  const lab = { attempts: [], ops: [], sockets: [], expected: 'some-other-token' };
  // As rosbridge_server does: a publish goes to every client subscribed to its topic, its sender included
  // (a ROS 2 node's subscription hears the same node's publisher).
  lab.publish = (topic, msg) => {
    for (const ws of lab.sockets) {
      if (ws.subscribed.has(topic)) ws.send(JSON.stringify({ op: 'publish', topic, msg }));
    }
  };
  const wss = new WebSocketServer({ noServer: true, maxPayload: 64 << 20 });
  const server = http.createServer((req, res) => res.writeHead(404).end());
  server.on('upgrade', (req, socket, head) => {
    const auth = req.headers.authorization ?? '';
    const accepted = auth === `Bearer ${lab.expected}`;
    lab.attempts.push({ auth, accepted });
    if (!accepted) {
      socket.end('HTTP/1.1 401 Unauthorized\r\nContent-Length: 0\r\nConnection: close\r\n\r\n');
      return;
    }
    wss.handleUpgrade(req, socket, head, (ws) => {
      lab.sockets.push(ws);
      ws.subscribed = new Set();
      ws.on('message', (data) => {
        const op = JSON.parse(data.toString('utf8'));
        lab.ops.push(op);
        if (op.op === 'subscribe') ws.subscribed.add(op.topic);
        if (op.op === 'publish') lab.publish(op.topic, op.msg);
      });
    });
  });
  await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
  atEnd(() => {
    for (const ws of lab.sockets) ws.terminate();
    server.close();
  });
  lab.port = server.address().port;
  return lab;
}

runTest('ros_rosbridge_client', 60_000, async () => {
  const env = parseArgs('rosbridge_client');
  const { WebSocketServer } = env.require('ws');
  const lab = await startLabServer(WebSocketServer);
  const tokenFile = path.join(env.artifacts, 'token');
  fs.writeFileSync(tokenFile, `${TOKEN}\n`, { mode: 0o600 });
  const dir = path.join(env.artifacts, 'session');
  const sim = await Sim.start(env.simPath, [
    '--scenario', 'warehouse', '--port', '0', '--rfb-only', '--crowd', '0', '--robot-start', 'cross_west',
    '--robot-control', 'external', '--ros-namespace', NAMESPACE, '--data-dir', dir,
    '--rosbridge-connect', `ws://127.0.0.1:${lab.port}/`, '--rosbridge-token-file', tokenFile,
  ], env.artifacts, 'sim_client');

  // A wrong token is refused; sim_rfb keeps trying and gets in once the server takes its token.
  await poll('a first (refused) attempt', 5000, 50, () => lab.attempts.length >= 1);
  check(lab.attempts[0].auth === `Bearer ${TOKEN}`, `sim_rfb sent Authorization '${lab.attempts[0].auth}'`);
  lab.expected = TOKEN;
  await poll('sim_rfb to connect again after the 401', 10_000, 50, () => lab.sockets.length >= 1);
  log(`refused with 401 ${lab.attempts.length - 1} time(s), then connected with the token`);

  // It advertises every topic and subscribes to cmd_vel, all under the namespace, then publishes.
  const advertised = () => new Map(lab.ops.filter((op) => op.op === 'advertise').map((op) => [op.topic, op.type]));
  await poll('advertise ops for every topic', 5000, 50, () => advertised().size >= TOPICS.length - 1);
  for (const topic of TOPICS.filter((t) => t !== '/cmd_vel')) {
    const type = advertised().get(NAMESPACE + topic);
    check(/^[a-z0-9_]+\/(msg\/)?[A-Za-z0-9]+$/.test(type ?? ''), `${NAMESPACE}${topic} advertised as '${type}'`);
  }
  check(lab.ops.some((op) => op.op === 'subscribe' && op.topic === `${NAMESPACE}/cmd_vel`), 'no subscribe to cmd_vel');
  // Its own /cmd_vel stays home: published there too, it would come straight back as commands.
  check(!advertised().has(`${NAMESPACE}/cmd_vel`), `sim_rfb advertised ${NAMESPACE}/cmd_vel, which it subscribes to`);
  const scan = await poll(`a publish on ${NAMESPACE}/scan`, 3000, 50,
                          () => lab.ops.find((op) => op.op === 'publish' && op.topic === `${NAMESPACE}/scan`));
  check(scan.msg.ranges.length === 360, `${NAMESPACE}/scan has ${scan.msg.ranges.length} ranges`);
  log(`advertised ${advertised().size} topics under ${NAMESPACE}, subscribed to cmd_vel, /scan arrives`);

  // The lab's stack drives.
  for (let i = 0; i < SENDS; ++i) {
    lab.publish(`${NAMESPACE}/cmd_vel`, { linear: { x: 0.3, y: 0, z: 0 }, angular: { x: 0, y: 0, z: 0 } });
    await sleep(50);
  }
  await sleep(1000);  // the watchdog's 0.5 s, and the rows that show it
  await sim.stopCleanly();

  const events = readEvents(dir);
  const commands = events.filter((e) => e.type === 'robot_command');
  // Two sends delivered together are recorded once (only the last command per pass of sim_rfb's loop counts).
  check(commands.length >= 0.8 * SENDS && commands.length <= SENDS &&
        commands.every((c) => c.v === 0.3 && c.w === 0 && c.source === 'rosbridge-client'),
        `robot_command events: ${JSON.stringify(commands.slice(0, 3))}... (${commands.length})`);
  const rows = robotRows(dir);
  const start = rows.filter((r) => r.tick <= commands[0].tick).pop();
  const end = rows[rows.length - 1];
  const ahead = (end.x - start.x) * Math.cos(start.yaw) + (end.y - start.y) * Math.sin(start.yaw);
  check(ahead > 0.3, `the robot moved ${ahead.toFixed(3)} m ahead under the lab's commands`);
  // Only the lab's commands count: sim_rfb's own /cmd_vel, echoed back by the server, must not keep it going.
  const last = commands[commands.length - 1].tick;
  const stale = events.find((e) => e.type === 'robot' && e.tick > last && e.detail?.startsWith('external control: no command'));
  check(stale, `the robot was not stopped by the watchdog after the lab's last command (tick ${last})`);
  log(`${commands.length} commands from the lab recorded; the robot moved ${ahead.toFixed(2)} m ahead and stopped`);
});
