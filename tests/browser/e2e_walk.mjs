// SPDX-License-Identifier: GPL-2.0-or-later
// Browser end-to-end test: a real Chromium opens sim_rfb's page, walks the avatar with W and sees the picture change.
//
// Usage: node e2e_walk.mjs SIM_RFB ARTIFACTS_DIR [WEB_DIR]
//   SIM_RFB        the sim_rfb executable to start (twice: once for the walk, once to test Reconnect)
//   ARTIFACTS_DIR  where screenshots, the simulator's output and the browser console are written (created)
//   WEB_DIR        the source web/ folder whose node_modules holds playwright-core (default: ../../web from here)
// Environment: RFBSIM_CHROMIUM (default /usr/bin/chromium), RFBSIM_E2E_TIMEOUT_S (default 90).
// Exits 0 when every check passed, 1 on the first failed check, 2 on the overall timeout.

import path from 'node:path';

import {
  PIXEL_CHANGE_THRESHOLD, changedFraction, check, firstStatus, getStatus, launchBrowser, log, openPage,
  parseArgs, pageState, poll, prepare, recordPage, runTest, saveCanvasPng, sleep, snapshot, startSim,
  stopSimCleanly, waitForConnection, waitForPicture,
} from './e2e_support.mjs';

// ---------------------------------------------------------------------------------------------------------------
// Settings.
// ---------------------------------------------------------------------------------------------------------------
const SIM_WIDTH = 640;                 // framebuffer size asked of sim_rfb, pixels
const SIM_HEIGHT = 480;
const HOLD_W_MS = 1500;                // how long W is held down, wall time
const MIN_WALK_M = 0.3;                // the avatar must move at least this far, metres
const MIN_CHANGED_FRACTION = 0.03;     // at least this share of canvas pixels must change after the walk
const env = parseArgs('e2e_walk.mjs');

function avatarOf(status) {
  const a = status && status.avatar;
  check(a && Number.isFinite(a.x) && Number.isFinite(a.y),
        `status.json has no numeric avatar.x / avatar.y: ${JSON.stringify(status)}`);
  return { x: a.x, y: a.y, yaw: a.yaw };
}

// Starts sim_rfb on port at the walk's framebuffer size.
const startWalkSim = (name, port) =>
  startSim(env, name, ['--port', String(port), '--width', String(SIM_WIDTH), '--height', String(SIM_HEIGHT)]);

// ---------------------------------------------------------------------------------------------------------------
// The test.
// ---------------------------------------------------------------------------------------------------------------
async function main() {
  const chromium = prepare(env);

  // 1. The simulator starts and answers status.json.
  const sim = await startWalkSim('sim_rfb-1', 0);
  const port = new URL(sim.url).port;
  const status0 = await firstStatus(sim);
  log(`status.json: ${JSON.stringify(status0)}`);
  avatarOf(status0);

  // 2. A fresh browser opens the page.
  const context = await launchBrowser(chromium, { width: 800, height: 600 });
  const page = context.pages()[0] || await context.newPage();
  const { pageErrors, close: closeConsoleLog } = recordPage(page, path.join(env.artifacts, 'browser-console.log'));

  // A valid and an invalid query option: the first is used, the second ignored.
  const pageUrl = new URL('?quality=7&compression=high', sim.url).href;
  const initialState = await openPage(page, pageUrl);
  const pageOptions = initialState.options;
  check(pageOptions && pageOptions.quality === 7 && pageOptions.compression === null,
        `query options not applied as expected (quality=7 used, compression=high ignored): ${JSON.stringify(pageOptions)}`);

  // 3. noVNC connects and the canvas shows a real picture.
  await waitForConnection(page);
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
  await page.screenshot({ path: path.join(env.artifacts, 'walk_before.png') });
  await saveCanvasPng(page, path.join(env.artifacts, 'walk_before_canvas.png'));

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
  await page.screenshot({ path: path.join(env.artifacts, 'walk_after.png') });
  await saveCanvasPng(page, path.join(env.artifacts, 'walk_after_canvas.png'));
  log(`canvas pixels changed after the walk: ${(100 * changed).toFixed(1)} % ` +
      `(need >= ${(100 * MIN_CHANGED_FRACTION).toFixed(1)} %)`);
  check(changed >= MIN_CHANGED_FRACTION, 'the picture did not change enough after walking');
  log('screenshots: walk_before.png, walk_after.png (+ *_canvas.png)');

  // 8. SIGTERM ends the simulator cleanly.
  await stopSimCleanly(sim);

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
  await page.screenshot({ path: path.join(env.artifacts, 'disconnected.png') });

  // 10. Reconnect works without reloading the page, against a new simulator on the same port.
  const sim2 = await startWalkSim('sim_rfb-2', port);
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
  await page.screenshot({ path: path.join(env.artifacts, 'reconnected.png') });

  await stopSimCleanly(sim2);
  await panel.waitFor({ state: 'visible', timeout: 10_000 });

  check(pageErrors.length === 0, `uncaught errors in the page: ${pageErrors.join(' | ')}`);
  await closeConsoleLog();
}

await runTest('browser_e2e_walk', 90, main);
