// SPDX-License-Identifier: GPL-2.0-or-later
// Browser end-to-end test of the study's video condition (issue 33) through web/survey-demo.html: participant A
// walks in the lab (holds W in a real page) and the researcher ends A's session through the admin API; watcher B,
// framed by the demo survey with ?condition=video&t1=..., is shown A's recording view-only: the picture moves with
// no key pressed, the keyboard hint stays hidden, /api/sessions names B's condition and source (A's id), and the
// survey hears started, watched with B's own code, then ended, once each. Watcher C, arriving while A's one place
// is taken, is told "No recording to watch right now": the survey hears unavailable then ended (outcome
// unavailable), and C's link fetched directly answers 503. Runs in Chromium, or in Firefox ESR with
// --browser firefox.
//
// Usage: node e2e_video_condition.mjs [--browser chromium|firefox] SIM_MANAGER SIM_RFB WEB_ROOT ARTIFACTS_DIR
//                                     [WEB_DIR]
//   SIM_MANAGER    the sim_manager executable to start
//   SIM_RFB        the sim_rfb executable it starts per session (and, with --replay, per watcher)
//   WEB_ROOT       the assembled web root (build/web/root) sim_manager serves
//   ARTIFACTS_DIR  where screenshots (video_*.png; firefox_video_*.png in Firefox), sim_manager's output, its data
//                  folder (video-data; firefox-video-data) and the browser console are written (created)
//   WEB_DIR        the source web/ folder: survey-demo.html, and node_modules with playwright-core and
//                  puppeteer-core (default: ../../web from here)
// Environment: RFBSIM_CHROMIUM (default /usr/bin/chromium), RFBSIM_FIREFOX (default /usr/bin/firefox-esr),
// RFBSIM_E2E_TIMEOUT_S (default 150).
// Exits 0 when every check passed, 1 on the first failed check, 2 on the overall timeout.

import fs from 'node:fs';
import path from 'node:path';

import { loadDriver } from './browser_driver.mjs';
import {
  PIXEL_CHANGE_THRESHOLD, changedFraction, check, log, openPage, pageState, parseManagerArgs, poll, recordPage,
  runTest, serveHtmlPage, sleep, snapshot, startSim, stopSimCleanly, thumbnail, waitForConnection, waitForPicture,
} from './e2e_support.mjs';
import { demoState, describeMessages as describe, rawMessages, recordAllMessages } from './survey_messages.mjs';

// ---------------------------------------------------------------------------------------------------------------
// Settings.
// ---------------------------------------------------------------------------------------------------------------
const ADMIN_TOKEN = 'e2e-video-admin-token-0123';
const SCENARIO = 'lab';
const UID_A = 'e2e-video-a';            // walks
const UID_B = 'e2e-video-b';            // watches A's recording
const UID_C = 'e2e-video-c';            // arrives when no recording is free
const VIDEO_CODE = 'VIDEO-CODE';        // B's t1: the code for having watched the whole recording
const HOLD_W_MS = 3000;                 // how long A holds W, wall time
const STAND_MS = 500;                   // A stands this long after the walk before the picture is kept
const THUMB = { cols: 32, rows: 18 };   // thumbnails compared between pages (mean luma per cell)
const END_GRACE_S = 3;                  // every session's end grace (sim_rfb --end-grace; 15 s with a code)
const MIN_CHANGED_FRACTION = 0.01;      // share of canvas pixels that must change for "the picture moved"
const MOTION_WINDOW_MS = 10_000;        // B's picture must move within this, with no key pressed
const FIRST_PICTURE_TIMEOUT_MS = 30_000;
const WATCHED_TIMEOUT_MS = 40_000;      // A's recording is ~8 s long; it plays from B's first connection
const ENDED_TIMEOUT_MS = (END_GRACE_S + 15) * 1000;
const AFTER_END_MS = 1500;              // how long the survey must hear nothing more after 'ended'
const VIEWPORT = { width: 1100, height: 900 };
const TOKEN_PATH = /^\/s\/([0-9a-f]{32})\/$/;

const env = parseManagerArgs('e2e_video_condition.mjs');
let driver = null;   // browser_driver.mjs's, for env.browser (main loads it)
// The Chromium test's files keep their names; the Firefox run's beside them get a firefox_ (firefox-) prefix.
const PREFIX = env.browser === 'chromium' ? '' : `${env.browser}_`;
const artifact = (name) => path.join(env.artifacts, `${PREFIX}${name}`);
const artifactDir = (name) => path.join(env.artifacts, `${PREFIX.replace('_', '-')}${name}`);

