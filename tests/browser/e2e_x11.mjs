// SPDX-License-Identifier: GPL-2.0-or-later
// Browser end-to-end test of `session_kind: x11` (issue 21): sim_manager runs an unmodified X11 program per
// session on its own TigerVNC Xvnc display, and a real Chromium reaches it through the bundled page.
//   1. Our key-echo program (tests/support/x11_key_echo.cpp) behind a uid-only link: the page shows its picture, a key
//      pressed in the page reaches the program (the picture changes, session.log gets `key w`), and the session
//      ended through the admin API leaves no Xvnc, no program and no X socket of its display behind.
//   2. The one-line demo, deploy/examples/x11-glxgears.yaml as shipped: glxgears turns in the page.
//
// Usage: node e2e_x11.mjs SIM_MANAGER KEY_ECHO WEB_ROOT ARTIFACTS_DIR [WEB_DIR]
//   SIM_MANAGER    the sim_manager executable to start (rfbsim_x11_session is found beside it)
//   KEY_ECHO       rfbsim_x11_key_echo, the X11 program of the first part
//   WEB_ROOT       the assembled web root (build/web/root) the first manager serves; the demo finds its own
//   ARTIFACTS_DIR  where x11_*.png, the managers' output, their data folders (x11-data, x11-demo-data) and the
//                  browser console are written (created)
//   WEB_DIR        the source web/ folder whose node_modules holds playwright-core (default: ../../web from here)
// The demo's config is read from ../../deploy/examples/x11-glxgears.yaml beside this script.
// Environment: RFBSIM_CHROMIUM (default /usr/bin/chromium), RFBSIM_E2E_TIMEOUT_S (default 90).
// Exits 0 when every check passed, 1 on the first failed check, 2 on the overall timeout.

import fs from 'node:fs';
import net from 'node:net';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

import {
  CheckFailed, PIXEL_CHANGE_THRESHOLD, changedFraction, check, launchBrowser, log, onCleanup, openPage, pageState,
  parseManagerArgs, poll, prepare, procInfo, recordPage, runTest, sleep, snapshot, startSim, stopSimCleanly,
  waitForConnection, waitForPicture,
} from './e2e_support.mjs';

// ---------------------------------------------------------------------------------------------------------------
// Settings.
// ---------------------------------------------------------------------------------------------------------------
const ADMIN_TOKEN = 'e2e-x11-admin-token-0123';   // 24 characters
const GEOMETRY = { width: 640, height: 480 };     // the display of both parts (the demo's config says 640x480)
const KEY_ECHO_BACKGROUND = [48, 48, 48];         // x11_key_echo.cpp's window before any key
const MIN_KEY_CHANGED_FRACTION = 0.5;   // the background (below the top quarter's noise) turns a bright colour
const MIN_GEARS_CHANGED_FRACTION = 0.002;   // glxgears' teeth turn: this share of pixels changes in a second
const SESSION_GONE_TIMEOUT_MS = 10_000;     // the session's processes must be gone this soon after its end
const VIEWPORT = { width: 1024, height: 720 };
const TOKEN_PATH = /^\/s\/([0-9a-f]{32})\/$/;

const env = parseManagerArgs('e2e_x11.mjs');
const demoConfig = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..', 'deploy', 'examples',
                                'x11-glxgears.yaml');

// ---------------------------------------------------------------------------------------------------------------
// Helpers: the manager's HTTP API, the processes under it, the display's files.
// ---------------------------------------------------------------------------------------------------------------

// A request to the manager at base (redirects are not followed); admin: with the Bearer token and the header
// the admin API asks of every state-changing request.
function request(base, pathname, { method = 'GET', admin = false } = {}) {
  const headers = admin ? { Authorization: `Bearer ${ADMIN_TOKEN}`, 'X-Rfbsim-Admin': '1' } : {};
  return fetch(new URL(pathname, base), { method, headers, redirect: 'manual', signal: AbortSignal.timeout(5000) });
}

// Every process below pid (children, their children, ...), from one pass over /proc.
function descendantsOf(pid) {
  const all = [];
  for (const entry of fs.readdirSync('/proc')) {
    if (/^\d+$/.test(entry)) {
      const info = procInfo(Number(entry));
      if (info) {
        all.push(info);
      }
    }
  }
  const found = [];
  const parents = new Set([pid]);
  // A process may be listed before its parent: go round until a pass adds nobody.
  for (let added = true; added;) {
    added = false;
    for (const info of all) {
      if (parents.has(info.ppid) && !parents.has(info.pid)) {
        parents.add(info.pid);
        found.push(info);
        added = true;
      }
    }
  }
  return found;
}

