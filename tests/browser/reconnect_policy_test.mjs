// SPDX-License-Identifier: GPL-2.0-or-later
// web/reconnect_policy.js without a browser: how the page classes each close code it can meet (sim_manager's
// close notices, sim_rfb's 1001, 4001 for a takeover, the browser's 1006), what the manager's status answers mean,
// which combinations reconnect by themselves, and the exact waits of the backoff with its jitter at both ends.
// Usage: node reconnect_policy_test.mjs WEB_DIR     Exits 0 when every test passed, 1 otherwise (node:test).
import assert from 'node:assert/strict';
import path from 'node:path';
import test from 'node:test';
import { pathToFileURL } from 'node:url';

const webDir = process.argv[2];
if (!webDir) {
  console.error('usage: node reconnect_policy_test.mjs WEB_DIR');
  process.exit(1);
}
const policy = await import(pathToFileURL(path.join(webDir, 'reconnect_policy.js')).href);
const { CLOSE_TAKEN_OVER, STANDALONE_MAX_RETRIES, classifyClose, nextStep, retryDelayMs, sessionView } = policy;

const LOW = () => 0;         // the jitter's lowest draw
const MIDDLE = () => 0.5;    // no jitter
const HIGH = () => 0.999999; // the jitter's highest draw

test('the closes sim_manager and sim_rfb send on purpose are endings, never reconnected', () => {
  // manager/sessions/session_views.cpp close_notice: finished 1000, expired/idle/ended/shutdown 1001; sim_rfb: 1001.
  for (const code of [1000, 1001]) {
    assert.equal(classifyClose({ connected: true, clean: true, code }), 'ended', `code ${code}`);
    assert.equal(classifyClose({ connected: false, clean: false, code }), 'ended', `code ${code}, not connected`);
  }
  assert.equal(classifyClose({ connected: true, clean: true, code: 1005 }), 'ended');
  for (const code of [4000, 4002, 4403, 4999]) {
    assert.equal(classifyClose({ connected: true, clean: true, code }), 'ended', `code ${code}`);
  }
});

test('4001 is a takeover by another window, whether or not the connection was up', () => {
  assert.equal(CLOSE_TAKEN_OVER, 4001);
  assert.equal(classifyClose({ connected: true, clean: true, code: 4001 }), 'taken-over');
  assert.equal(classifyClose({ connected: false, clean: false, code: 4001 }), 'taken-over');
});

test('a broken connection is lost, an attempt that never got through failed', () => {
  // 1006: no close frame (network, proxy, relay dropped); 1011: the manager lost the simulator's socket;
  // 1012-1014: restart, try again later, bad gateway.
  for (const code of [1006, 1011, 1012, 1013, 1014, 1015]) {
    assert.equal(classifyClose({ connected: true, clean: true, code }), 'lost', `code ${code}`);
    assert.equal(classifyClose({ connected: false, clean: false, code }), 'failed', `code ${code}, not connected`);
  }
  assert.equal(classifyClose({ connected: false, clean: false, code: null }), 'failed');
  assert.equal(classifyClose({ connected: false, clean: true, code: 1005 }), 'failed');
  assert.equal(classifyClose({}), 'failed');
});

test('refusals and abandoned attempts', () => {
  for (const code of [1002, 1003, 1007, 1008, 1009, 1010]) {
    assert.equal(classifyClose({ connected: true, clean: true, code }), 'refused', `code ${code}`);
  }
  assert.equal(classifyClose({ connected: false, clean: true, code: 1000, refused: true }), 'refused');
  // The page gave up on a try itself: its own close says 1000, yet nothing ended.
  assert.equal(classifyClose({ connected: false, clean: true, code: 1000, gaveUp: true }), 'failed');
});

