// SPDX-License-Identifier: GPL-2.0-or-later
// Hostile clients of sim_rfb's rosbridge server (docs/ros.md, "Limits"), shared by the abuse test
// (rosbridge_abuse_test.mjs, label ros) and bench_ros.mjs --abuse, so that the bench's attackers are the ones
// the test keeps working. Each attack runs until its stop() and counts what the server did to it:
//   holdConnections     many WebSockets at once, held open; optionally reopened as the server refuses them
//   floodSubscriptions  thousands of subscribe ops with new ids, to declared and to made-up topics
//   sendLarge           messages at the size limit (parsed), just over it (status, close 1009) and far over
//                       it (close while it is read)
//   neverRead           a hand-framed WebSocket that subscribes to everything, asks for large unique replies
//                       and never reads a byte
// Every socket is bound to a source address from `sources` (any 127.0.0.0/8 address is local on Linux), so
// that one attack can come from one address or from many.

import crypto from 'node:crypto';
import fs from 'node:fs';
import net from 'node:net';
import { Worker } from 'node:worker_threads';

import { sleep } from './ros_e2e_support.mjs';

/// The topics sim_rfb publishes (docs/ros.md, "Topics"); /map is a latched 0.6 MB message in the warehouse.
export const DECLARED_TOPICS = ['/clock', '/tf', '/odom', '/scan', '/map', '/scene_markers', '/people', '/plan',
                                '/goal_pose', '/events'];
/// The server's limits, as docs/ros.md states them.
export const LIMITS = { connections: 8, subscriptionsPerTopic: 32, subscriptions: 256, queueLength: 100,
                        messageBytes: 1 << 20, hardMessageBytes: (4 << 20) + 4096 };

/// `count` source addresses: ['127.0.0.2'] for one, 127.0.1.1 ... for many.
export function sourceAddresses(count) {
  if (count <= 1) return ['127.0.0.2'];
  return Array.from({ length: count }, (_, i) => `127.0.${1 + Math.floor(i / 250)}.${1 + (i % 250)}`);
}

/// The resident memory of process `pid` in MiB (VmRSS from /proc/PID/status); NaN once it is gone.
export function rssMiB(pid) {
  try {
    const match = /^VmRSS:\s+(\d+) kB/m.exec(fs.readFileSync(`/proc/${pid}/status`, 'utf8'));
    return match ? Number(match[1]) / 1024 : NaN;
  } catch {
    return NaN;
  }
}

// The host and port of a ws:// URL.
function hostPort(url) {
  const parsed = new URL(url);
  return { host: parsed.hostname.replace(/^\[|\]$/g, ''), port: Number(parsed.port) };
}

// A WebSocket of the `ws` package from `source`; big messages are taken whole (the attackers read them).
function openWs(WebSocket, url, source) {
  return new WebSocket(url, { localAddress: source, maxPayload: 64 << 20, perMessageDeflate: false });
}

// Resolves once `ws` is open (true), or once it failed or closed first (false); records a refusal's HTTP status.
function opened(ws, outcome) {
  return new Promise((resolve) => {
    ws.once('open', () => resolve(true));
    ws.on('error', (err) => {
      const status = /Unexpected server response: (\d+)/.exec(err.message);
      if (status) outcome.status = Number(status[1]);
      outcome.error = err.message;
    });
    ws.once('close', () => resolve(false));
  });
}

// Whether a received frame is a publish (sim_rfb writes those with "op" first), without parsing it.
const isPublish = (data) => data.subarray(0, 16).toString('latin1') === '{"op":"publish",';

// Waits until `ws` has handed its queued bytes to the kernel (or closed): the attackers send as fast as the
// socket takes it, never faster than this process can hold.
async function drained(ws, limit = 1 << 20) {
  while (ws.readyState === 1 && ws.bufferedAmount > limit) await sleep(2);
}

