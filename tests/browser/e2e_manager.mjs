// SPDX-License-Identifier: GPL-2.0-or-later
// Browser end-to-end test of sim_manager: a real browser (Chromium, or Firefox ESR with --browser firefox) follows
// participant links, sees the start-up progress and the first picture, walks, reloads, is embedded in a survey
// (allowed and refused origins), is ended by the researcher through the admin API, and the admin page lists
// sessions, watches one view-only and ends it. The stream the walking page got (codec, quality, frame rate) is logged.
//
// Usage: node e2e_manager.mjs [--browser chromium|firefox] SIM_MANAGER SIM_RFB WEB_ROOT ARTIFACTS_DIR [WEB_DIR]
//   SIM_MANAGER    the sim_manager executable to start
//   SIM_RFB        the sim_rfb executable it starts per session (through a small wrapper script that can delay
//                  the start, so that the page's start-up progress can be seen)
//   WEB_ROOT       the assembled web root (build/web/root) sim_manager serves
//   ARTIFACTS_DIR  where screenshots (manager_*.png; firefox_manager_*.png in Firefox), sim_manager's output, its
//                  data folder (manager-data; firefox-manager-data) and the browser console are written (created)
//   WEB_DIR        the source web/ folder whose node_modules holds playwright-core and puppeteer-core (default:
//                  ../../web from here)
// Environment: RFBSIM_CHROMIUM (default /usr/bin/chromium), RFBSIM_FIREFOX (default /usr/bin/firefox-esr),
// RFBSIM_E2E_TIMEOUT_S (default 150).
// Exits 0 when every check passed, 1 on the first failed check, 2 on the overall timeout.

import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';

import { loadDriver } from './browser_driver.mjs';
import {
  PIXEL_CHANGE_THRESHOLD, changedFraction, check, childrenOf, log, onCleanup, openPage, pageState,
  parseManagerArgs, poll, procInfo, recordPage, runTest, serveHtmlPage, sleep, snapshot, startSim,
  stopSimCleanly, waitForConnection, waitForPicture,
} from './e2e_support.mjs';

// ---------------------------------------------------------------------------------------------------------------
// Settings.
// ---------------------------------------------------------------------------------------------------------------
const ADMIN_TOKEN = 'e2e-admin-token-01234567';   // 24 characters
const SCENARIO = 'lab';
const IDLE_TIMEOUT_S = 30;
const SLOW_START_S = 2;                // the wrapper's delay for the second session (to see the progress)
const HOLD_W_MS = 1500;                // how long W is held down, wall time
const MIN_CHANGED_FRACTION = 0.03;     // at least this share of canvas pixels must change after the walk
const FIRST_FRAME_TIMEOUT_MS = 20_000; // a link must show its first picture within this
const BLOCKED_FRAME_TIMEOUT_MS = 10_000;
const VIEWPORT = { width: 1024, height: 720 };
const SURVEY_FRAME = { width: 800, height: 450 };
const TOKEN_PATH = /^\/s\/([0-9a-f]{32})\/$/;


const env = parseManagerArgs('e2e_manager.mjs');
// The Chromium test's files keep their names; the Firefox run's beside them get a firefox_ (firefox-) prefix.
const PREFIX = env.browser === 'chromium' ? '' : `${env.browser}_`;
const artifact = (name) => path.join(env.artifacts, `${PREFIX}${name}`);
const artifactDir = (name) => path.join(env.artifacts, `${PREFIX.replace('_', '-')}${name}`);

// ---------------------------------------------------------------------------------------------------------------
// Helpers: the manager's HTTP API, the session processes, the survey servers.
// ---------------------------------------------------------------------------------------------------------------
let base = '';   // http://127.0.0.1:PORT/ of sim_manager

// A request to sim_manager (redirects are not followed); admin: with the Bearer token.
function request(pathname, { method = 'GET', admin = false, headers = {} } = {}) {
  const allHeaders = { ...headers };
  if (admin) {
    allHeaders.Authorization = `Bearer ${ADMIN_TOKEN}`;
  }
  return fetch(new URL(pathname, base), { method, headers: allHeaders, redirect: 'manual',
                                           signal: AbortSignal.timeout(5000) });
}

async function listSessions() {
  const response = await request('api/sessions', { admin: true });
  check(response.status === 200, `GET /api/sessions with the token answered HTTP ${response.status}`);
  return response.json();
}