// Whether a process seen before (same pid and start time) still runs; a zombie does not count.
const stillThere = (proc) => {
  const now = procInfo(proc.pid);
  return now !== null && now.start === proc.start && now.state !== 'Z';
};

// Remembers every process under a manager so that none outlives the test: cleanup kills those still there.
// Returns { seen (pid -> procInfo), watch() to look again }.
function watchSessionProcesses(manager) {
  const seen = new Map();
  onCleanup(() => {
    for (const proc of seen.values()) {
      if (stillThere(proc)) {
        log(`cleanup: killing ${proc.comm} (pid ${proc.pid})`);
        try {
          process.kill(proc.pid, 'SIGKILL');
        } catch {
          // gone meanwhile
        }
      }
    }
  });
  const watch = () => {
    for (const proc of descendantsOf(manager.child.pid)) {
      if (!seen.has(proc.pid)) {
        seen.set(proc.pid, proc);
      }
    }
  };
  return { seen, watch };
}

const describeProcs = (procs) => procs.map((p) => `${p.comm} (pid ${p.pid})`).join(', ') || 'none';

// Whether something accepts connections on the unix socket at socketPath.
function socketAccepts(socketPath) {
  return new Promise((resolve) => {
    const socket = net.connect({ path: socketPath });
    const done = (accepted) => {
      socket.destroy();
      resolve(accepted);
    };
    socket.setTimeout(1000, () => done(false));
    socket.once('connect', () => done(true));
    socket.once('error', () => done(false));
  });
}

// What of display :N outlived its X server, as words ('' when nothing): its X socket with nobody accepting on
// it, or its lock file naming a process that is gone. A live server (another test's, by now) may hold N.
async function displayLeftovers(display) {
  const left = [];
  const socketPath = `/tmp/.X11-unix/X${display}`;
  if (fs.existsSync(socketPath) && !(await socketAccepts(socketPath))) {
    left.push(`${socketPath} (nobody accepts on it)`);
  }
  const lockPath = `/tmp/.X${display}-lock`;
  let lock = null;
  try {
    lock = fs.readFileSync(lockPath, 'utf8');
  } catch {
    // no lock: nothing left
  }
  if (lock !== null) {
    const pid = Number.parseInt(lock.trim(), 10);
    if (!(pid > 0) || procInfo(pid) === null) {
      left.push(`${lockPath} (pid ${lock.trim()} is gone)`);
    }
  }
  return left.join(', ');
}

// The RGB of the centre pixel of a stored snapshot.
const centrePixel = (page, name) => page.evaluate((name) => {
  const image = window.__e2eSnapshots[name];
  const i = 4 * (Math.floor(image.height / 2) * image.width + Math.floor(image.width / 2));
  return [image.data[i], image.data[i + 1], image.data[i + 2]];
}, name);

// Opens a uid-only link in page and checks that it leads to the session page; returns the session's token.
async function openLink(page, base, uid) {
  await openPage(page, new URL(`start?uid=${encodeURIComponent(uid)}`, base).href);
  const parsed = new URL(page.url());
  const match = TOKEN_PATH.exec(parsed.pathname);
  check(parsed.origin === new URL(base).origin && match,
        `the link for ${uid} led to ${page.url()}, expected ${new URL(base).origin}/s/<32 hex digits>/`);
  return match[1];
}

// Waits for a picture with content at the display's size; returns its snapshot statistics.
async function waitForDisplayPicture(page, name) {
  const picture = await waitForPicture(page, name);
  log(`${name}: canvas ${picture.width}x${picture.height}, ${picture.colours}+ colours, luma range ` +
      `${picture.lumaRange.toFixed(0)}`);
  check(picture.width === GEOMETRY.width && picture.height === GEOMETRY.height,
        `the canvas is ${picture.width}x${picture.height}, expected the display's ` +
        `${GEOMETRY.width}x${GEOMETRY.height}`);
  return picture;
}