/// Opens `count` WebSockets at once from `sources` and holds the ones the server lets in; with `reopen`, each
/// one refused or closed is opened again after `reopenMs` until stop(). Counts: opened (handshakes that
/// succeeded), refused (an HTTP status such as 503), reset (closed before any answer: the socket cap),
/// open (held now); settled() resolves once each of the first `count` attempts has an outcome.
export function holdConnections(WebSocket, url, { count = 200, sources = ['127.0.0.2'], reopen = false,
                                                 reopenMs = 50 } = {}) {
  const stats = { opened: 0, refused: 0, reset: 0, open: 0, statuses: {} };
  const sockets = new Set();
  const firstOutcomes = [];
  let stopped = false;
  const loop = async (i) => {
    let settle;
    firstOutcomes.push(new Promise((resolve) => { settle = resolve; }));
    while (!stopped) {
      const outcome = {};
      const ws = openWs(WebSocket, url, sources[i % sources.length]);
      sockets.add(ws);
      const closed = new Promise((resolve) => ws.once('close', resolve));
      const ok = await opened(ws, outcome);
      settle();  // the first attempt's outcome is known (later calls do nothing)
      if (ok) {
        stats.opened += 1;
        stats.open += 1;
        await closed;
        stats.open -= 1;
      } else if (outcome.status) {
        stats.refused += 1;
        stats.statuses[outcome.status] = (stats.statuses[outcome.status] ?? 0) + 1;
      } else {
        stats.reset += 1;
      }
      sockets.delete(ws);
      if (!reopen) break;
      await sleep(reopenMs);
    }
    settle();
  };
  for (let i = 0; i < count; ++i) loop(i);
  return {
    stats,
    settled: () => Promise.all(firstOutcomes),
    stop: async () => {
      stopped = true;
      for (const ws of sockets) ws.terminate();
      await sleep(100);
    },
  };
}

/// On each of `connections` WebSockets (from `sources`), `ops` subscribe ops with new ids: even ones to made-up
/// topics, odd ones round-robin over `topics`; then a call_service whose response marks the end of the round.
/// With `rounds` > 1 (or until stop() when Infinity), each later round first unsubscribes everything. Counts:
/// ops sent, error statuses received, rounds done, connections refused.
export function floodSubscriptions(WebSocket, url, { connections = 1, ops = 10_000, rounds = 1,
                                                    topics = DECLARED_TOPICS, sources = ['127.0.0.2'] } = {}) {
  const stats = { sent: 0, errors: 0, rounds: 0, refusedConnections: 0 };
  const sockets = new Set();
  let stopped = false;
  const one = async (c) => {
    const outcome = {};
    const ws = openWs(WebSocket, url, sources[c % sources.length]);
    sockets.add(ws);
    if (!(await opened(ws, outcome))) {
      stats.refusedConnections += 1;
      return;
    }
    let endOfRound = null;
    const closed = new Promise((resolve) => ws.once('close', resolve));
    ws.on('message', (data, isBinary) => {
      // Publishes are skipped unparsed: parsing every /map would cost this process more than the server. The
      // server writes them op first; statuses and service responses come with their keys sorted.
      if (isBinary || isPublish(data)) return;
      const op = JSON.parse(data.toString('utf8'));
      if (op.op === 'status' && op.level === 'error') {
        stats.errors += 1;
      } else if (op.op === 'service_response' && endOfRound) {
        endOfRound();
      }
    });
    for (let round = 0; round < rounds && !stopped && ws.readyState === 1; ++round) {
      if (round > 0) for (const topic of topics) ws.send(JSON.stringify({ op: 'unsubscribe', topic }));
      for (let i = 0; i < ops && !stopped && ws.readyState === 1; ++i) {
        const topic = i % 2 === 0 ? `/made_up/topic_${round}_${i}` : topics[((i - 1) / 2) % topics.length];
        ws.send(JSON.stringify({ op: 'subscribe', id: `r${round}-${i}`, topic }));
        stats.sent += 1;
        if (i % 256 === 0) await drained(ws);
      }
      const done = new Promise((resolve) => { endOfRound = resolve; });
      ws.send(JSON.stringify({ op: 'call_service', id: `end-${round}`, service: '/rosapi/get_time' }));
      await Promise.race([done, closed]);
      stats.rounds += 1;
    }
    if (rounds !== Infinity && !stopped) return;
    while (!stopped && ws.readyState === 1) await sleep(50);
  };
  for (let c = 0; c < connections; ++c) one(c);
  return {
    stats,
    stop: async () => {
      stopped = true;
      for (const ws of sockets) ws.terminate();
      await sleep(100);
    },
  };
}

/// A publish on /cmd_vel of exactly `bytes` bytes of JSON. `shape` 'text' pads with one string; 'objects'
/// with an array of empty objects, the costliest JSON to parse per byte.
export function publishOfSize(bytes, shape = 'text') {
  const head = '{"op":"publish","topic":"/cmd_vel","msg":{"pad":';
  const tail = '}}';
  const room = bytes - head.length - tail.length;
  if (shape === 'objects') {
    const n = Math.floor((room - 1) / 3);  // "[" + "{}," * (n - 1) + "{}" + "]" = 3n + 1
    const body = `[${'{},'.repeat(n - 1)}{}]`;
    return head + body + ' '.repeat(room - body.length) + tail;
  }
  return head + `"${'x'.repeat(room - 2)}"` + tail;
}

