// SPDX-License-Identifier: GPL-2.0-or-later
// web/h264_guard.js without a browser: a fake VideoDecoder stands in for WebCodecs' and the tests check what the
// guard reports (an error, decode() throwing, the page's callback throwing, a chunk that never comes out), that it
// reports once per connection, forgets retired decoders, passes frames through untouched, and installs nothing
// where there is no VideoDecoder.
// Usage: node h264_guard_test.mjs WEB_DIR     Exits 0 when every check passed, 1 otherwise.
import assert from 'node:assert/strict';
import path from 'node:path';
import { pathToFileURL } from 'node:url';

const webDir = process.argv[2];
if (!webDir) {
  console.error('usage: node h264_guard_test.mjs WEB_DIR');
  process.exit(1);
}
const { installH264Guard } = await import(pathToFileURL(path.join(webDir, 'h264_guard.js')).href);

const STALL_MS = 60;   // short limits, so that the stall tests take a fraction of a second
const CHECK_MS = 10;
const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

// Stands in for WebCodecs' VideoDecoder: decode() queues a chunk, the test decides when it comes out or fails.
class FakeDecoder {
  constructor(init) {
    if (!init || typeof init.output !== 'function' || typeof init.error !== 'function') {
      throw new TypeError('output and error callbacks are required');
    }
    this.init = init;
    this.state = 'configured';
    this.queue = [];
  }

  decode(chunk) {
    if (this.state !== 'configured') {
      throw new Error(`decode() on a ${this.state} decoder`);
    }
    this.queue.push(chunk);
  }

  reset() {
    this.queue = [];
  }

  close() {
    this.state = 'closed';
    this.queue = [];
  }

  // The oldest chunk comes out as a frame.
  emit() {
    const chunk = this.queue.shift();
    this.init.output({ timestamp: chunk.timestamp });
  }

  // The decoder fails, as WebCodecs does: closed, then the error callback.
  fail(message) {
    this.state = 'closed';
    this.init.error(new Error(message));
  }
}

// Installs a guard over a fresh FakeDecoder; returns { guard, reports, Decoder (what the page now gets) }.
function setUp() {
  globalThis.VideoDecoder = FakeDecoder;
  const reports = [];
  const guard = installH264Guard({ onFailure: (r) => reports.push(r), stallMs: STALL_MS, checkMs: CHECK_MS });
  return { guard, reports, Decoder: globalThis.VideoDecoder };
}

// A decoder made the way noVNC 1.7 makes one: its error callback throws, its output callback records frames.
function novncDecoder(Decoder, frames = []) {
  return new Decoder({
    output: (frame) => frames.push(frame),
    error: (e) => { throw new Error(`Failed to decode frame: ${e.message}`); },
  });
}

let failures = 0;
async function check(name, body) {
  try {
    await body();
    console.log(`ok   ${name}`);
  } catch (err) {
    failures += 1;
    console.log(`FAIL ${name}\n     ${err.message}`);
  } finally {
    delete globalThis.VideoDecoder;
  }
}

await check('without VideoDecoder nothing is installed and retire() is harmless', () => {
  delete globalThis.VideoDecoder;
  const guard = installH264Guard({ onFailure: () => assert.fail('reported') });
  assert.equal(guard.installed, false);
  assert.equal(globalThis.VideoDecoder, undefined);
  guard.retire();
});

await check('frames pass through untouched and in order; a healthy decoder is never reported', async () => {
  const { guard, reports, Decoder } = setUp();
  assert.equal(guard.installed, true);
  assert.notEqual(Decoder, FakeDecoder);
  const frames = [];
  const decoder = novncDecoder(Decoder, frames);
  assert.ok(decoder instanceof FakeDecoder);
  for (let t = 0; t < 20; t += 1) {
    decoder.decode({ timestamp: t });
    if (t % 2 === 1) {
      decoder.emit();
      decoder.emit();
    }
  }
  await sleep(3 * STALL_MS);
  assert.deepEqual(frames.map((f) => f.timestamp), [...Array(20).keys()]);
  assert.deepEqual(reports, []);
});

