// SPDX-License-Identifier: GPL-2.0-or-later
// Browser end-to-end test: a real Chromium opens sim_rfb's page, walks the avatar with W and sees the picture change.
//
// Usage: node e2e_walk.mjs SIM_RFB ARTIFACTS_DIR [WEB_DIR]
//   SIM_RFB        the sim_rfb executable to start (twice: once for the walk, once to test Reconnect)
//   ARTIFACTS_DIR  where screenshots, the simulator's output and the browser console are written (created)
//   WEB_DIR        the source web/ folder whose node_modules holds playwright-core (default: ../../web from here)
// Environment: RFBSIM_CHROMIUM (default /usr/bin/chromium), RFBSIM_E2E_TIMEOUT_S (default 90).
// Exits 0 when every check passed, 1 on the first failed check, 2 on the overall timeout.

import { spawn } from 'node:child_process';
import fs from 'node:fs';
import { createRequire } from 'node:module';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));

// ---------------------------------------------------------------------------------------------------------------
// Settings.
// ---------------------------------------------------------------------------------------------------------------
const SIM_WIDTH = 640;                 // framebuffer size asked of sim_rfb, pixels
const SIM_HEIGHT = 480;
const READY_TIMEOUT_MS = 30_000;       // sim_rfb must print its ready line within this
const HOLD_W_MS = 1500;                // how long W is held down, wall time
const MIN_WALK_M = 0.3;                // the avatar must move at least this far, metres
const MIN_CHANGED_FRACTION = 0.03;     // at least this share of canvas pixels must change after the walk
const PIXEL_CHANGE_THRESHOLD = 48;     // |dR| + |dG| + |dB| above this counts as a changed pixel
const EXIT_TIMEOUT_MS = 10_000;        // sim_rfb must exit this soon after SIGTERM
const OVERALL_TIMEOUT_MS = 1000 * Number(process.env.RFBSIM_E2E_TIMEOUT_S || 90);
const CHROMIUM = process.env.RFBSIM_CHROMIUM || '/usr/bin/chromium';
const CHROMIUM_ARGS = [
  '--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
  '--disable-background-networking', '--disable-component-update', '--disable-sync',
];

// ---------------------------------------------------------------------------------------------------------------
// Progress and failure.
// ---------------------------------------------------------------------------------------------------------------
const t0 = Date.now();
function log(message) {
  const seconds = ((Date.now() - t0) / 1000).toFixed(1).padStart(5);
  console.log(`[e2e ${seconds}s] ${message}`);
}

class CheckFailed extends Error {}
function check(condition, message) {
  if (!condition) {
    throw new CheckFailed(message);
  }
}

const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

// Resolves with fn()'s first truthy value, polling every intervalMs; throws CheckFailed after timeoutMs.
// A CheckFailed thrown by fn ends the wait at once; other errors (a refused fetch, say) are retried.
async function poll(what, timeoutMs, intervalMs, fn) {
  const deadline = Date.now() + timeoutMs;
  let lastError = null;
  for (;;) {
    try {
      const value = await fn();
      if (value) {
        return value;
      }
    } catch (err) {
      if (err instanceof CheckFailed) {
        throw err;
      }
      lastError = err;
    }
    if (Date.now() >= deadline) {
      const detail = lastError ? ` (last error: ${lastError.message})` : '';
      throw new CheckFailed(`timed out after ${timeoutMs} ms waiting for ${what}${detail}`);
    }
    await sleep(intervalMs);
  }
}

// ---------------------------------------------------------------------------------------------------------------
// Arguments.
// ---------------------------------------------------------------------------------------------------------------
const [simPath, artifactsArg, webArg] = process.argv.slice(2);
if (!simPath || !artifactsArg) {
  console.error('usage: node e2e_walk.mjs SIM_RFB ARTIFACTS_DIR [WEB_DIR]');
  process.exit(1);
}
const artifacts = path.resolve(artifactsArg);
const webDir = path.resolve(webArg || path.join(here, '..', '..', 'web'));

// ---------------------------------------------------------------------------------------------------------------
// The simulator process: start, wait for the ready line, stop.
// ---------------------------------------------------------------------------------------------------------------
const sims = [];   // every sim_rfb started, for cleanup