/// Sends one message of `bytes` on a new WebSocket from `source` and resolves with what came back:
/// { closeCode, errors (error statuses before the close), refused (no connection) } once the server closed it,
/// or { closeCode: null } when it still had not after timeoutMs.
export async function sendOnce(WebSocket, url, bytes, { source = '127.0.0.2', shape = 'text', timeoutMs = 5000 } = {}) {
  const outcome = {};
  const ws = openWs(WebSocket, url, source);
  if (!(await opened(ws, outcome))) return { refused: true, closeCode: null, errors: 0 };
  let errors = 0;
  ws.on('message', (data) => {
    if (isPublish(data)) return;
    const op = JSON.parse(data.toString('utf8'));
    if (op.op === 'status' && op.level === 'error') errors += 1;
  });
  const closed = new Promise((resolve) => ws.once('close', (code) => resolve(code)));
  ws.send(publishOfSize(bytes, shape));
  const code = await Promise.race([closed, sleep(timeoutMs).then(() => null)]);
  ws.terminate();
  return { closeCode: code, errors };
}

/// Until stop(), `connections` WebSockets (from `sources`) each send messages in a cycle of `cycle` sizes in
/// bytes (default: three at the limit, one just over it, one of 16 MiB), as fast as the socket takes them, and
/// reopen when closed. Counts: messages sent by size class, closes by code, connections refused.
export function sendLarge(WebSocket, url, { connections = 8, sources = ['127.0.0.2'], shape = 'objects',
                                           cycle = [LIMITS.messageBytes, LIMITS.messageBytes, LIMITS.messageBytes,
                                                    LIMITS.messageBytes + 1, 16 << 20] } = {}) {
  const stats = { atLimit: 0, over: 0, farOver: 0, closes: {}, refusedConnections: 0 };
  const sockets = new Set();
  const payloads = new Map(cycle.map((bytes) => [
    bytes, publishOfSize(bytes, bytes <= LIMITS.messageBytes ? shape : 'text')]));
  let stopped = false;
  const one = async (c) => {
    let k = 0;
    while (!stopped) {
      const outcome = {};
      const ws = openWs(WebSocket, url, sources[c % sources.length]);
      sockets.add(ws);
      ws.on('message', () => {});
      const closed = new Promise((resolve) => ws.once('close', (code) => resolve(code)));
      if (!(await opened(ws, outcome))) {
        stats.refusedConnections += 1;
        sockets.delete(ws);
        await sleep(50);
        continue;
      }
      while (!stopped && ws.readyState === 1) {
        const bytes = cycle[k++ % cycle.length];
        ws.send(payloads.get(bytes));
        if (bytes <= LIMITS.messageBytes) stats.atLimit += 1;
        else if (bytes <= LIMITS.hardMessageBytes) stats.over += 1;
        else stats.farOver += 1;
        await drained(ws, 0);
      }
      const code = await closed;
      stats.closes[code] = (stats.closes[code] ?? 0) + 1;
      sockets.delete(ws);
    }
  };
  const all = Promise.all(Array.from({ length: connections }, (_, c) => one(c)));
  return {
    stats,
    stop: async () => {
      stopped = true;
      for (const ws of sockets) ws.terminate();
      await Promise.race([all, sleep(2000)]);
    },
  };
}

// A client-to-server WebSocket frame (RFC 6455 5.2): FIN, text, masked, with a 16- or 64-bit length as needed.
function maskedTextFrame(text) {
  const payload = Buffer.from(text, 'utf8');
  const length = payload.length;
  const header = length < 126 ? Buffer.alloc(2) : length < 65536 ? Buffer.alloc(4) : Buffer.alloc(10);
  header[0] = 0x81;
  if (length < 126) {
    header[1] = 0x80 | length;
  } else if (length < 65536) {
    header[1] = 0x80 | 126;
    header.writeUInt16BE(length, 2);
  } else {
    header[1] = 0x80 | 127;
    header.writeBigUInt64BE(BigInt(length), 2);
  }
  const mask = crypto.randomBytes(4);
  for (let i = 0; i < length; ++i) payload[i] ^= mask[i & 3];
  return Buffer.concat([header, mask, payload]);
}