await check('callbacks are still the browser\'s to check: a decoder without them throws the browser\'s error', () => {
  const { Decoder } = setUp();
  assert.throws(() => new Decoder({ output: () => {} }), TypeError);
});

await check('a decoder error is reported once, and noVNC\'s throwing error callback does not escape', async () => {
  const { reports, Decoder } = setUp();
  const a = novncDecoder(Decoder);
  const b = novncDecoder(Decoder);
  a.decode({ timestamp: 1 });
  a.fail('Decoding error.');
  assert.deepEqual(reports, [], 'reported from inside the failing call');
  b.fail('Decoding error.');   // the same connection: already being replaced
  await sleep(0);
  assert.equal(reports.length, 1);
  assert.equal(reports[0].reason, 'error');
  assert.match(reports[0].detail, /Decoding error/);
});

await check('decode() throwing is reported and rethrown (noVNC logs it and keeps waiting for the frame)', async () => {
  const { reports, Decoder } = setUp();
  const decoder = novncDecoder(Decoder);
  decoder.close();
  assert.throws(() => decoder.decode({ timestamp: 1 }), /closed decoder/);
  await sleep(0);
  assert.deepEqual(reports.map((r) => r.reason), ['decode-threw']);
});

await check('the page\'s output callback throwing is reported', async () => {
  const { reports, Decoder } = setUp();
  const decoder = new Decoder({
    output: () => { throw new Error('Video frame timestamp mismatch'); },
    error: () => {},
  });
  decoder.decode({ timestamp: 1 });
  decoder.emit();
  await sleep(0);
  assert.deepEqual(reports.map((r) => r.reason), ['callback-threw']);
});

await check('a chunk that never comes out is reported as stalled, after the limit and not before', async () => {
  const { reports, Decoder } = setUp();
  const decoder = novncDecoder(Decoder);
  const started = performance.now();
  decoder.decode({ timestamp: 1 });
  await sleep(STALL_MS / 2);
  assert.deepEqual(reports, []);
  while (reports.length === 0 && performance.now() - started < 20 * STALL_MS) {
    await sleep(CHECK_MS);
  }
  assert.deepEqual(reports.map((r) => r.reason), ['stalled']);
  assert.ok(performance.now() - started >= STALL_MS);
});

await check('a chunk dropped by reset() or close() is not waited for', async () => {
  const { reports, Decoder } = setUp();
  const a = novncDecoder(Decoder);
  const b = novncDecoder(Decoder);
  a.decode({ timestamp: 1 });
  b.decode({ timestamp: 1 });
  a.reset();
  b.close();
  await sleep(3 * STALL_MS);
  assert.deepEqual(reports, []);
});

await check('retire(): old decoders are no longer reported, new ones are, once again', async () => {
  const { guard, reports, Decoder } = setUp();
  const old = novncDecoder(Decoder);
  old.decode({ timestamp: 1 });
  old.fail('first');
  await sleep(0);
  assert.equal(reports.length, 1);
  guard.retire();
  const stalledOld = novncDecoder(Decoder);
  stalledOld.decode({ timestamp: 2 });
  guard.retire();
  old.fail('late error of a replaced connection');
  await sleep(3 * STALL_MS);   // stalledOld's chunk never comes out either
  assert.equal(reports.length, 1);
  const fresh = novncDecoder(Decoder);
  fresh.fail('second');
  await sleep(0);
  assert.deepEqual(reports.map((r) => r.detail.match(/first|second/)[0]), ['first', 'second']);
});

await check('a failure retired before its report was delivered is dropped', async () => {
  const { guard, reports, Decoder } = setUp();
  novncDecoder(Decoder).fail('gone');
  guard.retire();
  await sleep(0);
  assert.deepEqual(reports, []);
});

if (failures > 0) {
  console.log(`${failures} check(s) failed`);
  process.exit(1);
}
console.log('all checks passed');