// ---------------------------------------------------------------------------------------------------------------
// 1. The key-echo program: picture, a key, the end and what it leaves.
// ---------------------------------------------------------------------------------------------------------------
async function keyEchoSession(context, scratch) {
  check(fs.existsSync(env.simRfbPath), `rfbsim_x11_key_echo not found at ${env.simRfbPath}`);
  const dataDir = path.join(env.artifacts, 'x11-data');
  fs.rmSync(dataDir, { recursive: true, force: true });
  const config = path.join(scratch, 'x11.yaml');
  fs.writeFileSync(config, [
    'session_kind: x11',
    `session_command: ${JSON.stringify(env.simRfbPath)}`,
    'x11:',
    `  geometry: ${GEOMETRY.width}x${GEOMETRY.height}`,
    `admin_token: ${ADMIN_TOKEN}`,
    `data_dir: ${JSON.stringify(dataDir)}`,
    'first_connect_timeout_s: 30',
    'idle_timeout_s: 30',
    'stop_grace_s: 3',
    '',
  ].join('\n'));

  const manager = await startSim(env, 'x11-manager', ['--config', config, '--port', '0', '--web-root', env.webRoot]);
  const base = manager.url;
  const procs = watchSessionProcesses(manager);

  // A link with only a uid leads to the session page, which shows the program's window: noise on top of grey.
  const page = context.pages()[0] || await context.newPage();
  const pageLog = recordPage(page, path.join(env.artifacts, 'x11-browser-console.log'));
  const token = await openLink(page, base, 'e2e-x11');
  await waitForConnection(page);
  await waitForDisplayPicture(page, 'first');
  procs.watch();
  const first = await centrePixel(page, 'first');
  check(first.every((v, i) => Math.abs(v - KEY_ECHO_BACKGROUND[i]) <= 8),
        `the centre of the picture is rgb(${first}), expected key_echo's background rgb(${KEY_ECHO_BACKGROUND})`);
  await page.screenshot({ path: path.join(env.artifacts, 'x11_session.png') });

  // The session's row: its folder, where the launcher names its display.
  const listed = await request(base, 'api/sessions', { admin: true });
  check(listed.status === 200, `GET /api/sessions with the token answered HTTP ${listed.status}`);
  const live = (await listed.json()).live.filter((s) => s.token === token);
  check(live.length === 1 && live[0].uid === 'e2e-x11' && live[0].scenario === '' && live[0].state === 'running',
        `expected one running session e2e-x11 with no scenario: ${JSON.stringify(live)}`);
  const session = live[0];
  const sessionLog = path.join(session.data_path, 'session.log');
  const readLog = () => (fs.existsSync(sessionLog) ? fs.readFileSync(sessionLog, 'utf8') : '');
  const display = Number(await poll('session.log to name the display', 5000, 100,
                                    () => /^display :(\d+)$/m.exec(readLog())?.[1]));
  log(`session ${session.id} runs on display :${display}; its folder is ${session.data_path}`);
  const comms = [...procs.seen.values()].map((p) => p.comm);
  check(comms.includes('Xvnc') && comms.some((c) => 'rfbsim_x11_key_echo'.startsWith(c)),
        `expected Xvnc and the key-echo program under sim_manager, saw ${describeProcs([...procs.seen.values()])}`);

  // The page's hint names no WASD walking: the status says the session runs another program than sim_rfb.
  const hint = await poll('the hint to name the keyboard and the mouse', 5000, 100, async () => {
    const text = await page.locator('#hint p').textContent();
    return text.includes('keyboard and the mouse') ? text : null;
  });
  check(!hint.includes('walk'), `the hint still speaks of walking: '${hint}'`);

  // No window manager: keys go to the window under the pointer, so the pointer goes over it (a click also gives
  // the page the keyboard). Then W turns the background a bright colour and the program says so.
  await page.locator('#screen canvas').click();
  await sleep(300);   // the click's pointer events reach Xvnc before the key
  await snapshot(page, 'before-key');
  await page.keyboard.press('w');
  await poll('the picture to change after W', 10_000, 200, async () => {
    await snapshot(page, 'after-key');
    return (await changedFraction(page, 'before-key', 'after-key', PIXEL_CHANGE_THRESHOLD)) >=
           MIN_KEY_CHANGED_FRACTION;
  });
  const changed = await changedFraction(page, 'before-key', 'after-key', PIXEL_CHANGE_THRESHOLD);
  const after = await centrePixel(page, 'after-key');
  log(`W: ${(100 * changed).toFixed(1)} % of the pixels changed (need >= ${100 * MIN_KEY_CHANGED_FRACTION} %); ` +
      `centre rgb(${after})`);
  await poll('session.log to get "key w"', 10_000, 100, () => /^key w$/m.test(readLog()));
  log('session.log has "key w"');
  await page.screenshot({ path: path.join(env.artifacts, 'x11_after_key.png') });

  // The researcher ends the session: the page says so, and nothing of the session is left.
  procs.watch();
  const ended = await request(base, `api/sessions/${session.id}/end`, { method: 'POST', admin: true });
  check(ended.status === 200, `POST /api/sessions/${session.id}/end answered HTTP ${ended.status}`);
  await page.locator('#disconnected').waitFor({ state: 'visible', timeout: 10_000 });
  const title = (await page.locator('#disconnected-title').innerText()).trim();
  const endedState = await pageState(page);
  log(`ended page: "${title}" (${JSON.stringify(endedState.lastDisconnect)})`);
  check(title === 'Session ended', `the panel's title is "${title}", expected "Session ended"`);
  check(endedState.lastDisconnect.final === true && endedState.lastDisconnect.code === 1001 &&
        endedState.lastDisconnect.reason === 'session ended by the researcher',
        `rfbsimState.lastDisconnect: ${JSON.stringify(endedState.lastDisconnect)}`);
  await page.screenshot({ path: path.join(env.artifacts, 'x11_ended.png') });
  const all = [...procs.seen.values()];
  await poll(`the session's processes (${describeProcs(all)}) to be gone`, SESSION_GONE_TIMEOUT_MS, 100,
             () => !all.some(stillThere));
  log(`gone after the end: ${describeProcs(all)}`);
  let leftovers = '';
  await poll(`display :${display}'s files to go`, 5000, 200, async () => {
    leftovers = await displayLeftovers(display);
    return leftovers === '';
  }).catch((err) => {
    throw new CheckFailed(`${err.message}; left behind: ${leftovers}`);
  });
  log(`display :${display}: no X socket or lock file left behind`);
  const status = await (await request(base, `s/${token}/status`)).json();
  check(status.state === 'ended', `the session's status says ${status.state}, expected ended`);

  check(pageLog.pageErrors.length === 0, `uncaught errors in the page: ${pageLog.pageErrors.join(' | ')}`);
  await stopSimCleanly(manager);
  await pageLog.close();
}

