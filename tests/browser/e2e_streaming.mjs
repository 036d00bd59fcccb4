// SPDX-License-Identifier: GPL-2.0-or-later
// Browser end-to-end test of streaming with the bundled noVNC in a real Chromium (or Firefox ESR with --browser
// firefox): ContinuousUpdates and Fence with Tight JPEG, H.264 decoded by WebCodecs (compared with the JPEG picture
// of the same still scene), JPEG for a page without WebCodecs, and the page's recovery from pictures its decoder
// cannot decode (web/h264_guard.js, app.js).
//
// Usage: node e2e_streaming.mjs [--browser chromium|firefox] SIM_RFB ARTIFACTS_DIR [WEB_DIR]
//   SIM_RFB        the sim_rfb executable to start (twice: --codec jpeg, then --codec h264, same seed and size)
//   ARTIFACTS_DIR  where the canvases and screenshots (streaming_*.png), the numbers (streaming.json), the
//                  simulators' output and the browser consoles (streaming-console*.log) are written (created)
//   WEB_DIR        the source web/ folder whose node_modules holds playwright-core and puppeteer-core (default:
//                  ../../web from here)
// Environment: RFBSIM_CHROMIUM (default /usr/bin/chromium), RFBSIM_FIREFOX (default /usr/bin/firefox-esr),
// RFBSIM_E2E_TIMEOUT_S (default 90).
// Exits 0 when every check passed, 1 on the first failed check, 2 on the overall timeout.
//
// The page is opened at http://127.0.0.1, a secure context, where Chromium and Firefox have WebCodecs and noVNC
// offers H.264.

import fs from 'node:fs';
import path from 'node:path';

import { loadDriver } from './browser_driver.mjs';
import {
  PIXEL_CHANGE_THRESHOLD, changedFraction, check, getStatus, log, openPage, pageState, parseArgs,
  poll, recordPage, runTest, saveCanvasPng, sleep, snapshot, startSim, stopSimCleanly,
  waitForConnection, waitForPicture,
} from './e2e_support.mjs';

// ---------------------------------------------------------------------------------------------------------------
// Settings. Measurements quoted are from Chromium 156 (software decoding) and llvmpipe at 640x480.
// ---------------------------------------------------------------------------------------------------------------
const SIM_WIDTH = 640;                 // framebuffer size asked of sim_rfb, pixels (H.264 macroblocks: 40x30)
const SIM_HEIGHT = 480;
const SEED = 7;                        // the same built-in test room, crowd and all, for both simulators
const WALK_MS = 3000;                  // a: how long W (and A, so that no wall stops the view) is held
const WALK_SAMPLE_MS = 500;            // a: the canvas is looked at this often while walking
const MIN_WALK_UPDATES = 20;           // a: updates pushed while walking (measured 52-93 in 3 s)
const MIN_CHANGING_SAMPLES = 4;        // a: of the 6 looks while walking, at least this many see a change
const MIN_CHANGED_FRACTION = 0.03;     // share of pixels that a key press must change (walk test's bound)
const STILL_MS = 600;                  // a picture counts as still when two looks this far apart agree
// b: H.264 against JPEG (quality 80) of the same still scene, mean absolute difference of each channel, 0..255.
// Each codec alone is ~1-2 away from the rendered picture, and their errors (x264's 4:2:0 with its colour
// conversion, JPEG's blocks) add up at edges; a wrong colour matrix or range shifts a whole channel by 10+, a
// broken or missing picture by 30+. Measured: R 1.25-1.26, G 0.66-0.69, B 1.27-1.29.
const MAX_CODEC_MAD = 6;
// b: share of pixels whose |dR|+|dG|+|dB| between the two exceeds PIXEL_CHANGE_THRESHOLD: a local error (a
// smeared block, an object missing) that the mean hides. Measured 0.20-0.24 %.
const MAX_CODEC_CHANGED_FRACTION = 0.01;
const STALL_MS = 2000;                 // c: h264_guard.js's stall limit
const BACKOFF_MS = [0, 1000, 3000];    // c: app.js's waits before the 1st, 2nd, 3rd reconnect in a row
const RECOVERY_NOTICE = 'Restoring the picture\u2026';   // c: app.js's progress line while it takes long
const env = parseArgs('e2e_streaming.mjs');
let driver = null;   // browser_driver.mjs's, for env.browser (main loads it)
// The Chromium test's files keep their names; a Firefox run's get a firefox_ prefix.
const PREFIX = env.browser === 'chromium' ? '' : `${env.browser}_`;
const artifact = (name) => path.join(env.artifacts, `${PREFIX}${name}`);