// ---------------------------------------------------------------------------------------------------------------
// Helpers: the manager's admin API, the demo survey's state.
// ---------------------------------------------------------------------------------------------------------------
let base = '';   // http://127.0.0.1:PORT/ of sim_manager

// A request to sim_manager (redirects are not followed); admin: with the Bearer token and the header sim_manager
// asks of an admin POST (X-Rfbsim-Admin, which a cross-site form cannot send).
function request(pathname, { method = 'GET', admin = false } = {}) {
  const headers = admin ? { Authorization: `Bearer ${ADMIN_TOKEN}`, 'X-Rfbsim-Admin': '1' } : {};
  return fetch(new URL(pathname, base), { method, headers, redirect: 'manual', signal: AbortSignal.timeout(5000) });
}

// Every session /api/sessions lists, live and recent.
async function listSessions() {
  const response = await request('api/sessions', { admin: true });
  check(response.status === 200, `GET /api/sessions with the token answered HTTP ${response.status}`);
  const body = await response.json();
  return [...body.live, ...body.recent];
}

// uid's one session in /api/sessions (fails if there are several), or null.
async function sessionOf(uid) {
  const rows = (await listSessions()).filter((s) => s.uid === uid);
  check(rows.length <= 1, `/api/sessions lists ${rows.length} sessions for ${uid}: ${JSON.stringify(rows)}`);
  return rows[0] || null;
}


// Waits until the demo accepted `event` on its session page; returns that page's messages.
function waitForEvent(page, event, timeoutMs) {
  return poll(`the survey to receive '${event}'`, timeoutMs, 200, async () => {
    const messages = (await demoState(page)).messages.filter((m) => m.page === 'session');
    return messages.some((m) => m.event === event) ? messages : null;
  });
}

// Mean absolute difference (0..255) between two thumbnails of the same size.
function thumbDistance(a, b) {
  check(a && b && a.length === b.length, 'thumbnails of different sizes');
  return a.reduce((sum, value, i) => sum + Math.abs(value - b[i]), 0) / a.length;
}

// The frame inside the demo's session iframe once its URL matches `accept`.
function sessionIframe(page, what, accept) {
  return poll(`the session iframe to reach ${what}`, 15_000, 100, async () => {
    const element = await page.$('#frame-session');
    const frame = element && await element.contentFrame();
    return frame && accept(new URL(frame.url())) ? frame : null;
  });
}

// The demo survey for one participant, opened and moved on from its intro page.
async function openDemo(page, surveyOrigin, query) {
  const url = `${surveyOrigin}/survey-demo.html?${new URLSearchParams({ manager: base, scenario: SCENARIO,
                                                                        condition: 'video', ...query })}`;
  log(`opening ${url}`);
  const response = await page.goto(url, { waitUntil: 'load', timeout: 20_000 });
  check(response && response.ok(), `GET survey-demo.html answered HTTP ${response && response.status()}`);
  const intro = await demoState(page);
  check(intro && intro.page === 'intro' && intro.uid === query.uid && intro.condition === 'video',
        `window.surveyDemo on the intro page: ${JSON.stringify(intro)}`);
}