// Starts sim_rfb and resolves with { child, url } once it printed its ready line.
function startSim(name, port) {
  const args = ['--port', String(port), '--width', String(SIM_WIDTH), '--height', String(SIM_HEIGHT)];
  log(`starting ${name}: ${simPath} ${args.join(' ')}`);
  const logFile = fs.createWriteStream(path.join(artifacts, `${name}.log`));
  const child = spawn(simPath, args, { stdio: ['ignore', 'pipe', 'pipe'] });
  const sim = { name, child, exited: null, logFile, tail: [] };
  sims.push(sim);

  const exited = new Promise((resolve) => {
    child.on('exit', (code, signal) => {
      sim.exited = { code, signal };
      resolve(sim.exited);
    });
  });
  sim.exitedPromise = exited;

  // Keep the last lines of output for failure messages; everything goes to the log file.
  const remember = (stream, label) => {
    let partial = '';
    stream.on('data', (chunk) => {
      logFile.write(chunk);
      partial += chunk.toString('utf8');
      const lines = partial.split('\n');
      partial = lines.pop();
      for (const line of lines) {
        sim.tail.push(`${label}: ${line}`);
        if (sim.tail.length > 30) {
          sim.tail.shift();
        }
        if (label === 'stdout' && sim.onStdoutLine) {
          sim.onStdoutLine(line);
        }
      }
    });
  };
  remember(child.stdout, 'stdout');
  remember(child.stderr, 'stderr');

  const ready = new Promise((resolve, reject) => {
    const timer = setTimeout(() => {
      reject(new CheckFailed(`${name} printed no ready line (http://...) within ${READY_TIMEOUT_MS} ms`));
    }, READY_TIMEOUT_MS);
    child.on('error', (err) => {
      clearTimeout(timer);
      reject(new CheckFailed(`could not start ${simPath}: ${err.message}`));
    });
    exited.then(({ code, signal }) => {
      clearTimeout(timer);
      reject(new CheckFailed(`${name} exited before it was ready (code ${code}, signal ${signal})`));
    });
    sim.onStdoutLine = (line) => {
      const match = /http:\/\/\S+/.exec(line);
      if (match) {
        clearTimeout(timer);
        sim.onStdoutLine = null;
        resolve(match[0]);
      }
    };
  });
  return ready.then((url) => {
    sim.url = url;
    log(`${name} ready at ${url}`);
    return sim;
  });
}

// Sends SIGTERM and resolves with { code, signal }; throws if the process is still there after timeoutMs.
async function stopSim(sim, timeoutMs) {
  if (sim.exited) {
    return sim.exited;
  }
  sim.child.kill('SIGTERM');
  const result = await Promise.race([sim.exitedPromise, sleep(timeoutMs).then(() => null)]);
  if (result === null) {
    throw new CheckFailed(`${sim.name} did not exit within ${timeoutMs} ms of SIGTERM`);
  }
  return result;
}

async function getStatus(sim) {
  const response = await fetch(new URL('status.json', sim.url), { signal: AbortSignal.timeout(3000) });
  check(response.ok, `GET status.json answered HTTP ${response.status}`);
  return response.json();
}

function avatarOf(status) {
  const a = status && status.avatar;
  check(a && Number.isFinite(a.x) && Number.isFinite(a.y),
        `status.json has no numeric avatar.x / avatar.y: ${JSON.stringify(status)}`);
  return { x: a.x, y: a.y, yaw: a.yaw };
}

// ---------------------------------------------------------------------------------------------------------------
// Canvas pixels, compared inside the page (no megabytes through the protocol).
// ---------------------------------------------------------------------------------------------------------------