const startStreamSim = (name, codec) => startSim(env, name, [
  '--port', '0', '--width', String(SIM_WIDTH), '--height', String(SIM_HEIGHT), '--seed', String(SEED),
  '--codec', codec,
]);

// The newest client's stream in status.json (a replaced connection's stream may linger a moment).
async function pageStream(sim) {
  const streams = (await getStatus(sim)).streams;
  check(Array.isArray(streams), 'status.json has no "streams" array');
  return streams.length === 0 ? null : streams.reduce((a, b) => (b.id > a.id ? b : a));
}

// Waits for the page's stream, newer than stream id `after`, to have CU on (noVNC enables it at the first
// EndOfContinuousUpdates). status.json is refreshed about once a second, so a new client may take that long to show.
const pushedStream = (sim, after = 0) => poll('the page\'s stream with continuous updates on', 10_000, 100,
  async () => {
    const stream = await pageStream(sim);
    return stream && stream.id > after && stream.continuous_updates ? stream : null;
  });

// Looks at the canvas until two looks STILL_MS apart differ in no pixel beyond noise; resolves with the name of
// the last snapshot.
async function waitForStillPicture(page, name) {
  let previous = `${name}-0`;
  await snapshot(page, previous);
  let round = 0;
  await poll(`the picture to stand still (${name})`, 10_000, 0, async () => {
    await sleep(STILL_MS);
    round += 1;
    const current = `${name}-${round}`;
    await snapshot(page, current);
    const changed = await changedFraction(page, previous, current, 8);
    previous = current;
    return changed === 0;
  });
  return previous;
}

// The canvas' RGBA pixels as a Buffer (for comparing canvases of different pages).
async function canvasPixels(page) {
  const base64 = await page.evaluate(() => {
    const canvas = document.querySelector('#screen canvas');
    const data = canvas.getContext('2d').getImageData(0, 0, canvas.width, canvas.height).data;
    let text = '';
    for (let i = 0; i < data.length; i += 0x8000) {
      text += String.fromCharCode.apply(null, data.subarray(i, i + 0x8000));
    }
    return btoa(text);
  });
  return Buffer.from(base64, 'base64');
}

// Mean absolute difference of R, G and B (0..255 each) and the share of pixels changed beyond the threshold.
function compareRgba(a, b) {
  check(a.length === b.length, `pictures of different sizes (${a.length} and ${b.length} bytes)`);
  const sums = [0, 0, 0];
  let changed = 0;
  for (let i = 0; i < a.length; i += 4) {
    let total = 0;
    for (let c = 0; c < 3; c += 1) {
      const d = Math.abs(a[i + c] - b[i + c]);
      sums[c] += d;
      total += d;
    }
    if (total > PIXEL_CHANGE_THRESHOLD) {
      changed += 1;
    }
  }
  const pixels = a.length / 4;
  return { mad: sums.map((s) => s / pixels), changed: changed / pixels };
}

// Presses key for ms and waits until the canvas differs from snapshot `before` in at least MIN_CHANGED_FRACTION.
async function pressAndSeeChange(page, key, ms, before, what) {
  await snapshot(page, before);
  await page.keyboard.down(key);
  await sleep(ms);
  await page.keyboard.up(key);
  let changed = 0;
  await poll(what, 10_000, 200, async () => {
    await snapshot(page, `${before}-after`);
    changed = await changedFraction(page, before, `${before}-after`, PIXEL_CHANGE_THRESHOLD);
    return changed >= MIN_CHANGED_FRACTION;
  });
  return changed;
}