/// A WebSocket spoken by hand over a TCP socket from `source`, so that it can stop reading for good: after the
/// server's 101 it sends `ops` (objects, as JSON text frames) and never reads another byte. Resolves with
/// { socket, accepted } once the 101 (accepted) or another answer (refused) came.
export function rawSubscriber(url, ops, { source = '127.0.0.2', timeoutMs = 5000 } = {}) {
  const { host, port } = hostPort(url);
  return new Promise((resolve) => {
    const socket = net.connect({ host, port, localAddress: source });
    let head = '';
    const timer = setTimeout(() => resolve({ socket, accepted: false }), timeoutMs);
    socket.on('error', () => {});
    socket.once('close', () => {
      clearTimeout(timer);
      resolve({ socket, accepted: false });
    });
    socket.on('connect', () => {
      socket.write(`GET / HTTP/1.1\r\nHost: ${host}:${port}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n` +
                   `Sec-WebSocket-Key: ${crypto.randomBytes(16).toString('base64')}\r\n` +
                   'Sec-WebSocket-Version: 13\r\n\r\n');
    });
    const onData = (chunk) => {
      head += chunk.toString('latin1');
      if (!head.includes('\r\n\r\n')) return;
      clearTimeout(timer);
      const accepted = head.startsWith('HTTP/1.1 101');
      // From here on nothing is read: the kernel's buffers fill, then the server's.
      socket.off('data', onData);
      socket.pause();
      if (accepted) for (const op of ops) socket.write(maskedTextFrame(JSON.stringify(op)));
      resolve({ socket, accepted });
    };
    socket.on('data', onData);
  });
}

/// The ops of a never-reading subscriber: every declared topic at full rate, 32 ids on /map (the latched map
/// is queued once for each), then `replies` unknown ops whose error statuses each echo a `replyBytes` id:
/// unique bytes the server must queue for this connection, so that its bound, not the kernel's buffers, is
/// what holds.
export function neverReadOps({ replies = 10_000, replyBytes = 1024, tag = 'n' } = {}) {
  const ops = [];
  for (const topic of DECLARED_TOPICS) ops.push({ op: 'subscribe', topic });
  for (let i = 1; i < LIMITS.subscriptionsPerTopic; ++i) {
    ops.push({ op: 'subscribe', topic: '/map', id: `${tag}-map-${i}` });
  }
  const pad = 'y'.repeat(Math.max(0, replyBytes - 24));
  for (let i = 0; i < replies; ++i) ops.push({ op: 'frobnicate', id: `${tag}-${i}-${pad}` });
  return ops;
}

/// `connections` never-reading subscribers (from `sources`) sending neverReadOps; they stay until stop().
/// Counts: accepted, refused.
export async function neverRead(url, { connections = 7, sources = ['127.0.0.2'], replies = 10_000,
                                       replyBytes = 1024 } = {}) {
  const stats = { accepted: 0, refused: 0 };
  const clients = await Promise.all(Array.from({ length: connections }, (_, c) =>
    rawSubscriber(url, neverReadOps({ replies, replyBytes, tag: `n${c}` }), { source: sources[c % sources.length] })));
  for (const { accepted } of clients) stats[accepted ? 'accepted' : 'refused'] += 1;
  return {
    stats,
    stop: async () => {
      for (const { socket } of clients) socket.destroy();
      await sleep(100);
    },
  };
}

/// Runs attack `fn` ('holdConnections', 'floodSubscriptions', 'sendLarge' or 'neverRead') with `options` on a
/// worker thread (rosbridge_abuse_worker.mjs) and resolves once it runs, with stop(), which resolves with the
/// attack's stats. `nodeModules` is where `ws` is.
export async function attackInWorker(fn, url, nodeModules, options = {}) {
  const worker = new Worker(new URL('./rosbridge_abuse_worker.mjs', import.meta.url),
                            { workerData: { fn, url, nodeModules, options } });
  const next = (type) => new Promise((resolve, reject) => {
    const onMessage = (message) => {
      if (message.type !== type) return;
      worker.off('message', onMessage);
      resolve(message);
    };
    worker.on('message', onMessage);
    worker.once('error', reject);
  });
  await next('started');
  return {
    stop: async () => {
      const stopped = next('stopped');
      worker.postMessage('stop');
      const { stats } = await stopped;
      await worker.terminate();
      return stats;
    },
  };
}