// ---------------------------------------------------------------------------------------------------------------
// The test.
// ---------------------------------------------------------------------------------------------------------------
async function main() {
  driver = loadDriver(env);
  const demoFile = path.join(env.webDir, 'survey-demo.html');
  check(fs.existsSync(demoFile), `no survey-demo.html in ${env.webDir}`);
  check(fs.existsSync(env.simRfbPath), `sim_rfb not found at ${env.simRfbPath}`);
  const dataDir = artifactDir('video-data');
  fs.rmSync(dataDir, { recursive: true, force: true });

  // 1. The demo survey on its own origin; sim_manager with the lab, small pictures (two cores are shared with the
  //    browser) and a short end grace for every session, watchers' included.
  const { origin: surveyOrigin } = await serveHtmlPage('survey server', '/survey-demo.html',
                                                       () => fs.readFileSync(demoFile));
  const manager = await startSim(env, `${PREFIX}sim_manager`, [
    '--port', '0', '--data-dir', dataDir, '--scenarios', SCENARIO, '--admin-token', ADMIN_TOKEN,
    '--frame-origins', surveyOrigin, '--session-command', env.simRfbPath, '--web-root', env.webRoot,
    '--session-arg', '--end-grace', '--session-arg', String(END_GRACE_S),
    '--session-arg', '--width', '--session-arg', '640', '--session-arg', '--height', '--session-arg', '360',
  ]);
  base = manager.url;
  const managerOrigin = new URL(base).origin;

  const browser = await driver.launch(VIEWPORT);
  const pageA = await browser.firstPage();
  const logA = recordPage(pageA, artifact('video-a-console.log'));
  log(`browser: ${await pageA.evaluate(() => navigator.userAgent)}`);

  // ---- 2. A walks: the link's picture, a click for the keyboard, W held down; then the researcher ends A. ----
  await openPage(pageA, new URL(`start?uid=${UID_A}&scenario=${SCENARIO}`, base).href);
  check(TOKEN_PATH.test(new URL(pageA.url()).pathname), `A's link led to ${pageA.url()}, not /s/<token>/`);
  await waitForConnection(pageA);
  await waitForPicture(pageA, 'A0');
  await snapshot(pageA, 'A0');
  await driver.click(pageA, '#screen canvas');
  await driver.waitHidden(pageA, '#hint', 5000);
  log(`A holds W for ${HOLD_W_MS} ms`);
  await pageA.keyboard.down('w');
  await sleep(HOLD_W_MS);
  await pageA.keyboard.up('w');
  await sleep(STAND_MS);
  await snapshot(pageA, 'A1');
  const walked = await changedFraction(pageA, 'A0', 'A1', PIXEL_CHANGE_THRESHOLD);
  log(`A's canvas changed by ${(100 * walked).toFixed(1)} % over the walk`);
  check(walked >= MIN_CHANGED_FRACTION, `A's picture did not change while W was held (${walked})`);
  await pageA.screenshot({ path: artifact('video_a_walked.png') });
  // A's first and last pictures, to tell which one B's picture shows.
  const thumbA0 = await thumbnail(pageA, 'A0', THUMB.cols, THUMB.rows);
  const thumbA1 = await thumbnail(pageA, 'A1', THUMB.cols, THUMB.rows);

  const rowA = await sessionOf(UID_A);
  check(rowA && rowA.state === 'running' && rowA.condition === 'interactive',
        `A's row in /api/sessions: ${JSON.stringify(rowA)}`);
  const ended = await request(`api/sessions/${rowA.id}/end`, { method: 'POST', admin: true });
  check(ended.status === 200, `POST /api/sessions/${rowA.id}/end answered HTTP ${ended.status}`);
  await poll(`A's session (id ${rowA.id}) to end`, 20_000, 250, async () => {
    const row = await sessionOf(UID_A);
    return row && row.state === 'ended' ? row : null;
  });
  log(`A (session ${rowA.id}) ended by the researcher`);
  await pageA.goto('about:blank');

  // ---- 3. Watcher B through the demo survey: the tutorial is skipped, the link carries condition=video. ----
  const pageB = await browser.newPage();
  await driver.addInitScript(pageB, recordAllMessages);
  const logB = recordPage(pageB, artifact('video-b-console.log'));
  await openDemo(pageB, surveyOrigin, { uid: UID_B, t1: VIDEO_CODE });
  await pageB.screenshot({ path: artifact('video_b_intro.png') });
  await driver.click(pageB, '#next-intro');
  const onSession = await demoState(pageB);
  check(onSession.page === 'session', `a watcher's intro led to the ${onSession.page} page, not the session`);
  const srcB = new URL(await driver.attribute(pageB, '#frame-session', 'src'));
  check(srcB.pathname === '/start' && srcB.searchParams.get('condition') === 'video' &&
        srcB.searchParams.get('uid') === UID_B && srcB.searchParams.get('t1') === VIDEO_CODE,
        `B's iframe opened ${srcB.href}`);
  // /start answered 302: the iframe reached the session page.
  const frameB = await sessionIframe(pageB, 'a session page', (url) => TOKEN_PATH.test(url.pathname));
  const tokenB = TOKEN_PATH.exec(new URL(frameB.url()).pathname)[1];
  log(`B's iframe at ${frameB.url()}`);
  await poll('the first picture in B\'s iframe', FIRST_PICTURE_TIMEOUT_MS, 100, async () => {
    const state = await pageState(frameB);
    check(!state || !state.lastDisconnect, `B's page reports a disconnect: ${state?.lastDisconnect?.message}`);
    return state && state.firstFrameAt !== null;
  });
  await waitForPicture(frameB, 'B0');

  // B's picture moves with no key pressed (the recording plays), and the hint never invites B to the keyboard.
  const motionStart = Date.now();
  const moved = await poll(`B's picture to change within ${MOTION_WINDOW_MS} ms`, MOTION_WINDOW_MS, 300, async () => {
    await snapshot(frameB, 'B1');
    const fraction = await changedFraction(frameB, 'B0', 'B1', PIXEL_CHANGE_THRESHOLD);
    return fraction >= MIN_CHANGED_FRACTION ? fraction : null;
  });
  log(`B's canvas changed by ${(100 * moved).toFixed(1)} % after ${Date.now() - motionStart} ms, no key pressed`);
  await pageB.screenshot({ path: artifact('video_b_playing.png') });
  const stateB = await pageState(frameB);
  check(stateB.watcher === true, `B's page does not know it is a watcher: ${JSON.stringify(stateB.watcher)}`);
  check(await driver.isHidden(frameB, '#hint'), 'the keyboard hint shows on a watcher\'s page');
  const statusB = await (await request(`s/${tokenB}/status`)).json();
  check(statusB.condition === 'video', `B's status has condition ${statusB.condition}`);

  // The researcher's list: B watches A.
  const rowB = await sessionOf(UID_B);
  check(rowB && rowB.condition === 'video' && rowB.yoked_to === rowA.id && rowB.token === tokenB,
        `B's row in /api/sessions: ${JSON.stringify(rowB)}; expected condition video, yoked_to ${rowA.id}`);
  const rowAWatched = await sessionOf(UID_A);
  check(rowAWatched.watchers === 1 && rowAWatched.condition === 'interactive',
        `A's row once B watches: ${JSON.stringify(rowAWatched)}`);
  log(`/api/sessions: B (session ${rowB.id}) condition video, yoked_to ${rowB.yoked_to}; A has 1 watcher`);

  // ---- 4. Watcher C while B holds A's one place: no recording free. ----
  const pageC = await browser.newPage();
  await driver.addInitScript(pageC, recordAllMessages);
  const logC = recordPage(pageC, artifact('video-c-console.log'));
  await openDemo(pageC, surveyOrigin, { uid: UID_C });
  await driver.click(pageC, '#next-intro');
  const frameC = await sessionIframe(pageC, '/start', (url) => url.pathname === '/start');
  const messagesC = await waitForEvent(pageC, 'ended', 15_000);
  await sleep(AFTER_END_MS);
  const finalC = (await demoState(pageC)).messages;
  log(`C's survey heard: ${describe(finalC)}`);
  check(finalC.length === 2 && finalC[0].event === 'unavailable' && finalC[1].event === 'ended' &&
        finalC.every((m) => m.page === 'session' && m.uid === UID_C && m.code === null &&
                            m.outcome === 'unavailable') && messagesC.length <= 2,
        `expected unavailable, ended (outcome unavailable, code null) for ${UID_C}: ${JSON.stringify(finalC)}`);
  const textC = await driver.innerText(frameC, 'body');
  check(textC.includes('No recording to watch right now'), `C's iframe shows "${textC.replace(/\s+/g, ' ')}"`);
  check(await driver.isEnabled(pageC, '#next-session'), 'Next stays disabled for C after "unavailable"');
  const progressC = await driver.innerText(pageC, '#progress-session');
  check(/no recording is free/i.test(progressC), `C's survey says "${progressC}"`);
  const doneC = await demoState(pageC);
  check(JSON.stringify(doneC.codes) === JSON.stringify({ session: { outcome: 'unavailable', code: null } }),
        `C's window.surveyDemo.codes: ${JSON.stringify(doneC.codes)}`);
  await pageC.screenshot({ path: artifact('video_c_unavailable.png') });
  const direct = await request(`start?uid=${UID_C}&scenario=${SCENARIO}&condition=video`);
  check(direct.status === 503, `C's link fetched directly answered HTTP ${direct.status}, expected 503`);
  check(await sessionOf(UID_C) === null, 'C has a session although no recording was free');
  log('C: unavailable then ended in the survey, the 503 page in the iframe, 503 for the link itself');

  // ---- 5. B's recording plays to its end: watched with B's code, then ended, once each. ----
  await waitForEvent(pageB, 'watched', WATCHED_TIMEOUT_MS);
  // B's last picture is A's end (where A stood after the walk), not its start: B was shown A's session.
  await snapshot(frameB, 'B2');
  const thumbB0 = await thumbnail(frameB, 'B0', THUMB.cols, THUMB.rows);
  const thumbB2 = await thumbnail(frameB, 'B2', THUMB.cols, THUMB.rows);
  const distances = { startToStart: thumbDistance(thumbB0, thumbA0), endToEnd: thumbDistance(thumbB2, thumbA1),
                      endToStart: thumbDistance(thumbB2, thumbA0), walk: thumbDistance(thumbA0, thumbA1) };
  log(`thumbnail distances (mean luma difference): B's first to A's first ${distances.startToStart.toFixed(1)}, ` +
      `B's last to A's last ${distances.endToEnd.toFixed(1)}, B's last to A's first ` +
      `${distances.endToStart.toFixed(1)}; A's walk ${distances.walk.toFixed(1)}`);
  check(distances.startToStart < distances.walk / 4,
        `B's first picture is not A's first one: ${JSON.stringify(distances)}`);
  check(distances.endToEnd < distances.endToStart / 2,
        `B's last picture is not A's last one: ${JSON.stringify(distances)}`);
  check(await driver.isEnabled(pageB, '#next-session'), 'Next stays disabled for B after "watched"');
  const progressB = await driver.innerText(pageB, '#progress-session');
  check(progressB.includes('You watched the whole recording') && progressB.includes(VIDEO_CODE),
        `B's survey says "${progressB}"`);
  await pageB.screenshot({ path: artifact('video_b_watched.png') });
  await waitForEvent(pageB, 'ended', ENDED_TIMEOUT_MS);
  await sleep(AFTER_END_MS);
  const messagesB = (await demoState(pageB)).messages;
  log(`B's survey heard: ${describe(messagesB)}`);
  const eventsB = messagesB.map((m) => m.event).join();
  const codeOf = (event) => messagesB.find((m) => m.event === event).code;
  check(eventsB === 'started,watched,ended' && codeOf('started') === null && codeOf('watched') === VIDEO_CODE &&
        codeOf('ended') === VIDEO_CODE && messagesB.every((m) => m.uid === UID_B && m.page === 'session'),
        `expected started, watched(${VIDEO_CODE}), ended(${VIDEO_CODE}) for ${UID_B}: ${JSON.stringify(messagesB)}`);
  check(messagesB[1].outcome === 'watched' && messagesB[2].outcome === 'watched',
        `B's outcome in the messages: ${JSON.stringify(messagesB)}`);
  // Every message the survey page got came from sim_manager's frame and was accepted by the demo.
  const rawB = await rawMessages(pageB);
  check(rawB.length === messagesB.length && rawB.every((m) => m.origin === managerOrigin),
        `messages seen by B's survey: ${JSON.stringify(rawB)}`);
  const rawC = await rawMessages(pageC);
  check(rawC.length === finalC.length && rawC.every((m) => m.origin === managerOrigin),
        `messages seen by C's survey: ${JSON.stringify(rawC)}`);

  // The thank-you page lists the watcher's code; the index records B's outcome.
  await driver.click(pageB, '#next-session');
  const doneB = await demoState(pageB);
  check(doneB.page === 'done' &&
        JSON.stringify(doneB.codes) === JSON.stringify({ session: { outcome: 'watched', code: VIDEO_CODE } }),
        `B's window.surveyDemo at the end: ${JSON.stringify(doneB)}`);
  const listed = await driver.innerText(pageB, '#codes-list');
  check(listed.includes(VIDEO_CODE) && listed.includes('recording watched'),
        `B's thank-you page lists "${listed.replace(/\s+/g, ' ')}"`);
  await pageB.screenshot({ path: artifact('video_b_done.png') });
  const finalB = await poll('B\'s row to record the outcome watched', 10_000, 250, async () => {
    const row = await sessionOf(UID_B);
    return row && row.outcome === 'watched' ? row : null;
  });
  log(`B's row: state ${finalB.state}, outcome ${finalB.outcome}`);

  const pageErrors = [...logA.pageErrors, ...logB.pageErrors, ...logC.pageErrors];
  check(pageErrors.length === 0, `uncaught errors in the pages: ${pageErrors.join(' | ')}`);
  await stopSimCleanly(manager);
  await Promise.all([logA.close(), logB.close(), logC.close()]);
}

await runTest(`${env.browser === 'chromium' ? 'browser' : env.browser}_e2e_video_condition`, 150, main);