// ---------------------------------------------------------------------------------------------------------------
// Breaking the decoder from the test. The guard made window.VideoDecoder a subclass of the browser's class, whose
// decode() it calls for every chunk: replacing that one method (once) reaches the decoder noVNC is using, under
// noVNC and under the guard, without either of them knowing.
// ---------------------------------------------------------------------------------------------------------------

// The next chunk reaches the real decoder as broken bytes (its start code and NAL header kept, the rest
// scrambled): Chromium's decoder fails with EncodingError, as it would on a picture damaged on its way.
const breakNextChunk = (page) => page.evaluate(() => {
  const native = Object.getPrototypeOf(window.VideoDecoder).prototype;
  const decode = native.decode;
  native.decode = function brokenDecode(chunk) {
    native.decode = decode;
    const data = new Uint8Array(chunk.byteLength + 64);
    chunk.copyTo(data);
    for (let i = 5; i < data.length; i += 1) {
      data[i] = (i * 7919) & 0xff;
    }
    return decode.call(this, new EncodedVideoChunk({ type: chunk.type, timestamp: chunk.timestamp, data }));
  };
});

// The next chunk is swallowed: it never reaches the decoder, so its frame never comes out (a decoder that drops
// a picture without a word).
const swallowNextChunk = (page) => page.evaluate(() => {
  const native = Object.getPrototypeOf(window.VideoDecoder).prototype;
  const decode = native.decode;
  native.decode = function swallowedDecode() {
    native.decode = decode;
  };
});

// While the page recovers: { notice: the progress line says RECOVERY_NOTICE, held: the frozen picture is kept
// on screen (app.js puts a copy of it behind the view) }.
const recoveryLook = (page) => page.evaluate((notice) => ({
  notice: window.rfbsimState.recovering && document.getElementById('status-text').textContent === notice &&
          !document.getElementById('status').hidden,
  held: window.rfbsimState.recovering &&
        getComputedStyle(document.getElementById('screen')).backgroundImage.startsWith('url("data:image/jpeg'),
}), RECOVERY_NOTICE);

// Breaks the decoder with `breaker`, makes the picture change so that a chunk comes, and waits for the page to
// replace its connection and show a picture again. Returns { failure, reportedMs, reconnectMs, recoveredMs,
// noticeShown, heldShown, oldStreamId } (ms since the break was armed); the first look with the notice is kept as
// screenshot `shot`, if given.
async function failAndRecover(page, sim, breaker, label, shot = null) {
  const before = await pageState(page);
  const oldStream = await pageStream(sim);
  await breaker(page);
  const armed = Date.now();
  // A turn changes the picture, so the next chunk is not long in coming.
  await page.keyboard.down('d');
  let failure = null;
  let reportedMs = null;
  let reconnectMs = null;
  let noticeShown = false;
  let heldShown = false;
  const lookAtRecovery = async () => {
    const look = await recoveryLook(page);
    if (look.notice && !noticeShown && shot !== null) {
      await page.screenshot({ path: shot });
    }
    noticeShown ||= look.notice;
    heldShown ||= look.held;
  };
  try {
    await poll(`${label}: the page to report the failure and reconnect`, 15_000, 50, async () => {
      const state = await pageState(page);
      if (reportedMs === null && state.pictureFailures > before.pictureFailures) {
        reportedMs = Date.now() - armed;
        failure = state.lastPictureFailure;
        await page.keyboard.up('d');
      }
      await lookAtRecovery();
      if (reconnectMs === null && state.attempts > before.attempts) {
        reconnectMs = Date.now() - armed;
      }
      check(!state.lastDisconnect, `${label}: the page shows a disconnect: ${state.lastDisconnect?.message}`);
      check(await driver.isHidden(page, '#disconnected'), `${label}: the disconnect panel shows`);
      return reconnectMs !== null;
    });
  } finally {
    await page.keyboard.up('d');
  }
  await poll(`${label}: a picture on the new connection`, 15_000, 50, async () => {
    await lookAtRecovery();
    const state = await pageState(page);
    return state.connected && !state.recovering;
  });
  const recoveredMs = Date.now() - armed;
  const background = await page.evaluate(() => getComputedStyle(document.getElementById('screen')).backgroundImage);
  check(background === 'none', `${label}: the held picture is still behind the view after recovery (${background})`);
  return { failure, reportedMs, reconnectMs, recoveredMs, noticeShown, heldShown, oldStreamId: oldStream.id };
}

