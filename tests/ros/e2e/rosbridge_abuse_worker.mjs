// SPDX-License-Identifier: GPL-2.0-or-later
// One attack of rosbridge_abusers.mjs on a thread of its own (attackInWorker), so that the attacker's work
// (masking 16 MiB messages, sending 10,000 ops a round) never holds up the event loop of the viewer and the
// listener whose frames and messages measure the session: on one thread, they counted the attacker's stalls.
// workerData: { fn (the attack's name), url, nodeModules, options }. Posts { type: 'started' } once the attack
// runs and { type: 'stopped', stats } after the message 'stop'.

import { createRequire } from 'node:module';
import path from 'node:path';
import { parentPort, workerData } from 'node:worker_threads';

import { floodSubscriptions, holdConnections, neverRead, sendLarge } from './rosbridge_abusers.mjs';

const { fn, url, nodeModules, options } = workerData;
const WebSocket = createRequire(path.join(nodeModules, '..', 'package.json'))('ws');
const attacks = { floodSubscriptions, holdConnections, sendLarge };
const attack = fn === 'neverRead' ? await neverRead(url, options) : attacks[fn](WebSocket, url, options);
parentPort.postMessage({ type: 'started' });
parentPort.on('message', async (message) => {
  if (message !== 'stop') return;
  await attack.stop();
  parentPort.postMessage({ type: 'stopped', stats: attack.stats });
  parentPort.close();
});