// Logs the stream sim_rfb last reported for uid's live session (GET /api/sessions: codec, quality, frame rate, round
// trip),
// so that each run says what its browser was sent. sim_rfb reports about once a second while someone watches.
async function logStream(uid, when) {
  const session = await poll(`the stream report of ${uid}`, 5000, 250, async () => {
    const live = (await listSessions()).live.find((s) => s.uid === uid);
    return live && live.codec ? live : null;
  }).catch(() => null);
  log(`stream of ${uid} ${when} (${env.browser}): ` + (session
    ? `codec ${session.codec}, quality ${session.quality ?? 'none'}, ${session.fps} updates/s, ` +
      `round trip ${session.rtt_ms} ms`
    : 'not reported within 5 s'));
}

const startLink = (uid) => new URL(`start?uid=${encodeURIComponent(uid)}&scenario=${SCENARIO}`, base).href;

// The session token a page URL names (checks the URL's form).
function tokenOf(url, what) {
  const parsed = new URL(url);
  const match = TOKEN_PATH.exec(parsed.pathname);
  check(parsed.origin === new URL(base).origin && match,
        `${what}: expected ${new URL(base).origin}/s/<32 hex digits>/, got ${url}`);
  return match[1];
}

// Whether a process seen before (same pid and start time) is still there.
const stillThere = (proc) => {
  const now = procInfo(proc.pid);
  return now !== null && now.start === proc.start;
};