test("the manager's status answers", () => {
  assert.equal(sessionView({ httpStatus: 200, json: true, state: 'running' }), 'live');
  assert.equal(sessionView({ httpStatus: 200, json: true, state: 'starting', managed: true }), 'live');
  for (const state of ['ending', 'finished', 'expired', 'idle', 'ended', 'crashed', 'abandoned']) {
    assert.equal(sessionView({ httpStatus: 200, json: true, state, managed: true }), 'over', state);
  }
  // The manager's JSON 404 (unknown session) and 410; a plain 404 after a manager answered.
  assert.equal(sessionView({ httpStatus: 404, json: true }), 'gone');
  assert.equal(sessionView({ httpStatus: 410, json: false, managed: true }), 'gone');
  assert.equal(sessionView({ httpStatus: 404, json: false, managed: true }), 'gone');
  // sim_rfb serving the page itself: a plain 404, and no manager ever answered.
  assert.equal(sessionView({ httpStatus: 404, json: false }), 'none');
  assert.equal(sessionView({ httpStatus: 403, json: false }), 'none');
  // No usable answer now: the network, a timeout, a server error, a proxy's error page.
  assert.equal(sessionView({ httpStatus: null }), 'unknown');
  assert.equal(sessionView({}), 'unknown');
  assert.equal(sessionView({ httpStatus: 502, json: false, managed: true }), 'unknown');
  assert.equal(sessionView({ httpStatus: 503, json: true }), 'unknown');
  assert.equal(sessionView({ httpStatus: 403, json: false, managed: true }), 'unknown');
  assert.equal(sessionView({ httpStatus: 200, json: true, state: null, managed: true }), 'unknown');
});

test('a lost connection is tried again while the session is alive or cannot be asked about', () => {
  for (const kind of ['lost', 'failed']) {
    for (const session of ['live', 'unknown']) {
      for (const retries of [0, 5, 1000]) {
        const step = nextStep({ kind, session, retries }, MIDDLE);
        assert.equal(step.action, 'retry', `${kind} ${session} after ${retries}`);
        assert.equal(step.retry, retries + 1);
        assert.equal(step.delayMs, retryDelayMs(retries + 1, MIDDLE));
      }
    }
  }
});

test('nothing is tried again once the session is over or gone, whatever the close said', () => {
  for (const kind of ['lost', 'failed', 'ended', 'refused', 'taken-over']) {
    for (const session of ['over', 'gone']) {
      assert.deepEqual(nextStep({ kind, session, retries: 0 }), { action: 'end' }, `${kind} ${session}`);
    }
  }
});

test('endings, refusals and takeovers wait for the person', () => {
  for (const session of ['live', 'unknown', 'none']) {
    assert.deepEqual(nextStep({ kind: 'taken-over', session }), { action: 'taken-over' }, session);
    assert.deepEqual(nextStep({ kind: 'ended', session }), { action: 'offer' }, session);
    assert.deepEqual(nextStep({ kind: 'refused', session }), { action: 'offer' }, session);
  }
});

test('without a manager a lost connection gets a few tries, then Reconnect', () => {
  for (let retries = 0; retries < STANDALONE_MAX_RETRIES; retries += 1) {
    assert.equal(nextStep({ kind: 'lost', session: 'none', retries }).action, 'retry', `after ${retries}`);
  }
  assert.deepEqual(nextStep({ kind: 'lost', session: 'none', retries: STANDALONE_MAX_RETRIES }),
                   { action: 'offer' });
  assert.deepEqual(nextStep({ kind: 'failed', session: 'none', retries: STANDALONE_MAX_RETRIES + 3 }),
                   { action: 'offer' });
});

test('the waits: 0.5 s doubling to 10 s, +/- 20 % jitter', () => {
  const nominal = [500, 1000, 2000, 4000, 8000, 10_000, 10_000];
  nominal.forEach((ms, i) => {
    const retry = i + 1;
    assert.equal(retryDelayMs(retry, MIDDLE), ms, `try ${retry}`);
    assert.equal(retryDelayMs(retry, LOW), Math.round(ms * 0.8), `try ${retry}, lowest`);
    assert.equal(retryDelayMs(retry, HIGH), Math.round(ms * 1.2), `try ${retry}, highest`);
  });
  assert.equal(retryDelayMs(1_000_000, MIDDLE), 10_000);
  // A random source out of range is clamped, never a negative or runaway wait.
  assert.equal(retryDelayMs(1, () => -5), 400);
  assert.equal(retryDelayMs(1, () => 7), 600);
});

test('the jitter spreads pages that lost their connection together', () => {
  // Four pages, four draws: four different waits around the 4 s of the third doubling.
  const waits = [0, 0.25, 0.5, 0.75].map((draw) => retryDelayMs(4, () => draw));
  assert.deepEqual(waits, [3200, 3600, 4000, 4400]);
});
