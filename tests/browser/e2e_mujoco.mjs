// SPDX-License-Identifier: GPL-2.0-or-later
// Browser end-to-end test of a simulator we did not write, linked through librfbsim: sim_manager serves
// examples/mujoco_rfb (MuJoCo's arm on a table) as `session_kind: rfb` with no scenarios, so a link carries only
// a uid; the bundled page in a real Chromium shows MuJoCo's picture, the picture holds still with no key, and
// holding W (the arm's shoulder) changes it. SIGTERM then stops sim_manager and its session cleanly.
//
// Usage: node e2e_mujoco.mjs SIM_MANAGER MUJOCO_RFB WEB_ROOT ARTIFACTS_DIR [WEB_DIR]
//   SIM_MANAGER    the sim_manager executable to start
//   MUJOCO_RFB     the mujoco_rfb executable it starts per session
//   WEB_ROOT       the assembled web root (build/web/root) sim_manager serves
//   ARTIFACTS_DIR  where mujoco_*.png, sim_manager's output, its data folder (mujoco-data) and the browser
//                  console are written (created)
//   WEB_DIR        the source web/ folder whose node_modules holds playwright-core (default: ../../web from here)
// Environment: RFBSIM_CHROMIUM (default /usr/bin/chromium), RFBSIM_E2E_TIMEOUT_S (default 90).
// Exits 0 when every check passed, 1 on the first failed check, 2 on the overall timeout.

import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';

import {
  PIXEL_CHANGE_THRESHOLD, changedFraction, check, childrenOf, launchBrowser, log, onCleanup, openPage,
  parseManagerArgs, poll, prepare, procInfo, recordPage, runTest, sleep, snapshot, startSim, stopSimCleanly,
  waitForConnection, waitForPicture,
} from './e2e_support.mjs';

const HOLD_W_MS = 800;                  // how long W is held down, wall time
const MIN_CHANGED_FRACTION = 0.01;      // at least this share of canvas pixels must change after W (the arm)
const MAX_STILL_FRACTION = 0.001;       // at most this share may change in a second with no key
const VIEWPORT = { width: 1024, height: 720 };
const TOKEN_PATH = /^\/s\/([0-9a-f]{32})\/$/;

const env = parseManagerArgs('e2e_mujoco.mjs');

// Whether a process with this pid still runs (a zombie does not count).
function running(pid) {
  const info = procInfo(pid);
  return info !== null && info.state !== 'Z';
}

async function main() {
  const chromium = prepare(env);
  check(fs.existsSync(env.simRfbPath), `mujoco_rfb not found at ${env.simRfbPath}`);

  // 0. The manager's config: the MuJoCo example as a linked program, with no scenarios.
  const scratch = fs.mkdtempSync(path.join(os.tmpdir(), 'rfbsim-e2e-mujoco-'));
  onCleanup(() => fs.rmSync(scratch, { recursive: true, force: true }));
  const dataDir = path.join(env.artifacts, 'mujoco-data');
  fs.rmSync(dataDir, { recursive: true, force: true });
  const config = path.join(scratch, 'manager.yaml');
  fs.writeFileSync(config, [
    'session_kind: rfb',
    `session_command: ${JSON.stringify(env.simRfbPath)}`,
    'session_args: [--port, "{port}", --bind, 127.0.0.1, --rfb-only]',
    'first_connect_timeout_s: 60',
    'idle_timeout_s: 30',
    'stop_grace_s: 3',
    '',
  ].join('\n'));

  // 1. sim_manager starts; its session processes are killed at cleanup should anything go wrong.
  const manager = await startSim(env, 'sim_manager', [
    '--config', config, '--port', '0', '--data-dir', dataDir, '--web-root', env.webRoot,
  ]);
  const base = manager.url;
  const sessionPids = new Set();
  onCleanup(() => {
    for (const pid of sessionPids) {
      if (running(pid)) {
        log(`cleanup: killing session process group ${pid}`);
        try {
          process.kill(-pid, 'SIGKILL');
        } catch {
          // already gone
        }
      }
    }
  });

  // 2. A link with only a uid leads to the session page, which shows MuJoCo's picture.
  const context = await launchBrowser(chromium, VIEWPORT);
  const page = context.pages()[0] || await context.newPage();
  recordPage(page, path.join(env.artifacts, 'mujoco-browser-console.log'));
  await openPage(page, new URL('start?uid=e2e-mujoco', base).href);
  const parsed = new URL(page.url());
  check(parsed.origin === new URL(base).origin && TOKEN_PATH.test(parsed.pathname),
        `the link led to ${page.url()}, expected ${new URL(base).origin}/s/<32 hex digits>/`);
  await waitForConnection(page);
  for (const child of childrenOf(manager.child.pid)) {
    sessionPids.add(child.pid);
  }
  const picture = await waitForPicture(page, 'first');
  log(`canvas ${picture.width}x${picture.height}, ${picture.colours}+ colours, luma range ` +
      `${picture.lumaRange.toFixed(0)}`);
  check(picture.width === 640 && picture.height === 480,
        `the canvas is ${picture.width}x${picture.height}, expected mujoco_rfb's 640x480`);
  await page.screenshot({ path: path.join(env.artifacts, 'mujoco_session.png') });

  // 3. With no key the arm rests: the picture a second later is the same.
  await page.locator('#screen canvas').click();
  await page.locator('#hint').waitFor({ state: 'hidden', timeout: 5000 });
  await sleep(1500);   // the arm settles on its servos; any update in flight arrives
  await snapshot(page, 'A');
  await sleep(1000);
  await snapshot(page, 'B');
  const still = await changedFraction(page, 'A', 'B', PIXEL_CHANGE_THRESHOLD);
  log(`canvas pixels changed in a second without a key: ${(100 * still).toFixed(2)} %`);
  check(still >= 0 && still <= MAX_STILL_FRACTION,
        `the picture changed by itself (${(100 * still).toFixed(2)} % of pixels) with no key held`);

  // 4. Holding W moves the arm's shoulder: the picture changes.
  log(`holding W for ${HOLD_W_MS} ms`);
  await page.keyboard.down('w');
  await sleep(HOLD_W_MS);
  await page.keyboard.up('w');
  await poll('the picture to change after W', 10_000, 250, async () => {
    await snapshot(page, 'C');
    return (await changedFraction(page, 'B', 'C', PIXEL_CHANGE_THRESHOLD)) >= MIN_CHANGED_FRACTION;
  });
  const moved = await changedFraction(page, 'B', 'C', PIXEL_CHANGE_THRESHOLD);
  log(`canvas pixels changed after W: ${(100 * moved).toFixed(1)} % (need >= ${100 * MIN_CHANGED_FRACTION} %)`);
  await page.screenshot({ path: path.join(env.artifacts, 'mujoco_after_w.png') });

  // 5. SIGTERM stops sim_manager with the session running, and the session's process goes with it.
  await context.close();
  await stopSimCleanly(manager);
  await poll('the session process to be gone', 10_000, 100, () => [...sessionPids].every((pid) => !running(pid)));
  log('sim_manager exited 0 and no mujoco_rfb is left');
}

runTest('e2e_mujoco', 90, main);