// After a recovery: the picture is live (a key press changes it, with no click: the view kept the keyboard) and
// the server pushes updates again, answered by the page's fences. oldStreamId: the replaced connection's stream.
async function checkLive(page, sim, label, oldStreamId) {
  const state = await pageState(page);
  check(state.focused, `${label}: the new view does not have the keyboard (a click would be needed)`);
  check(await driver.isHidden(page, '#status'), `${label}: the progress line still shows after recovery`);
  const stream0 = await pushedStream(sim, oldStreamId);
  const changed = await pressAndSeeChange(page, 'a', 400, `${label}-live`,
                                          `${label}: the picture to change after a key press`);
  const stream1 = await pageStream(sim);
  check(stream1.id === stream0.id && stream1.updates_sent > stream0.updates_sent,
        `${label}: no updates pushed after the recovery: ${JSON.stringify([stream0, stream1])}`);
  return { changed, updates: stream1.updates_sent - stream0.updates_sent, encoding: stream1.encoding };
}

// ---------------------------------------------------------------------------------------------------------------
// The test.
// ---------------------------------------------------------------------------------------------------------------
async function main() {
  driver = loadDriver(env);
  const results = {};
  const browser = await driver.launch({ width: 800, height: 600 });
  const page = await browser.firstPage();
  const { pageErrors, close: closeConsoleLog } =
    recordPage(page, artifact('streaming-console.log'));

  // ---- a. Tight JPEG with ContinuousUpdates and Fence ------------------------------------------------------
  const jpegSim = await startStreamSim(`${PREFIX}sim_rfb-jpeg`, 'jpeg');
  await openPage(page, jpegSim.url);
  await waitForConnection(page);
  await waitForPicture(page, 'jpeg-first');
  const jpegStream = await pushedStream(jpegSim);
  log(`jpeg stream: ${JSON.stringify(jpegStream)}`);
  check(jpegStream.encoding === 'tight', `--codec jpeg streams "${jpegStream.encoding}", expected "tight"`);
  check(jpegStream.fence === true, 'the page\'s stream has "fence" false: noVNC answers fences');
  check(Number.isFinite(jpegStream.base_rtt_ms) && jpegStream.base_rtt_ms >= 0,
        `base_rtt_ms is not a number: ${jpegStream.base_rtt_ms}`);
  check((await pageState(page)).h264Offered === true,
        'the page did not offer H.264 at http://127.0.0.1 (no WebCodecs in this Chromium?)');

  // The still scene's JPEG picture: the reference for b.
  await waitForStillPicture(page, 'jpeg-still');
  const jpegStill = await canvasPixels(page);
  await saveCanvasPng(page, artifact('streaming_jpeg_still_canvas.png'));

  // Walking: updates keep coming without any FramebufferUpdateRequest, and the canvas keeps changing.
  await driver.click(page, '#screen canvas');
  const walk0 = await pageStream(jpegSim);
  await page.keyboard.down('w');
  await page.keyboard.down('a');
  let changingSamples = 0;
  const samples = Math.round(WALK_MS / WALK_SAMPLE_MS);
  await snapshot(page, 'walk-0');
  for (let i = 1; i <= samples; i += 1) {
    await sleep(WALK_SAMPLE_MS);
    await snapshot(page, `walk-${i}`);
    if (await changedFraction(page, `walk-${i - 1}`, `walk-${i}`, PIXEL_CHANGE_THRESHOLD) > 0.005) {
      changingSamples += 1;
    }
  }
  await page.keyboard.up('a');
  await page.keyboard.up('w');
  const walk1 = await pageStream(jpegSim);
  results.continuousUpdates = {
    stream: jpegStream, updatesWhileWalking: walk1.updates_sent - walk0.updates_sent,
    updateRequests: [walk0.update_requests, walk1.update_requests], changingSamples, samples,
  };
  log(`walking ${WALK_MS} ms: ${walk1.updates_sent - walk0.updates_sent} updates pushed, update requests ` +
      `${walk0.update_requests} -> ${walk1.update_requests}, canvas changed in ${changingSamples}/${samples} looks`);
  check(walk1.id === walk0.id, 'the page\'s stream changed while walking');
  check(walk1.updates_sent - walk0.updates_sent >= MIN_WALK_UPDATES,
        `only ${walk1.updates_sent - walk0.updates_sent} updates pushed while walking (need ${MIN_WALK_UPDATES})`);
  check(walk1.update_requests === walk0.update_requests,
        `the page sent ${walk1.update_requests - walk0.update_requests} FramebufferUpdateRequests while walking ` +
        '(with continuous updates it sends none)');
  check(changingSamples >= MIN_CHANGING_SAMPLES,
        `the canvas changed in only ${changingSamples} of ${samples} looks while walking`);
  await stopSimCleanly(jpegSim);

  // ---- b. H.264 decoded by WebCodecs -----------------------------------------------------------------------
  const h264Sim = await startStreamSim(`${PREFIX}sim_rfb-h264`, 'h264');
  await openPage(page, h264Sim.url);
  await waitForConnection(page);
  await waitForPicture(page, 'h264-first');
  const h264Stream = await pushedStream(h264Sim);
  log(`h264 stream: ${JSON.stringify(h264Stream)}`);
  check(h264Stream.encoding === 'h264', `--codec h264 streams "${h264Stream.encoding}" to a page offering H.264`);
  const h264State = await pageState(page);
  check(h264State.h264Guarded, 'the H.264 guard is not installed although the browser has VideoDecoder');

  await waitForStillPicture(page, 'h264-still');
  const h264Still = await canvasPixels(page);
  await saveCanvasPng(page, artifact('streaming_h264_still_canvas.png'));
  const codecs = compareRgba(h264Still, jpegStill);
  results.h264VsJpeg = codecs;
  log(`H.264 vs JPEG, still scene: mean |difference| R ${codecs.mad[0].toFixed(2)}, ` +
      `G ${codecs.mad[1].toFixed(2)}, B ${codecs.mad[2].toFixed(2)}; ` +
      `${(100 * codecs.changed).toFixed(2)} % of pixels beyond ${PIXEL_CHANGE_THRESHOLD}`);
  check(codecs.mad.every((m) => m < MAX_CODEC_MAD),
        `the H.264 picture differs from the JPEG one by more than ${MAX_CODEC_MAD} per channel`);
  check(codecs.changed < MAX_CODEC_CHANGED_FRACTION,
        `${(100 * codecs.changed).toFixed(2)} % of the H.264 picture's pixels differ from the JPEG one ` +
        `(at most ${100 * MAX_CODEC_CHANGED_FRACTION} %)`);

  await driver.click(page, '#screen canvas');
  const turned = await pressAndSeeChange(page, 'd', 400, 'h264-turn', 'the H.264 picture to change after a turn');
  results.h264Turn = turned;
  log(`after a turn, ${(100 * turned).toFixed(1)} % of the H.264 picture changed`);

  // Where the browser has no VideoDecoder (any insecure context: plain http to a host other than localhost), the
  // guard stays out of the way and the same server streams JPEG: seen here on a second page whose VideoDecoder
  // is taken away before any script runs.
  const plainPage = await browser.newPage();
  const plainLog = recordPage(plainPage, artifact('streaming-console-no-webcodecs.log'));
  await driver.addInitScript(plainPage, () => { delete window.VideoDecoder; });
  await openPage(plainPage, h264Sim.url);
  await waitForConnection(plainPage);
  await waitForPicture(plainPage, 'no-webcodecs');
  const plainState = await pageState(plainPage);
  const plainStream = await pushedStream(h264Sim, h264Stream.id);
  log(`a page without VideoDecoder: guard installed ${plainState.h264Guarded}, H.264 offered ` +
      `${plainState.h264Offered}, stream ${plainStream.encoding}`);
  check(!plainState.h264Guarded && plainState.h264Offered === false && plainStream.encoding === 'tight',
        `a page without VideoDecoder should get JPEG: ${JSON.stringify({ plainState, plainStream })}`);
  check(plainLog.pageErrors.length === 0, `uncaught errors without VideoDecoder: ${plainLog.pageErrors.join(' | ')}`);
  await plainPage.close();
  await plainLog.close();
  results.withoutVideoDecoder = { state: plainState, stream: plainStream };

  // ---- c. A picture the decoder cannot decode does not freeze the page -------------------------------------
  // Three failures in a row: broken bytes (the decoder's error), a chunk that never comes out (the stall
  // check), broken bytes again (the third: the page then asks for JPEG). Each time the page must reconnect by
  // itself, waiting longer each time, and show a live picture again.
  const recoveries = [];
  const breakers = [[breakNextChunk, 'error'], [swallowNextChunk, 'stalled'], [breakNextChunk, 'error']];
  for (const [i, [breaker, reason]] of breakers.entries()) {
    const label = `failure ${i + 1}`;
    const r = await failAndRecover(page, h264Sim, breaker, label,
                                   artifact(`streaming_restoring_${i + 1}.png`));
    log(`${label}: ${r.failure.reason} reported after ${r.reportedMs} ms (${r.failure.detail}); reconnect ` +
        `after ${r.reconnectMs} ms, picture back after ${r.recoveredMs} ms` +
        (r.heldShown ? '; the frozen picture stayed on screen' : '') +
        (r.noticeShown ? `; the page said "${RECOVERY_NOTICE}"` : ''));
    check(r.failure.reason === reason, `${label}: reported as ${r.failure.reason}, expected ${reason}`);
    if (reason === 'stalled') {
      check(r.reportedMs >= STALL_MS, `${label}: a stall reported after ${r.reportedMs} ms, before ${STALL_MS} ms`);
    }
    // A wait of a second or more is long enough for the test to see the held picture.
    check(BACKOFF_MS[i] < 1000 || r.heldShown, `${label}: the frozen picture was not kept on screen while waiting`);
    check(r.reconnectMs - r.reportedMs >= BACKOFF_MS[i] - 100,
          `${label}: reconnected ${r.reconnectMs - r.reportedMs} ms after the failure, expected a wait of ` +
          `${BACKOFF_MS[i]} ms`);
    const state = await pageState(page);
    check(state.pictureFailures === i + 1, `${label}: the page counts ${state.pictureFailures} failures`);
    const live = await checkLive(page, h264Sim, label, r.oldStreamId);
    log(`${label}: live again on ${live.encoding}: a key press changed ${(100 * live.changed).toFixed(1)} % ` +
        `of the picture, ${live.updates} updates pushed`);
    recoveries.push({ ...r, ...live, h264Offered: state.h264Offered, h264Disabled: state.h264Disabled });
  }
  results.recoveries = recoveries;
  await page.screenshot({ path: artifact('streaming_recovered.png') });

  check(recoveries[0].encoding === 'h264' && recoveries[1].encoding === 'h264',
        'after the first two failures the new connection is not on H.264 again');
  check(recoveries[2].noticeShown,
        `the third recovery (a ${BACKOFF_MS[2]} ms wait) did not show "${RECOVERY_NOTICE}"`);
  check(recoveries[2].h264Disabled && recoveries[2].h264Offered === false && recoveries[2].encoding === 'tight',
        `after three failures in a row the page should ask for JPEG: ${JSON.stringify(recoveries[2])}`);
  const streams = (await getStatus(h264Sim)).streams;
  check(streams.length === 1, `the server has ${streams.length} streams, expected the page's one (old ones closed)`);
  check(pageErrors.length === 0, `uncaught errors in the page: ${pageErrors.join(' | ')}`);

  fs.writeFileSync(artifact('streaming.json'), `${JSON.stringify(results, null, 2)}\n`);
  await stopSimCleanly(h264Sim);
  await closeConsoleLog();
}

await runTest(`${env.browser === 'chromium' ? 'browser' : env.browser}_e2e_streaming`, 90, main);