// Stores the canvas' pixels under `name` and returns simple statistics about them.
function snapshot(page, name) {
  return page.evaluate((name) => {
    const canvas = document.querySelector('#screen canvas');
    if (!canvas || canvas.width === 0 || canvas.height === 0) {
      return { ok: false, why: 'no canvas, or canvas has no size yet' };
    }
    const image = canvas.getContext('2d').getImageData(0, 0, canvas.width, canvas.height);
    window.__e2eSnapshots = window.__e2eSnapshots || {};
    window.__e2eSnapshots[name] = image;
    let minLuma = 255;
    let maxLuma = 0;
    const colours = new Set();
    const d = image.data;
    for (let i = 0; i < d.length; i += 4 * 7) {
      const luma = (d[i] * 299 + d[i + 1] * 587 + d[i + 2] * 114) / 1000;
      minLuma = Math.min(minLuma, luma);
      maxLuma = Math.max(maxLuma, luma);
      if (colours.size < 1000) {
        colours.add((d[i] << 16) | (d[i + 1] << 8) | d[i + 2]);
      }
    }
    return { ok: true, width: canvas.width, height: canvas.height, lumaRange: maxLuma - minLuma,
             colours: colours.size };
  }, name);
}

// Share of pixels that differ between two stored snapshots.
function changedFraction(page, a, b, threshold) {
  return page.evaluate(({ a, b, threshold }) => {
    const A = window.__e2eSnapshots[a];
    const B = window.__e2eSnapshots[b];
    if (!A || !B || A.width !== B.width || A.height !== B.height) {
      return -1;
    }
    let changed = 0;
    for (let i = 0; i < A.data.length; i += 4) {
      const diff = Math.abs(A.data[i] - B.data[i]) + Math.abs(A.data[i + 1] - B.data[i + 1]) +
                   Math.abs(A.data[i + 2] - B.data[i + 2]);
      if (diff > threshold) {
        changed += 1;
      }
    }
    return changed / (A.width * A.height);
  }, { a, b, threshold });
}

// Writes the canvas itself (unscaled, no overlays) as a PNG.
async function saveCanvasPng(page, file) {
  const dataUrl = await page.evaluate(() => document.querySelector('#screen canvas').toDataURL('image/png'));
  fs.writeFileSync(file, Buffer.from(dataUrl.slice(dataUrl.indexOf(',') + 1), 'base64'));
}

// A picture with content: a real size and more than one colour.
async function waitForPicture(page, name) {
  return poll(`a picture with content on the canvas (${name})`, 15_000, 250, async () => {
    const s = await snapshot(page, name);
    return s.ok && s.colours > 8 && s.lumaRange > 16 ? s : null;
  });
}

const pageState = (page) => page.evaluate(() => JSON.parse(JSON.stringify(window.rfbsimState || null)));

// ---------------------------------------------------------------------------------------------------------------
// Cleanup: always, once, whatever happened.
// ---------------------------------------------------------------------------------------------------------------
let context = null;
let userDataDir = null;
let cleanupPromise = null;

function cleanup() {
  if (cleanupPromise) {
    return cleanupPromise;
  }
  cleanupPromise = (async () => {
    if (context) {
      await Promise.race([context.close().catch(() => {}), sleep(10_000)]);
    }
    for (const sim of sims) {
      if (!sim.exited) {
        log(`cleanup: stopping ${sim.name} (pid ${sim.child.pid})`);
        sim.child.kill('SIGTERM');
        const gone = await Promise.race([sim.exitedPromise, sleep(3000).then(() => null)]);
        if (!gone) {
          sim.child.kill('SIGKILL');
          await Promise.race([sim.exitedPromise, sleep(2000)]);
        }
      }
      sim.logFile.end();
    }
    if (userDataDir) {
      fs.rmSync(userDataDir, { recursive: true, force: true });
    }
  })();
  return cleanupPromise;
}

function printSimTails() {
  for (const sim of sims) {
    if (sim.tail.length > 0) {
      console.error(`--- last output of ${sim.name} (full log: ${path.join(artifacts, sim.name + '.log')}) ---`);
      console.error(sim.tail.join('\n'));
    }
  }
}

const watchdog = setTimeout(() => {
  console.error(`FAIL: overall timeout of ${OVERALL_TIMEOUT_MS / 1000} s reached`);
  printSimTails();
  const hardExit = setTimeout(() => process.exit(2), 15_000);
  hardExit.unref();
  cleanup().finally(() => process.exit(2));
}, OVERALL_TIMEOUT_MS);