// ---------------------------------------------------------------------------------------------------------------
// 2. The one-line demo as shipped: glxgears turns in the page.
// ---------------------------------------------------------------------------------------------------------------
async function glxgearsDemo(context) {
  check(fs.existsSync(demoConfig), `the demo's config is not at ${demoConfig}`);
  const dataDir = path.join(env.artifacts, 'x11-demo-data');
  fs.rmSync(dataDir, { recursive: true, force: true });
  // As the docs run it, with no --web-root (the manager finds the page it was built with).
  const manager = await startSim(env, 'x11-demo-manager', [
    '--config', demoConfig, '--port', '0', '--data-dir', dataDir, '--frame-origins', 'http://127.0.0.1:1',
  ]);
  const procs = watchSessionProcesses(manager);

  const page = await context.newPage();
  const pageLog = recordPage(page, path.join(env.artifacts, 'x11-demo-browser-console.log'));
  await openLink(page, manager.url, 'e2e-gears');
  await waitForConnection(page);
  await waitForDisplayPicture(page, 'gears-a');
  procs.watch();
  check([...procs.seen.values()].some((p) => p.comm === 'glxgears'),
        `no glxgears under sim_manager: ${describeProcs([...procs.seen.values()])}`);
  await page.screenshot({ path: path.join(env.artifacts, 'x11_gears.png') });
  await sleep(1000);
  await snapshot(page, 'gears-b');
  const turned = await changedFraction(page, 'gears-a', 'gears-b', PIXEL_CHANGE_THRESHOLD);
  log(`glxgears: ${(100 * turned).toFixed(2)} % of the pixels changed in a second (need >= ` +
      `${100 * MIN_GEARS_CHANGED_FRACTION} %)`);
  check(turned >= MIN_GEARS_CHANGED_FRACTION, 'the gears did not turn: the picture held still for a second');
  await page.screenshot({ path: path.join(env.artifacts, 'x11_gears_later.png') });

  // SIGTERM stops the demo with its session running, and glxgears and its Xvnc go with it.
  check(pageLog.pageErrors.length === 0, `uncaught errors in the page: ${pageLog.pageErrors.join(' | ')}`);
  procs.watch();
  await stopSimCleanly(manager);
  const all = [...procs.seen.values()];
  await poll(`the demo's session processes (${describeProcs(all)}) to be gone`, SESSION_GONE_TIMEOUT_MS, 100,
             () => !all.some(stillThere));
  log(`the demo stopped; gone: ${describeProcs(all)}`);
  await pageLog.close();
}

async function main() {
  const chromium = prepare(env);
  const scratch = fs.mkdtempSync(path.join(os.tmpdir(), 'rfbsim-e2e-x11-'));
  onCleanup(() => fs.rmSync(scratch, { recursive: true, force: true }));
  const context = await launchBrowser(chromium, VIEWPORT);
  await keyEchoSession(context, scratch);
  await glxgearsDemo(context);
}

await runTest('browser_e2e_x11', 90, main);
