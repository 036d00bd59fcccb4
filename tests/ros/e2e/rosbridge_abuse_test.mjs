// SPDX-License-Identifier: GPL-2.0-or-later
// ros_rosbridge_abuse: sim_rfb's rosbridge server (docs/ros.md, "Limits") against hostile clients (issue 31),
// while a Raw RFB viewer watches the session. One sim_rfb (warehouse, 15 people, 320x180); after each case
// the viewer still gets frames, a new rosbridge client is still served (/clock, rosapi's get_time) and
// sim_rfb's VmRSS stays within a bound far below what the attack would cost an unbounded server:
//   (a) large messages: 1 MiB + 1 byte gets an error status and the close (1009); 16 MiB is refused while it
//       is read (nothing near 16 MiB is held); 1 MiB of "[{},{},...]" (JSON's costliest shape) is refused
//       with an error status in well under a second (it took the network thread 17 s), the connection open;
//       16 messages of exactly 1 MiB are taken and answered
//   (b) 10,000 subscribe ops on one connection, half to made-up topics: exactly 256 are kept (the
//       per-connection cap), the other 9,744 each get an error status; a queue_length of 10^9 is cut to 100
//       with a warning
//   (c) 200 WebSockets at once from one address: at most 8 are let in, the rest refused; the viewer's
//       frames go on meanwhile; once they close, a new client is served
//   (d) two subscribers that never read a byte, each subscribed to every topic (/map 32 times) and asking
//       for 80 MiB of unique replies: sim_rfb keeps each one's queue within its bound (the log says it drops),
//       its memory levels off, the frames go on, and a client is served meanwhile
// sim_rfb then stops cleanly at SIGTERM, promptly.

import fs from 'node:fs';
import path from 'node:path';

import { watch } from './rfb_viewer.mjs';
import { LIMITS, holdConnections, neverRead, publishOfSize, rssMiB, sendOnce } from './rosbridge_abusers.mjs';
import { Rosbridge, Sim, check, log, parseArgs, poll, runTest, sleep } from './ros_e2e_support.mjs';

// The topics sim_rfb publishes but /map (0.6 MB, latched: sent again for each subscription that takes it).
const SMALL_TOPICS = ['/clock', '/tf', '/odom', '/scan', '/scene_markers', '/people', '/plan', '/goal_pose', '/events'];

// sim_rfb's output so far: Sim writes its stdout and stderr to ARTIFACTS/<name>.log.
let logPath = null;
function logText() {
  try {
    return fs.readFileSync(logPath, 'utf8');
  } catch {
    return '';
  }
}

// Updates the viewer got in `ms`; at least `least` of them, or the session's stream has stopped.
async function framesFlow(viewer, what, ms = 2000, least = 4) {
  const before = viewer.updates();
  await sleep(ms);
  const got = viewer.updates() - before;
  check(got >= least, `${what}: the viewer got ${got} updates in ${ms} ms (at least ${least} expected)`);
  return got;
}

// A well-behaved client from 127.0.0.1: /clock arrives and get_time is answered, with no error status.
async function served(WebSocket, url, what) {
  const client = await Rosbridge.connect(WebSocket, url, `client after ${what}`);
  client.send({ op: 'subscribe', topic: '/clock' });
  client.send({ op: 'call_service', id: 't', service: '/rosapi/get_time' });
  await client.waitForPublish('/clock', 3000);
  await client.waitFor('get_time response', (op) => op.op === 'service_response' && op.result === true, 3000);
  const errors = client.statuses('error');
  check(errors.length === 0, `${what}: errors for a good client ${JSON.stringify(errors)}`);
  client.ws.close();
  await client.closed;
}

// Everything after a case: frames, a served client, and VmRSS under `baseline + growthMiB`.
async function stillServing(sim, viewer, WebSocket, url, what, baseline, growthMiB) {
  await framesFlow(viewer, `after ${what}`);
  await served(WebSocket, url, what);
  const rss = rssMiB(sim.child.pid);
  check(sim.alive, `sim_rfb died during ${what}`);
  check(rss < baseline + growthMiB,
        `after ${what}: VmRSS ${rss.toFixed(1)} MiB, over ${baseline.toFixed(1)} + ${growthMiB}`);
  log(`after ${what}: frames flow, a new client is served, VmRSS ${rss.toFixed(1)} MiB ` +
      `(${baseline.toFixed(1)} before)`);
}