// A survey page: a form field that has the keyboard, and the session link in an iframe.
function surveyPage(link) {
  const src = link.replace(/&/g, '&amp;').replace(/"/g, '&quot;');
  return `<!DOCTYPE html>
<html lang="en">
<head><meta charset="utf-8"><title>Study survey</title></head>
<body style="font-family: sans-serif; margin: 1rem;">
  <h1 style="font-size: 1.2rem; margin: 0 0 0.5rem;">Study survey (test page)</h1>
  <p><label for="answer">Your answer</label> <input id="answer" autofocus></p>
  <iframe id="sim" title="Simulation" src="${src}" width="${SURVEY_FRAME.width}" height="${SURVEY_FRAME.height}"
          style="border: 1px solid #888;"></iframe>
</body>
</html>
`;
}

// The survey test page on its own loopback origin: /survey?uid=U embeds U's session link.
function startSurveyServer(name) {
  return serveHtmlPage(name, '/survey', (url) => surveyPage(startLink(url.searchParams.get('uid') || '')));
}

// Records every text the page's progress line shows (in every frame), with when: window.__e2eStatusSeen.
function recordStatusLine() {
  window.__e2eStatusSeen = [];
  const record = () => {
    const status = document.getElementById('status');
    if (!status) {
      return;
    }
    const text = status.hidden ? '' : status.textContent.replace(/\s+/g, ' ').trim();
    const seen = window.__e2eStatusSeen;
    if (seen.length === 0 || seen[seen.length - 1].text !== text) {
      seen.push({ text, at: Math.round(performance.now()) });
    }
  };
  new MutationObserver(record).observe(document, { subtree: true, childList: true, characterData: true,
                                                   attributes: true, attributeFilter: ['hidden'] });
}

const statusSeen = (target) => target.evaluate(() => window.__e2eStatusSeen || []);
const describeSeen = (seen) => seen.map((s) => `${s.at} ms "${s.text}"`).join(', ');

// Waits for window.rfbsimState.firstFrameAt in target (a page or a frame) and returns it.
function waitForFirstFrame(target, what) {
  return poll(`the first picture of ${what} (rfbsimState.firstFrameAt)`, FIRST_FRAME_TIMEOUT_MS, 50, async () => {
    const state = await pageState(target);
    check(!state || !state.lastDisconnect,
          `${what}: the page reports a disconnect: ${state?.lastDisconnect?.message}`);
    return state && state.firstFrameAt !== null ? state.firstFrameAt : null;
  });
}

// ---------------------------------------------------------------------------------------------------------------
// The test.
// ---------------------------------------------------------------------------------------------------------------
async function main() {
  const driver = loadDriver(env);
  check(fs.existsSync(env.simRfbPath), `sim_rfb not found at ${env.simRfbPath}`);
  check(fs.existsSync(path.join(env.webRoot, 'admin.html')), `no admin.html in the web root ${env.webRoot}`);

  // 0. A wrapper that starts sim_rfb, late while the flag file exists; a fresh data folder; the survey servers.
  const scratch = fs.mkdtempSync(path.join(os.tmpdir(), 'rfbsim-e2e-manager-'));
  onCleanup(() => fs.rmSync(scratch, { recursive: true, force: true }));
  const slowFlag = path.join(scratch, 'slow-start');
  const wrapper = path.join(scratch, 'sim_rfb_wrapper.sh');
  check(!env.simRfbPath.includes("'") && !slowFlag.includes("'"), 'paths with quotes are not supported');
  fs.writeFileSync(wrapper, [
    '#!/bin/sh',
    `# rfbsim e2e: sim_rfb, started ${SLOW_START_S} s late while ${slowFlag} exists.`,
    `if [ -e '${slowFlag}' ]; then sleep ${SLOW_START_S}; fi`,
    `exec '${env.simRfbPath}' "$@"`,
    '',
  ].join('\n'), { mode: 0o755 });
  const dataDir = artifactDir('manager-data');
  fs.rmSync(dataDir, { recursive: true, force: true });

  const survey = await startSurveyServer('survey server (allowed origin)');
  const stranger = await startSurveyServer('survey server (origin not allowed)');

  // 1. sim_manager starts; its session processes are watched so that none can outlive the test.
  const manager = await startSim(env, `${PREFIX}sim_manager`, [
    '--port', '0', '--data-dir', dataDir, '--scenarios', SCENARIO, '--admin-token', ADMIN_TOKEN,
    '--frame-origins', survey.origin, '--idle-timeout-s', String(IDLE_TIMEOUT_S),
    '--session-command', wrapper, '--web-root', env.webRoot,
  ]);
  base = manager.url;
  const sessionProcs = new Map();   // pid -> procInfo of every process sim_manager started
  const watchChildren = () => {
    for (const child of childrenOf(manager.child.pid)) {
      if (!sessionProcs.has(child.pid)) {
        sessionProcs.set(child.pid, child);
      }
    }
  };
  onCleanup(() => {
    for (const proc of sessionProcs.values()) {
      if (stillThere(proc)) {
        log(`cleanup: killing session process group ${proc.pid}`);
        try {
          process.kill(-proc.pid, 'SIGKILL');
        } catch {
          // already gone
        }
      }
    }
  });

  const unauthorised = await request('api/sessions');
  check(unauthorised.status === 401, `GET /api/sessions without the token answered HTTP ${unauthorised.status}`);

  // 2. The browser (admin credentials only for sim_manager's origin, only when asked for them).
  const browser = await driver.launch(VIEWPORT, {
    credentials: { username: 'researcher', password: ADMIN_TOKEN, origin: new URL(base).origin },
  });
  await browser.addInitScript(recordStatusLine);
  const page = await browser.firstPage();
  const pageLog = recordPage(page, artifact('manager-browser-console.log'));
  log(`browser: ${await page.evaluate(() => navigator.userAgent)}`);
  const sockets = driver.watchWebSockets(page);

  // ---- a. The link leads to /s/<token>/, which shows progress, then a picture. ----
  const link1 = startLink('e2e-1');
  const navigatedAt = Date.now();
  await openPage(page, link1);
  const token1 = tokenOf(page.url(), 'the page after /start');
  log(`redirected to ${page.url()}`);
  const firstFrameAt = await waitForFirstFrame(page, 'e2e-1');
  const seenWall = Date.now() - navigatedAt;
  const timing = await page.evaluate(() => {
    const n = performance.getEntriesByType('navigation')[0];
    return { redirectEnd: n.redirectEnd, responseEnd: n.responseEnd, domContentLoaded: n.domContentLoadedEventEnd };
  });
  const socket1 = sockets[0];
  const ms = (value) => (value === null || value === undefined ? '?' : `${Math.round(value)} ms`);
  log(`link -> first picture: ${ms(firstFrameAt)} after the navigation started (rfbsimState.firstFrameAt; ` +
      `the test saw it ${seenWall} ms after calling goto)`);
  log(`  page time: redirect done ${ms(timing.redirectEnd)}, page loaded ${ms(timing.responseEnd)}, ` +
      `DOMContentLoaded (noVNC's modules in) ${ms(timing.domContentLoaded)}; wall time from goto: WebSocket ` +
      `opened ${ms(socket1 && socket1.openedAt - navigatedAt)}, first RFB bytes ` +
      `${ms(socket1 && socket1.firstDataAt && socket1.firstDataAt - navigatedAt)}` +
      (driver.name === 'firefox' ? ' (WebDriver BiDi does not show WebSocket data)' : ''));
  check(socket1 && new URL(socket1.url).pathname === `/s/${token1}/ws`,
        `the page's WebSocket went to ${socket1?.url}, expected /s/${token1}/ws`);
  const seen1 = await statusSeen(page);
  log(`progress line showed: ${describeSeen(seen1)}`);
  check(seen1.some((s) => /^(Starting your simulation|Connecting to the simulator)/.test(s.text)),
        'the page never showed "Starting your simulation" or "Connecting to the simulator"');
  check(seen1.length > 0 && seen1[seen1.length - 1].text === '', 'the progress line still shows after the picture');
  await waitForConnection(page);
  const picture1 = await waitForPicture(page, 'A0');
  log(`canvas ${picture1.width}x${picture1.height}, ${picture1.colours}+ colours, luma range ` +
      `${picture1.lumaRange.toFixed(0)}`);
  const state1 = await pageState(page);
  check(state1.sessionState === 'running', `rfbsimState.sessionState is ${state1.sessionState}, expected running`);
  watchChildren();
  await page.screenshot({ path: artifact('manager_session.png') });

  // ---- b. Holding W walks: the picture changes. ----
  await sleep(500);   // the rest of the first frames
  await snapshot(page, 'A');
  await driver.click(page, '#screen canvas');
  await driver.waitHidden(page, '#hint', 5000);
  log(`holding W for ${HOLD_W_MS} ms`);
  await page.keyboard.down('w');
  await sleep(HOLD_W_MS);
  await page.keyboard.up('w');
  await poll('the picture to change after walking', 10_000, 250, async () => {
    await snapshot(page, 'B');
    return (await changedFraction(page, 'A', 'B', PIXEL_CHANGE_THRESHOLD)) >= MIN_CHANGED_FRACTION;
  });
  const walked = await changedFraction(page, 'A', 'B', PIXEL_CHANGE_THRESHOLD);
  log(`canvas pixels changed after the walk: ${(100 * walked).toFixed(1)} % (need >= ` +
      `${(100 * MIN_CHANGED_FRACTION).toFixed(1)} %)`);
  await logStream('e2e-1', 'after the walk');

  // ---- c. A reload comes back to the same session; the same link does too. ----
  await page.reload({ waitUntil: 'load', timeout: 20_000 });
  check(page.url() === `${new URL(base).origin}/s/${token1}/`, `after the reload the page is at ${page.url()}`);
  // As in openPage: app.js may still be evaluating when 'load' fires.
  await poll('app.js to start again after the reload', 10_000, 100, () => pageState(page));
  await waitForConnection(page);
  await waitForFirstFrame(page, 'e2e-1 after the reload');
  await waitForPicture(page, 'C');
  log('reloaded: same session page, connected again, picture shown');
  const sessionsAfterReload = await listSessions();
  const live1 = sessionsAfterReload.live.filter((s) => s.uid === 'e2e-1');
  check(sessionsAfterReload.live.length === 1 && live1.length === 1 && live1[0].token === token1 &&
        live1[0].state === 'running',
        `expected exactly one live session (e2e-1, running): ${JSON.stringify(sessionsAfterReload.live)}`);
  const again = await request(`start?uid=e2e-1&scenario=${SCENARIO}`);
  check(again.status === 302 && again.headers.get('location') === `/s/${token1}/`,
        `the link again answered HTTP ${again.status} to ${again.headers.get('location')}, expected /s/${token1}/`);
  log(`/api/sessions lists one live session for e2e-1 (id ${live1[0].id}); the link leads back to it`);

  // ---- d. A survey on an allowed origin embeds a session; one on another origin cannot. ----
  fs.writeFileSync(slowFlag, '');   // this session starts SLOW_START_S late: the progress must show
  const surveyPageTab = await browser.newPage();
  const surveyLog = recordPage(surveyPageTab, artifact('manager-survey-console.log'));
  await surveyPageTab.goto(`${survey.origin}/survey?uid=e2e-2`, { waitUntil: 'load', timeout: 20_000 });
  const frame = await poll('the survey iframe to reach the session page', 10_000, 100, () => {
    const child = surveyPageTab.frames().find((f) => f !== surveyPageTab.mainFrame());
    return child && TOKEN_PATH.test(new URL(child.url()).pathname) ? child : null;
  });
  const token2 = tokenOf(frame.url(), 'the survey iframe');
  check(token2 !== token1, 'the second participant got the first one\'s session');
  const firstFrame2 = await waitForFirstFrame(frame, 'e2e-2 in the survey iframe');
  fs.rmSync(slowFlag, { force: true });
  await waitForPicture(frame, 'F');
  const seen2 = await statusSeen(frame);
  log(`iframe: first picture ${firstFrame2.toFixed(0)} ms after its navigation (start delayed by ` +
      `${SLOW_START_S} s); progress line showed: ${describeSeen(seen2)}`);
  check(seen2.some((s) => /^Starting your simulation\u2026 \d+ s$/.test(s.text)),
        'the iframe never showed "Starting your simulation… N s" while its session started');
  check(seen2.some((s) => s.text === 'Loading the picture\u2026'),
        'the iframe never showed "Loading the picture…"');
  const surveyFocus = await surveyPageTab.evaluate(() => document.activeElement && document.activeElement.id);
  check(surveyFocus === 'answer', `the session page took the focus from the survey (survey focus: ${surveyFocus})`);
  log('the survey\'s field kept the keyboard focus');
  watchChildren();
  await surveyPageTab.screenshot({ path: artifact('manager_iframe.png') });

  const strangerTab = await browser.newPage();
  const strangerLog = recordPage(strangerTab, artifact('manager-stranger-console.log'));
  const strangerSockets = driver.watchWebSockets(strangerTab);
  await strangerTab.goto(`${stranger.origin}/survey?uid=e2e-2`, { waitUntil: 'load', timeout: 20_000 });
  const blocked = await poll('the browser to refuse the frame on the other origin', BLOCKED_FRAME_TIMEOUT_MS, 100,
                             () => {
    const child = strangerTab.frames().find((f) => f !== strangerTab.mainFrame());
    return child && driver.isRefusedFrame(child) ? child : null;
  });
  await sleep(500);
  let blockedState = 'absent';
  try {
    blockedState = await blocked.evaluate(() => typeof window.rfbsimState);
  } catch (err) {
    blockedState = `not readable (${err.message.split('\n')[0]})`;
  }
  check(blockedState !== 'object', 'the session page runs inside a frame on an origin that is not allowed');
  check(strangerSockets.length === 0, 'the refused frame opened a WebSocket');
  const refusals = strangerLog.cspReports.filter((text) => /frame-ancestors/.test(text));
  log(`frame on ${stranger.origin} refused: url ${blocked.url()}, rfbsimState ${blockedState}, ` +
      `console: ${refusals[0] ? refusals[0].slice(0, 160) : '(no CSP message)'}`);
  await strangerTab.screenshot({ path: artifact('manager_iframe_refused.png') });
  const liveAfterFrames = (await listSessions()).live;
  check(liveAfterFrames.length === 2,
        `expected 2 live sessions (e2e-1, e2e-2): ${JSON.stringify(liveAfterFrames)}`);

  // ---- e. The researcher ends e2e-1 through the API: the page says so, without Reconnect. ----
  const id1 = live1[0].id;
  const withoutHeader = await request(`api/sessions/${id1}/end`, { method: 'POST', admin: true });
  check(withoutHeader.status === 403, `POST .../end without X-Rfbsim-Admin answered HTTP ${withoutHeader.status}`);
  const ended = await request(`api/sessions/${id1}/end`, { method: 'POST', admin: true,
                                                          headers: { 'X-Rfbsim-Admin': '1' } });
  check(ended.status === 200, `POST /api/sessions/${id1}/end answered HTTP ${ended.status}`);
  await driver.waitVisible(page, '#disconnected', 10_000);
  const panelTitle = (await driver.innerText(page, '#disconnected-title')).trim();
  const panelText = (await driver.innerText(page, '#disconnected')).replace(/\s+/g, ' ').trim();
  const endedState = await pageState(page);
  const { code: endCode, reason: endReason } = endedState.lastDisconnect;
  log(`ended page: "${panelText}" (close ${endCode} "${endReason}", session state ${endedState.sessionState})`);
  check(panelTitle === 'Session ended', `the panel's title is "${panelTitle}", expected "Session ended"`);
  check(/researcher/i.test(panelText), 'the panel does not say that the researcher ended the session');
  check(await driver.isHidden(page, '#reconnect'), 'a Reconnect button shows for a session that is over');
  check(endedState.lastDisconnect.final === true && endedState.lastDisconnect.code === 1001 &&
        endedState.lastDisconnect.reason === 'session ended by the researcher',
        `rfbsimState.lastDisconnect: ${JSON.stringify(endedState.lastDisconnect)}`);
  await page.screenshot({ path: artifact('manager_ended.png') });
  const gone = await request(`s/${token1}/`);
  check(gone.status === 410, `the ended session's page answered HTTP ${gone.status}, expected 410`);

  // ---- f. The admin page (HTTP Basic) lists e2e-2 live and e2e-1 ended, and ends e2e-2. ----
  const adminTab = await browser.newPage();
  const adminLog = recordPage(adminTab, artifact('manager-admin-console.log'));
  const adminResponse = await adminTab.goto(new URL('admin', base).href, { waitUntil: 'load', timeout: 20_000 });
  check(adminResponse && adminResponse.status() === 200, `GET /admin answered HTTP ${adminResponse?.status()}`);
  // Rows by session id (admin.js puts it in data-id); their text must then name the participant.
  const id2 = liveAfterFrames.find((s) => s.uid === 'e2e-2').id;
  const row2 = `#live tbody tr[data-id="${id2}"]`;
  await driver.waitVisible(adminTab, row2, 10_000);
  const row1 = `#recent tbody tr[data-id="${id1}"]`;
  await driver.waitVisible(adminTab, row1, 10_000);
  const row2Text = (await driver.innerText(adminTab, row2)).replace(/\s+/g, ' ').trim();
  const row1Text = (await driver.innerText(adminTab, row1)).replace(/\s+/g, ' ').trim();
  log(`admin page: live "${row2Text}"; recent "${row1Text}"`);
  check(/\be2e-2\b/.test(row2Text) && /\brunning\b/.test(row2Text), 'the admin page does not show e2e-2 as running');
  check(/\be2e-1\b/.test(row1Text) && /\bended\b/.test(row1Text), 'the admin page does not show e2e-1 as ended');
  check(await driver.count(adminTab, '#live tbody tr') === 1, 'the admin page lists more than one live session');
  const watchLink = `${row2} a[aria-label^="Watch"]`;
  const watchHref = await driver.attribute(adminTab, watchLink, 'href');
  check(watchHref === `/admin/watch/${token2}/`,
        `the Watch link goes to ${watchHref}, expected /admin/watch/${token2}/`);
  const watchText = (await driver.innerText(adminTab, watchLink)).trim();
  check(watchText === 'Watch (view only)', `the Watch link says "${watchText}", expected "Watch (view only)"`);
  await adminTab.screenshot({ path: artifact('manager_admin.png'), fullPage: true });

  // The researcher watches e2e-2: the participant's page under /admin/watch/ (behind the admin credentials, which
  // the browser also sends on the WebSocket handshake), showing the picture and the session's state.
  const watchTab = await browser.newPage();
  recordPage(watchTab, artifact('manager-watch-console.log'));
  const watchSocketEntries = driver.watchWebSockets(watchTab);
  const watchResponse = await watchTab.goto(new URL(watchHref, base).href, { waitUntil: 'load', timeout: 20_000 });
  check(watchResponse && watchResponse.status() === 200, `GET ${watchHref} answered HTTP ${watchResponse?.status()}`);
  const watchFirstFrameAt = await waitForFirstFrame(watchTab, 'the watch page of e2e-2');
  const watchSockets = watchSocketEntries.map((entry) => entry.url);
  check(watchSockets.length === 1 && new URL(watchSockets[0]).pathname === `/admin/watch/${token2}/ws`,
        `the watch page's WebSockets went to ${JSON.stringify(watchSockets)}, expected /admin/watch/${token2}/ws`);
  await poll('the watch page to learn the session state', 5000, 100,
             async () => (await pageState(watchTab)).sessionState === 'running');
  // The watch page knows it only watches: no invitation to walk, a read-only view.
  const watchView = await watchTab.evaluate(() => ({
    watching: window.rfbsimState.watching,
    hintHidden: document.getElementById('hint').hidden,
  }));
  check(watchView.watching === true && watchView.hintHidden === true,
        `the watch page should be view only with no walking hint, got ${JSON.stringify(watchView)}`);
  const metricsText = await (await request('metrics')).text();
  check(/^rfbsim_relay_connections\{kind="watch"\} 1$/m.test(metricsText),
        'rfbsim_relay_connections{kind="watch"} is not 1 while the watch page is open');
  log(`watch page of e2e-2: first picture ${Math.round(watchFirstFrameAt)} ms after its navigation started`);
  await watchTab.screenshot({ path: artifact('manager_watch.png') });
  await watchTab.close();

  // End from the page: confirm, then e2e-2 moves to the recent table and its iframe says the session ended.
  let confirmText = '';
  adminTab.once('dialog', (dialog) => {
    confirmText = dialog.message();
    dialog.accept();
  });
  await driver.click(adminTab, `${row2} button[aria-label^="End session"]`);
  await driver.waitVisible(adminTab, `#recent tbody tr[data-id="${id2}"]`, 10_000);
  await driver.waitVisible(adminTab, '#live-empty', 5000);
  check(confirmText.includes('e2e-2'), `the End confirmation did not name the participant: "${confirmText}"`);
  await driver.waitVisible(frame, '#disconnected', 10_000);
  check(await driver.isHidden(frame, '#reconnect'), 'the iframe offers Reconnect after the researcher ended it');
  log(`ended e2e-2 from the admin page (confirm: "${confirmText}"); its iframe says "` +
      `${(await driver.innerText(frame, '#disconnected')).replace(/\s+/g, ' ').trim()}"`);

  // The page explains a 401 (credentials dropped, token changed).
  const answerAgain = await driver.answerInstead(adminTab, '/api/sessions', { status: 401, contentType: 'text/html',
                                                                              body: '<h1>401</h1>' });
  await poll('the admin page to explain HTTP 401', 10_000, 200, async () =>
    /Not authorised/.test(await driver.innerText(adminTab, '#message')));
  log(`admin page on 401: "${(await driver.innerText(adminTab, '#message')).trim()}"`);
  await answerAgain();

  // ---- Finally: SIGTERM stops sim_manager cleanly with a session still running, and no process is left. ----
  const link3 = await request(`start?uid=e2e-3&scenario=${SCENARIO}`);
  check(link3.status === 302, `the link for e2e-3 answered HTTP ${link3.status}`);
  const token3 = tokenOf(new URL(link3.headers.get('location'), base).href, 'the link for e2e-3');
  await poll('session e2e-3 to run', 20_000, 100, async () => {
    const response = await request(`s/${token3}/status`);
    return response.status === 200 && (await response.json()).state === 'running';
  });
  watchChildren();
  log(`session processes seen: ${[...sessionProcs.values()].map((p) => `${p.pid} (${p.comm})`).join(', ')}`);
  check(sessionProcs.size === 3, `expected 3 session processes, saw ${sessionProcs.size}`);
  check(sessionProcs.size === 3 && [...sessionProcs.values()].filter(stillThere).length === 1,
        'expected only e2e-3\'s session process to be running before SIGTERM');
  const pageErrors = [...pageLog.pageErrors, ...surveyLog.pageErrors, ...strangerLog.pageErrors,
                      ...adminLog.pageErrors];
  check(pageErrors.length === 0, `uncaught errors in the pages: ${pageErrors.join(' | ')}`);
  await stopSimCleanly(manager);
  const left = [...sessionProcs.values()].filter(stillThere);
  check(left.length === 0, `session processes outlived sim_manager: ${left.map((p) => p.pid).join(', ')}`);
  log('sim_manager exited 0 and left no session process');
  await Promise.all([pageLog.close(), surveyLog.close(), strangerLog.close(), adminLog.close()]);
}

await runTest(`${env.browser === 'chromium' ? 'browser' : env.browser}_e2e_manager`, 150, main);