for (const signal of ['SIGINT', 'SIGTERM']) {
  process.on(signal, () => {
    console.error(`FAIL: interrupted by ${signal}`);
    cleanup().finally(() => process.exit(1));
  });
}

// ---------------------------------------------------------------------------------------------------------------
// The test.
// ---------------------------------------------------------------------------------------------------------------
async function main() {
  check(fs.existsSync(simPath), `sim_rfb not found at ${simPath}`);
  check(fs.existsSync(CHROMIUM), `Chromium not found at ${CHROMIUM}`);
  fs.mkdirSync(artifacts, { recursive: true });
  log(`artifacts go to ${artifacts}`);

  // playwright-core lives in web/node_modules (NODE_PATH does not reach ES module imports).
  let chromium;
  try {
    ({ chromium } = createRequire(path.join(webDir, 'package.json'))('playwright-core'));
  } catch (err) {
    throw new CheckFailed(`cannot load playwright-core from ${webDir}/node_modules ` +
                          `(run: npm ci --prefix ${webDir}): ${err.message}`);
  }

  // 1. The simulator starts and answers status.json.
  const sim = await startSim('sim_rfb-1', 0);
  const port = new URL(sim.url).port;
  // The first status may be published a moment after the ready line; allow a few seconds for it.
  const status0 = await poll('status.json to report the avatar', 5000, 100, async () => {
    const status = await getStatus(sim);
    return status && status.avatar ? status : null;
  });
  log(`status.json: ${JSON.stringify(status0)}`);
  avatarOf(status0);

  // 2. A fresh browser opens the page.
  userDataDir = fs.mkdtempSync(path.join(os.tmpdir(), 'rfbsim-e2e-chromium-'));
  log(`launching ${CHROMIUM}`);
  context = await chromium.launchPersistentContext(userDataDir, {
    executablePath: CHROMIUM,
    headless: true,
    args: CHROMIUM_ARGS,
    viewport: { width: 800, height: 600 },
    timeout: 30_000,
  });
  const page = context.pages()[0] || await context.newPage();
  const consoleLog = fs.createWriteStream(path.join(artifacts, 'browser-console.log'));
  const pageErrors = [];
  page.on('console', (msg) => consoleLog.write(`${msg.type()}: ${msg.text()}\n`));
  page.on('pageerror', (err) => {
    pageErrors.push(err.message);
    consoleLog.write(`pageerror: ${err.message}\n`);
  });
  page.on('requestfailed', (req) => consoleLog.write(`requestfailed: ${req.url()} ${req.failure()?.errorText}\n`));
  const badResponses = [];
  page.on('response', (res) => {
    if (res.status() >= 400) {
      badResponses.push(`${res.status()} ${res.url()}`);
      consoleLog.write(`response: HTTP ${res.status()} for ${res.url()}\n`);
    }
  });

  // A valid and an invalid query option: the first is used, the second ignored.
  const pageUrl = new URL('?quality=7&compression=high', sim.url).href;
  log(`opening ${pageUrl}`);
  const response = await page.goto(pageUrl, { waitUntil: 'load', timeout: 20_000 });
  check(response && response.ok(), `GET ${pageUrl} answered HTTP ${response && response.status()}`);
  const compatMode = await page.evaluate(() => document.compatMode);
  check(compatMode === 'CSS1Compat', `page renders in quirks mode (${compatMode})`);
  // app.js may still be evaluating when 'load' fires (seen with Chromium 156), so wait for its state object.
  const initialState = await poll('app.js to start (window.rfbsimState)', 10_000, 100, () => pageState(page));
  const pageOptions = initialState.options;
  check(pageOptions && pageOptions.quality === 7 && pageOptions.compression === null,
        `query options not applied as expected (quality=7 used, compression=high ignored): ${JSON.stringify(pageOptions)}`);

  // 3. noVNC connects and the canvas shows a real picture.
  await poll('the RFB connection (window.rfbsimState.connected)', 20_000, 200, async () => {
    const state = await pageState(page);
    check(state !== null, 'the page did not set window.rfbsimState (app.js not loaded?)');
    check(!state.lastDisconnect, `the page reports a disconnect: ${state.lastDisconnect?.message}`);
    return state.connected;
  });
  log('noVNC connected');
  const before = await waitForPicture(page, 'A');
  log(`canvas ${before.width}x${before.height}, ${before.colours}+ colours, luma range ${before.lumaRange.toFixed(0)}`);
  check(before.width === SIM_WIDTH && before.height === SIM_HEIGHT,
        `canvas is ${before.width}x${before.height}, expected ${SIM_WIDTH}x${SIM_HEIGHT}`);

  // The view is scaled into the window without scrollbars, keeping the aspect ratio.
  const layout = await page.evaluate(() => {
    const r = document.querySelector('#screen canvas').getBoundingClientRect();
    const root = document.scrollingElement || document.documentElement;
    return { left: r.left, top: r.top, width: r.width, height: r.height, innerWidth, innerHeight,
             scrollWidth: root.scrollWidth, scrollHeight: root.scrollHeight };
  });
  check(layout.scrollWidth <= layout.innerWidth && layout.scrollHeight <= layout.innerHeight,
        `the page scrolls: ${JSON.stringify(layout)}`);
  check(layout.left >= -1 && layout.top >= -1 && layout.left + layout.width <= layout.innerWidth + 1 &&
        layout.top + layout.height <= layout.innerHeight + 1, `canvas is outside the window: ${JSON.stringify(layout)}`);
  check(Math.abs(layout.width / layout.height - SIM_WIDTH / SIM_HEIGHT) < 0.02 &&
        (Math.abs(layout.width - layout.innerWidth) < 2 || Math.abs(layout.height - layout.innerHeight) < 2),
        `canvas is not scaled to fit the window: ${JSON.stringify(layout)}`);
  log(`canvas shown at ${layout.width.toFixed(0)}x${layout.height.toFixed(0)} in a ` +
      `${layout.innerWidth}x${layout.innerHeight} window`);

  // 4. Before a click the focus hint shows; screenshot A.
  const hint = page.locator('#hint');
  check(await hint.isVisible(), 'the focus hint is not visible before the canvas was clicked');
  log(`focus hint visible: "${(await hint.innerText()).replace(/\s+/g, ' ').trim()}"`);
  await page.screenshot({ path: path.join(artifacts, 'walk_before.png') });
  await saveCanvasPng(page, path.join(artifacts, 'walk_before_canvas.png'));

  // 5. A click on the canvas gives it the keyboard, and the hint goes away.
  await page.locator('#screen canvas').click();
  await hint.waitFor({ state: 'hidden', timeout: 5000 });
  const focusedState = await pageState(page);
  check(focusedState.focused, 'rfbsimState.focused is false after clicking the canvas');
  check(await page.evaluate(() => document.activeElement === document.querySelector('#screen canvas')),
        'the canvas does not have keyboard focus after the click');
  log('clicked the canvas: it has focus, the hint is hidden');

  // 6. Hold W, then the simulator reports that the avatar walked.
  const start = avatarOf(await getStatus(sim));
  log(`holding W for ${HOLD_W_MS} ms (avatar at x=${start.x.toFixed(3)} y=${start.y.toFixed(3)})`);
  await page.keyboard.down('w');
  await sleep(HOLD_W_MS);
  await page.keyboard.up('w');
  const walked = await poll(`the avatar to move more than ${MIN_WALK_M} m`, 10_000, 200, async () => {
    const a = avatarOf(await getStatus(sim));
    const distance = Math.hypot(a.x - start.x, a.y - start.y);
    return distance > MIN_WALK_M ? { a, distance } : null;
  });
  log(`avatar moved ${walked.distance.toFixed(2)} m to x=${walked.a.x.toFixed(3)} y=${walked.a.y.toFixed(3)}`);

  // 7. The picture follows; screenshot B differs substantially from A.
  await poll('the picture to change after walking', 10_000, 250, async () => {
    await snapshot(page, 'B');
    return (await changedFraction(page, 'A', 'B', PIXEL_CHANGE_THRESHOLD)) >= MIN_CHANGED_FRACTION;
  });
  await sleep(500);   // let the last updates of the walk arrive
  const after = await snapshot(page, 'B');
  check(after.ok, `canvas unreadable after the walk: ${after.why}`);
  const changed = await changedFraction(page, 'A', 'B', PIXEL_CHANGE_THRESHOLD);
  await page.screenshot({ path: path.join(artifacts, 'walk_after.png') });
  await saveCanvasPng(page, path.join(artifacts, 'walk_after_canvas.png'));
  log(`canvas pixels changed after the walk: ${(100 * changed).toFixed(1)} % ` +
      `(need >= ${(100 * MIN_CHANGED_FRACTION).toFixed(1)} %)`);
  check(changed >= MIN_CHANGED_FRACTION, 'the picture did not change enough after walking');
  log('screenshots: walk_before.png, walk_after.png (+ *_canvas.png)');

  // 8. SIGTERM ends the simulator cleanly.
  const exit1 = await stopSim(sim, EXIT_TIMEOUT_MS);
  log(`sim_rfb-1 exited: code ${exit1.code}, signal ${exit1.signal}`);
  check(exit1.code === 0 && exit1.signal === null, `sim_rfb-1 did not exit with code 0 on SIGTERM`);

  // 9. The page says the connection ended and offers Reconnect.
  const panel = page.locator('#disconnected');
  await panel.waitFor({ state: 'visible', timeout: 10_000 });
  const reconnect = page.getByRole('button', { name: 'Reconnect' });
  check(await reconnect.isVisible(), 'no visible Reconnect button after the disconnect');
  check(await reconnect.isEnabled(), 'the Reconnect button is disabled');
  const panelText = (await panel.innerText()).replace(/\s+/g, ' ').trim();
  const disconnected = await pageState(page);
  check(!disconnected.connected && disconnected.lastDisconnect, 'rfbsimState does not record the disconnect');
  check(await hint.isHidden(), 'the focus hint still shows while disconnected');
  log(`disconnect shown: "${panelText}" (kind ${disconnected.lastDisconnect.kind}, ` +
      `close code ${disconnected.lastDisconnect.code})`);
  await page.screenshot({ path: path.join(artifacts, 'disconnected.png') });

  // 10. Reconnect works without reloading the page, against a new simulator on the same port.
  const sim2 = await startSim('sim_rfb-2', port);
  check(new URL(sim2.url).port === port, `sim_rfb-2 is on port ${new URL(sim2.url).port}, asked for ${port}`);
  await page.evaluate(() => { window.__e2eNoReload = true; });
  await reconnect.click();
  await poll('the page to reconnect', 20_000, 200, async () => {
    const state = await pageState(page);
    check(state.attempts === 2, `expected 2 connection attempts, page made ${state.attempts}`);
    check(state.connecting || state.connected, `reconnect failed: ${state.lastDisconnect?.message}`);
    return state.connected;
  });
  check(await page.evaluate(() => window.__e2eNoReload === true), 'the page reloaded on Reconnect');
  check(await panel.isHidden(), 'the disconnect panel still shows after reconnecting');
  await waitForPicture(page, 'C');
  const reconnected = await pageState(page);
  check(reconnected.focused, 'after Reconnect the simulator view does not have keyboard focus');
  log('reconnected without a page reload; the view has focus and a picture');
  await page.screenshot({ path: path.join(artifacts, 'reconnected.png') });

  const exit2 = await stopSim(sim2, EXIT_TIMEOUT_MS);
  check(exit2.code === 0 && exit2.signal === null,
        `sim_rfb-2 did not exit with code 0 on SIGTERM (code ${exit2.code}, signal ${exit2.signal})`);
  await panel.waitFor({ state: 'visible', timeout: 10_000 });

  check(pageErrors.length === 0, `uncaught errors in the page: ${pageErrors.join(' | ')}`);
  consoleLog.end();
}

let exitCode = 0;
try {
  await main();
  log('PASS: browser_e2e_walk');
} catch (err) {
  exitCode = 1;
  if (err instanceof CheckFailed) {
    console.error(`FAIL: ${err.message}`);
  } else {
    console.error(`FAIL: unexpected error: ${err && err.stack ? err.stack : err}`);
  }
  printSimTails();
} finally {
  await cleanup();
  clearTimeout(watchdog);
}
process.exit(exitCode);