// (a) Messages at, just over and far over the 1 MiB limit.
async function largeMessages(sim, WebSocket, url, baseline) {
  const over = await sendOnce(WebSocket, url, LIMITS.messageBytes + 1);
  check(over.closeCode === 1009 && over.errors === 1,
        `1 MiB + 1 byte: close ${over.closeCode} after ${over.errors} error statuses (1009 after one expected)`);
  const farOver = await sendOnce(WebSocket, url, 16 << 20);
  // The close frame races the rest of our 16 MiB: the socket may be reset (1006) before we read it.
  check(farOver.closeCode === 1009 || farOver.closeCode === 1006, `16 MiB: close ${farOver.closeCode}`);
  await poll('the log line of the refusal while reading', 3000, 50,
             () => logText().includes('a message over 4198400 bytes, read no further'));
  check(rssMiB(sim.child.pid) < baseline + 12, `16 MiB: VmRSS ${rssMiB(sim.child.pid).toFixed(1)} MiB after it`);
  log(`over the limit: 1 MiB + 1 byte -> error status, close 1009; 16 MiB -> close ${farOver.closeCode} while read`);

  const client = await Rosbridge.connect(WebSocket, url, 'large');
  let from = client.mark();
  const started = Date.now();
  client.sendText(publishOfSize(LIMITS.messageBytes, 'objects'));
  client.send({ op: 'call_service', id: 'after-objects', service: '/rosapi/get_time' });
  await client.waitFor('get_time after 1 MiB of {}', (op) => op.op === 'service_response', 3000, from);
  const objectsMs = Date.now() - started;
  const refusal = client.statuses('error', from);
  check(refusal.length === 1 && /more than 10000 values/.test(refusal[0].msg),
        `1 MiB of [{},...]: statuses ${JSON.stringify(refusal).slice(0, 300)}`);
  check(objectsMs < 1500, `1 MiB of [{},...] took ${objectsMs} ms to answer`);
  log(`1 MiB of [{},{},...]: refused ('${refusal[0].msg}'), answered after ${objectsMs} ms, connection open`);

  from = client.mark();
  const atLimit = publishOfSize(LIMITS.messageBytes, 'text');
  for (let i = 0; i < 16; ++i) client.sendText(atLimit);
  client.send({ op: 'call_service', id: 'after-burst', service: '/rosapi/get_time' });
  await client.waitFor('get_time after 16 x 1 MiB', (op) => op.op === 'service_response', 5000, from);
  check(client.ws.readyState === 1, 'messages of exactly 1 MiB closed the connection');
  log(`16 messages of exactly 1 MiB: taken, the connection open (${client.statuses('error', from).length} ` +
      'error statuses: a /cmd_vel of the wrong shape)');
  client.ws.close();
  await client.closed;
}

// (b) 10,000 subscribes: 5,000 to made-up topics, 5,000 round-robin over nine real ones.
async function manySubscriptions(WebSocket, url) {
  const client = await Rosbridge.connect(WebSocket, url, 'subscriber');
  const ops = 10_000;
  const from = client.mark();
  for (let i = 0; i < ops; ++i) {
    const topic = i % 2 === 0 ? `/made_up/topic_${i}` : SMALL_TOPICS[((i - 1) / 2) % SMALL_TOPICS.length];
    client.send({ op: 'subscribe', id: `s${i}`, topic });
  }
  client.send({ op: 'call_service', id: 'end', service: '/rosapi/get_time' });
  await client.waitFor('the end of 10,000 subscribes', (op) => op.op === 'service_response' && op.id === 'end',
                       15_000, from);
  const errors = client.statuses('error', from);
  const kept = ops - errors.length;
  check(kept === LIMITS.subscriptions, `${kept} of ${ops} subscriptions kept (${LIMITS.subscriptions} expected)`);
  check(errors.filter((s) => /no such topic/.test(s.msg)).length === ops / 2, 'made-up topics not all refused');
  check(errors.some((s) => /already 256 subscriptions on this connection/.test(s.msg)), 'no refusal names the cap');
  log(`10,000 subscribes: ${kept} kept, ${errors.length} refused with an error status`);
  client.ws.close();
  await client.closed;

  // A queue_length that would hold every message for an hour: cut, with a warning.
  const greedy = await Rosbridge.connect(WebSocket, url, 'greedy');
  greedy.send({ op: 'subscribe', id: 'g', topic: '/tf', throttle_rate: 3_600_000, queue_length: 1_000_000_000 });
  const warning = await greedy.waitForStatus('warning', 3000);
  check(warning.msg.includes(`queue_length 1000000000 is over the limit; ${LIMITS.queueLength} is used`),
        `warning '${warning.msg}'`);
  log(`queue_length 10^9: '${warning.msg}'`);
  greedy.ws.close();
  await greedy.closed;
}

// (c) 200 WebSockets at once from 127.0.0.2, held.
async function manyConnections(viewer, WebSocket, url) {
  const attack = holdConnections(WebSocket, url, { count: 200, sources: ['127.0.0.2'] });
  await attack.settled();
  const { opened, refused, reset } = attack.stats;
  check(opened >= 1 && opened <= LIMITS.connections, `${opened} of 200 connections let in (at most 8 expected)`);
  check(opened + refused + reset === 200, `outcomes: ${JSON.stringify(attack.stats)}`);
  log(`200 connections from one address: ${opened} let in, ${refused} refused ` +
      `(${JSON.stringify(attack.stats.statuses)}), ${reset} closed at accept`);
  const frames = await framesFlow(viewer, 'while 200 connections are held');
  log(`while they are held: ${frames} updates in 2 s`);
  await attack.stop();
  // Their closes take a moment to reach the server: a new client is served once they have.
  await poll('a connection slot after the 200 closed', 5000, 100, async () => {
    try {
      const probe = await Rosbridge.connect(WebSocket, url, 'probe', 1000);
      probe.ws.close();
      await probe.closed;
      return true;
    } catch {
      return false;
    }
  });
}

// (d) Two subscribers that never read, each asking for 80 MiB of replies.
async function neverReading(sim, viewer, WebSocket, url, baseline) {
  const replies = 5000;
  const replyBytes = 16 << 10;
  const attack = await neverRead(url, { connections: 2, replies, replyBytes });
  check(attack.stats.accepted === 2, `never-reading subscribers: ${JSON.stringify(attack.stats)}`);
  const asked = (2 * replies * replyBytes) / (1 << 20);
  await poll('the log line that a slow reader loses messages', 10_000, 100,
             () => logText().includes('a connection reads too slowly'));
  await sleep(2000);
  const early = rssMiB(sim.child.pid);
  await served(WebSocket, url, 'two never-reading subscribers (meanwhile)');
  const frames = await framesFlow(viewer, 'while two subscribers never read', 3000, 6);
  const late = rssMiB(sim.child.pid);
  log(`never-reading subscribers (${asked.toFixed(0)} MiB of replies asked for): VmRSS ${baseline.toFixed(1)} -> ` +
      `${early.toFixed(1)} -> ${late.toFixed(1)} MiB; ${frames} updates in 3 s; a client is served meanwhile`);
  check(late - early < 16, `VmRSS still grows: ${early.toFixed(1)} -> ${late.toFixed(1)} MiB in 3 s`);
  check(late - baseline < asked / 2,
        `VmRSS grew by ${(late - baseline).toFixed(1)} MiB for ${asked.toFixed(0)} MiB asked`);
  await attack.stop();
}

runTest('ros_rosbridge_abuse', 60_000, async () => {
  const env = parseArgs('rosbridge_abuse');
  const WebSocket = env.require('ws');
  const sim = await Sim.start(env.simPath, ['--scenario', 'warehouse', '--port', '0', '--rfb-only',
                                            '--rosbridge-port', '0', '--width', '320', '--height', '180'],
                              env.artifacts, 'sim');
  logPath = path.join(env.artifacts, 'sim.log');
  const url = await sim.rosbridgeUrl();
  const [, host, port] = await sim.waitLine(/^sim_rfb ready: vnc:\/\/([\d.]+):(\d+)/, 1000);
  const viewer = await watch(host, Number(port));
  await framesFlow(viewer, 'before any attack');
  await served(WebSocket, url, 'nothing');
  const baseline = rssMiB(sim.child.pid);
  log(`sim_rfb streams and serves; VmRSS ${baseline.toFixed(1)} MiB`);

  await largeMessages(sim, WebSocket, url, baseline);
  await stillServing(sim, viewer, WebSocket, url, 'large messages', baseline, 48);
  await manySubscriptions(WebSocket, url);
  await stillServing(sim, viewer, WebSocket, url, '10,000 subscribes', baseline, 64);
  await manyConnections(viewer, WebSocket, url);
  await stillServing(sim, viewer, WebSocket, url, '200 connections', baseline, 64);
  await neverReading(sim, viewer, WebSocket, url, rssMiB(sim.child.pid));
  await stillServing(sim, viewer, WebSocket, url, 'never-reading subscribers', baseline, 128);

  viewer.stop();
  const stopping = Date.now();
  await sim.stopCleanly();
  check(Date.now() - stopping < 5000, `sim_rfb took ${Date.now() - stopping} ms to stop`);
  log(`sim_rfb stopped cleanly in ${Date.now() - stopping} ms`);
});
