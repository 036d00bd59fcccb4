// SPDX-License-Identifier: GPL-2.0-or-later
// Browser end-to-end test of survey embedding: web/survey-demo.html, served from its own origin, walks a
// participant through a tutorial (which runs out of time) and a session (whose task is done at once) in iframes
// of sim_manager's page, and must hear exactly the simulator's postMessages: started, timeout with the t2 code,
// then started, completed with the t1 code, ended. The same demo on an origin sim_manager does not list hears
// nothing; the session folders record the uid, the outcome and the code. Runs in Chromium, or in Firefox ESR with
// --browser firefox.
//
// Usage: node e2e_survey.mjs [--browser chromium|firefox] SIM_MANAGER SIM_RFB WEB_ROOT ARTIFACTS_DIR [WEB_DIR]
//   SIM_MANAGER    the sim_manager executable to start
//   SIM_RFB        the sim_rfb executable it starts per session
//   WEB_ROOT       the assembled web root (build/web/root) sim_manager serves
//   ARTIFACTS_DIR  where screenshots (survey_*.png; firefox_survey_*.png in Firefox), sim_manager's output, its
//                  data folder (survey-data; firefox-survey-data) and the browser console are written (created)
//   WEB_DIR        the source web/ folder: survey-demo.html, and node_modules with playwright-core and
//                  puppeteer-core (default: ../../web from here)
// Environment: RFBSIM_CHROMIUM (default /usr/bin/chromium), RFBSIM_FIREFOX (default /usr/bin/firefox-esr),
// RFBSIM_E2E_TIMEOUT_S (default 150).
// Exits 0 when every check passed, 1 on the first failed check, 2 on the overall timeout.

import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

import { loadDriver } from './browser_driver.mjs';
import {
  check, log, pageState, parseManagerArgs, poll, recordPage, runTest, serveHtmlPage, sleep, startSim,
  stopSimCleanly,
} from './e2e_support.mjs';
import { demoState, describeMessages as describe, rawMessages, recordAllMessages } from './survey_messages.mjs';

// ---------------------------------------------------------------------------------------------------------------
// Settings.
// ---------------------------------------------------------------------------------------------------------------
const here = path.dirname(fileURLToPath(import.meta.url));
const QUICK_SCENARIO = path.join(here, 'scenarios', 'quick_reach.yaml');   // done on the first tick with a viewer
const ADMIN_TOKEN = 'e2e-survey-admin-token-0123';
const TIME_LIMIT_S = 6;                 // every session's task time limit (sim_rfb --time-limit)
const UID = 'e2e-p1';                   // the participant; the demo's tutorial runs as e2e-p1-tutorial
const STRANGER_UID = 'e2e-p2';
const CODE_SUCCESS = 'E2E-DONE';        // the session's t1 and t2, given to the demo as ?t1= and ?t2=
const CODE_TIMEOUT = 'E2E-LATE';
const TUTORIAL_CODE_TIMEOUT = 'TUTORIAL-TIMEOUT';   // survey-demo.html's own t2 for its tutorial
const FIRST_PICTURE_TIMEOUT_MS = 30_000;
const OUTCOME_TIMEOUT_MS = (TIME_LIMIT_S + 25) * 1000;   // the clock starts with the first picture
const ENDED_TIMEOUT_MS = 20_000;        // quick_reach.yaml's end_grace is 3 s
const SILENCE_MS = 6000;                // how long the refused survey must hear nothing
const VIEWPORT = { width: 1100, height: 900 };
const TOKEN_PATH = /^\/s\/[0-9a-f]{32}\/$/;

const env = parseManagerArgs('e2e_survey.mjs');
let driver = null;   // browser_driver.mjs's, for env.browser (main loads it)
// The Chromium test's files keep their names; the Firefox run's beside them get a firefox_ (firefox-) prefix.
const PREFIX = env.browser === 'chromium' ? '' : `${env.browser}_`;
const artifact = (name) => path.join(env.artifacts, `${PREFIX}${name}`);
const artifactDir = (name) => path.join(env.artifacts, `${PREFIX.replace('_', '-')}${name}`);

// ---------------------------------------------------------------------------------------------------------------
// Helpers.
// ---------------------------------------------------------------------------------------------------------------

// The demo survey on its own loopback origin, standing in for the survey site. Resolves with the origin.
async function startDemoServer(name, demoFile) {
  const { origin } = await serveHtmlPage(name, '/survey-demo.html', () => fs.readFileSync(demoFile));
  return origin;
}


// The events the demo accepted on one of its pages.
async function eventsOn(page, demoPage) {
  const state = await demoState(page);
  return state.messages.filter((m) => m.page === demoPage);
}

// Waits until the demo accepted `event` on demoPage; returns that page's messages.
function waitForEvent(page, demoPage, event, timeoutMs) {
  return poll(`the survey to receive '${event}' on its ${demoPage} page`, timeoutMs, 200, async () => {
    const messages = await eventsOn(page, demoPage);
    return messages.some((m) => m.event === event) ? messages : null;
  });
}

// The session page inside the demo's iframe #frame-<demoPage>, once it reached /s/<token>/.
function sessionFrame(page, demoPage) {
  return poll(`the ${demoPage} iframe to reach a session page`, 15_000, 100, async () => {
    const element = await page.$(`#frame-${demoPage}`);
    const frame = element && await element.contentFrame();
    return frame && TOKEN_PATH.test(new URL(frame.url()).pathname) ? frame : null;
  });
}

async function nextEnabled(page, demoPage) {
  return driver.isEnabled(page, `#next-${demoPage}`);
}

// The data folder of uid's session: DATA_DIR/sessions/<id>-<uid>.
function sessionFolder(dataDir, uid) {
  const root = path.join(dataDir, 'sessions');
  const pattern = new RegExp(`^\\d+-${uid}$`);   // uids are letters, digits, - and _: no escaping needed
  const names = fs.existsSync(root) ? fs.readdirSync(root).filter((name) => pattern.test(name)) : [];
  check(names.length === 1, `expected one folder ${root}/<id>-${uid}, found ${JSON.stringify(names)}`);
  return path.join(root, names[0]);
}

// session.json once it has an outcome (it is replaced atomically, so a read sees a whole document).
function recordedSession(folder) {
  return poll(`${folder}/session.json to record an outcome`, 20_000, 250, () => {
    const session = JSON.parse(fs.readFileSync(path.join(folder, 'session.json'), 'utf8'));
    return session.outcome ? session : null;
  });
}

// The `outcome` lines of events.jsonl (whole lines only).
function outcomeEvents(folder) {
  const text = fs.readFileSync(path.join(folder, 'events.jsonl'), 'utf8');
  return text.split('\n').slice(0, -1).map((line) => JSON.parse(line)).filter((e) => e.type === 'outcome');
}

// ---------------------------------------------------------------------------------------------------------------
// The test.
// ---------------------------------------------------------------------------------------------------------------
async function main() {
  driver = loadDriver(env);
  const demoFile = path.join(env.webDir, 'survey-demo.html');
  check(fs.existsSync(demoFile), `no survey-demo.html in ${env.webDir}`);
  check(fs.existsSync(env.simRfbPath), `sim_rfb not found at ${env.simRfbPath}`);
  check(fs.existsSync(QUICK_SCENARIO), `test scenario missing: ${QUICK_SCENARIO}`);
  const dataDir = artifactDir('survey-data');
  fs.rmSync(dataDir, { recursive: true, force: true });

  // 1. Two origins serve the demo: one that sim_manager lists in frame_origins, and one it does not.
  const surveyOrigin = await startDemoServer('survey server (allowed origin)', demoFile);
  const strangerOrigin = await startDemoServer('survey server (origin not allowed)', demoFile);

  // 2. sim_manager with the tutorial and the quick test scenario, a short time limit for every task, and
  //    small pictures (two cores are shared with the browser).
  const manager = await startSim(env, `${PREFIX}sim_manager`, [
    '--port', '0', '--data-dir', dataDir, '--scenarios', `tutorial,quick=${QUICK_SCENARIO}`,
    '--frame-origins', surveyOrigin, '--admin-token', ADMIN_TOKEN, '--session-command', env.simRfbPath,
    '--web-root', env.webRoot,
    '--session-arg', '--time-limit', '--session-arg', String(TIME_LIMIT_S),
    '--session-arg', '--width', '--session-arg', '640', '--session-arg', '--height', '--session-arg', '360',
  ]);
  const base = manager.url;
  const managerOrigin = new URL(base).origin;

  const browser = await driver.launch(VIEWPORT);
  const page = await browser.firstPage();
  await driver.addInitScript(page, recordAllMessages);
  const pageLog = recordPage(page, artifact('survey-browser-console.log'));
  log(`browser: ${await page.evaluate(() => navigator.userAgent)}`);
  const shot = (name) => page.screenshot({ path: artifact(`survey_${name}.png`) });

  // ---- The intro page: the participant id from the link. ----
  const demoUrl = (origin, uid) => `${origin}/survey-demo.html?${new URLSearchParams({
    manager: base, uid, scenario: 'quick', t1: CODE_SUCCESS, t2: CODE_TIMEOUT,
  })}`;
  log(`opening ${demoUrl(surveyOrigin, UID)}`);
  const response = await page.goto(demoUrl(surveyOrigin, UID), { waitUntil: 'load', timeout: 20_000 });
  check(response && response.ok(), `GET survey-demo.html answered HTTP ${response && response.status()}`);
  check(await page.evaluate(() => document.compatMode) === 'CSS1Compat', 'survey-demo.html renders in quirks mode');
  const intro = await demoState(page);
  check(intro && intro.page === 'intro' && intro.uid === UID && intro.manager === managerOrigin,
        `window.surveyDemo on the intro page: ${JSON.stringify(intro)}`);
  const shownUid = (await driver.innerText(page, '#uid-shown')).trim();
  check(shownUid === UID, `the demo shows the participant id "${shownUid}", expected "${UID}"`);
  await shot('intro');

  // ---- (b) The tutorial runs out of time: started, then timeout with the tutorial's t2 code. ----
  await driver.click(page, '#next-intro');
  const tutorialFrame = await sessionFrame(page, 'tutorial');
  log(`tutorial iframe at ${tutorialFrame.url()}`);
  await waitForEvent(page, 'tutorial', 'started', FIRST_PICTURE_TIMEOUT_MS);
  const framed = await pageState(tutorialFrame);
  check(framed && framed.firstFrameAt !== null, 'the survey heard "started" before the iframe showed a picture');
  check(!await nextEnabled(page, 'tutorial'), 'Next is enabled on the tutorial page before the outcome');
  log('tutorial: picture shown, "started" received, Next still disabled');

  // A message from any other origin (here: the survey page itself) must not count, however it looks.
  await page.evaluate((uid) => window.postMessage({ type: 'rfbsim', event: 'completed', uid, code: 'FORGED' }, '*'),
                      `${UID}-tutorial`);
  await sleep(300);
  const afterForgery = await eventsOn(page, 'tutorial');
  check(!afterForgery.some((m) => m.code === 'FORGED') && !await nextEnabled(page, 'tutorial'),
        `the demo accepted a message from its own origin: ${describe(afterForgery)}`);
  await shot('tutorial');

  const tutorialMessages = await waitForEvent(page, 'tutorial', 'timeout', OUTCOME_TIMEOUT_MS);
  log(`tutorial messages: ${describe(tutorialMessages)}`);
  check(tutorialMessages.length === 2 && tutorialMessages[0].event === 'started' &&
        tutorialMessages[1].code === TUTORIAL_CODE_TIMEOUT && tutorialMessages.every((m) => m.uid === `${UID}-tutorial`),
        `expected started, timeout(${TUTORIAL_CODE_TIMEOUT}) for ${UID}-tutorial: ${JSON.stringify(tutorialMessages)}`);
  check(await nextEnabled(page, 'tutorial'), 'Next stays disabled after the timeout message');
  const tutorialProgress = await driver.innerText(page, '#progress-tutorial');
  check(tutorialProgress.includes(TUTORIAL_CODE_TIMEOUT), `the tutorial page does not show its code: "${tutorialProgress}"`);
  await shot('tutorial_timeout');

  // ---- (a) The session's task is done at once: started, completed with t1, then ended. ----
  await driver.click(page, '#next-tutorial');
  const sessionPageFrame = await sessionFrame(page, 'session');
  log(`session iframe at ${sessionPageFrame.url()}`);
  await waitForEvent(page, 'session', 'completed', FIRST_PICTURE_TIMEOUT_MS + 15_000);
  check(await nextEnabled(page, 'session'), 'Next stays disabled after the completed message');
  await shot('session_completed');
  const sessionMessages = await waitForEvent(page, 'session', 'ended', ENDED_TIMEOUT_MS);
  log(`session messages: ${describe(sessionMessages)}`);
  // This task is done on the first tick with a viewer, which may be before noVNC drew the first picture: the
  // page then may post 'completed' before 'started' (survey.js does not order them). 'ended' comes last.
  const order = sessionMessages.map((m) => m.event).join();
  const codeOf = (event) => sessionMessages.find((m) => m.event === event).code;
  check((order === 'started,completed,ended' || order === 'completed,started,ended') &&
        codeOf('started') === null && codeOf('completed') === CODE_SUCCESS && codeOf('ended') === CODE_SUCCESS &&
        sessionMessages.every((m) => m.uid === UID),
        `expected started, completed(${CODE_SUCCESS}), ended(${CODE_SUCCESS}) for ${UID}: ` +
        JSON.stringify(sessionMessages));
  if (order !== 'started,completed,ended') {
    log('note: the outcome was posted before the first picture (the task was done before it was drawn)');
  }
  const sessionProgress = await driver.innerText(page, '#progress-session');
  check(sessionProgress.includes(CODE_SUCCESS), `the session page does not show its code: "${sessionProgress}"`);
  const frameState = await sessionPageFrame.evaluate(() => ({
    outcome: window.rfbsimState.outcome,
    code: window.rfbsimState.completionCode,
    posted: [...window.rfbsimState.surveyEvents],
  }));
  check(frameState.outcome === 'completed' && frameState.code === CODE_SUCCESS &&
        [...frameState.posted].sort().join() === 'completed,ended,started',
        `the session page's own record: ${JSON.stringify(frameState)}`);
  await shot('session_ended');

  // ---- The thank-you page lists both codes. ----
  await driver.click(page, '#next-session');
  const done = await demoState(page);
  check(done.page === 'done' &&
        JSON.stringify(done.codes) === JSON.stringify({
          tutorial: { outcome: 'timeout', code: TUTORIAL_CODE_TIMEOUT },
          session: { outcome: 'completed', code: CODE_SUCCESS },
        }), `window.surveyDemo at the end: ${JSON.stringify(done)}`);
  const listed = await driver.innerText(page, '#codes-list');
  check(listed.includes(TUTORIAL_CODE_TIMEOUT) && listed.includes(CODE_SUCCESS),
        `the thank-you page lists "${listed.replace(/\s+/g, ' ')}"`);
  await shot('done');

  // Every message the page got from sim_manager was one the demo accepted; the only other was the forgery.
  const raw = await rawMessages(page);
  const fromManager = raw.filter((m) => m.origin === managerOrigin);
  check(fromManager.length === done.messages.length && raw.length === fromManager.length + 1,
        `messages seen by the page: ${JSON.stringify(raw)}; accepted: ${JSON.stringify(done.messages)}`);

  // ---- (c) The same demo on an origin not in frame_origins: the browser refuses the frame; nothing arrives. ----
  const stranger = await browser.newPage();
  await driver.addInitScript(stranger, recordAllMessages);
  const strangerLog = recordPage(stranger, artifact('survey-stranger-console.log'));
  await stranger.goto(demoUrl(strangerOrigin, STRANGER_UID), { waitUntil: 'load', timeout: 20_000 });
  await driver.click(stranger, '#next-intro');
  const blocked = await poll('the browser to refuse the frame on the other origin', 15_000, 100, async () => {
    const element = await stranger.$('#frame-tutorial');
    const frame = element && await element.contentFrame();
    return frame && driver.isRefusedFrame(frame) ? frame : null;
  });
  log(`frame on ${strangerOrigin} refused (${blocked.url()}); listening ${SILENCE_MS} ms for messages`);
  await sleep(SILENCE_MS);
  const strangerRaw = await rawMessages(stranger);
  const strangerDemo = await demoState(stranger);
  check(strangerRaw.length === 0 && strangerDemo.messages.length === 0,
        `the survey on ${strangerOrigin} received messages: ${JSON.stringify(strangerRaw)}`);
  check(!await nextEnabled(stranger, 'tutorial'), 'Next is enabled on the refused survey');
  await stranger.screenshot({ path: artifact('survey_refused.png') });

  // ---- (d) The session folders and the index record the uid, the outcome and the code. ----
  const expected = [
    { uid: UID, scenario: 'quick', outcome: 'completed', code: CODE_SUCCESS },
    { uid: `${UID}-tutorial`, scenario: 'tutorial', outcome: 'timeout', code: TUTORIAL_CODE_TIMEOUT },
  ];
  for (const want of expected) {
    const folder = sessionFolder(dataDir, want.uid);
    const session = await recordedSession(folder);
    check(session.uid === want.uid && session.scenario === want.scenario && session.outcome === want.outcome &&
          session.completion && session.completion.code === want.code,
          `${folder}/session.json: uid ${session.uid}, scenario ${session.scenario}, outcome ${session.outcome}, ` +
          `completion ${JSON.stringify(session.completion)}; expected ${JSON.stringify(want)}`);
    const outcomes = outcomeEvents(folder);
    check(outcomes.length === 1 && outcomes[0].outcome === want.outcome && outcomes[0].code === want.code,
          `${folder}/events.jsonl: outcome lines ${JSON.stringify(outcomes)}`);
    log(`${path.basename(folder)}: session.json outcome ${session.outcome}, code ${session.completion.code}; ` +
        `events.jsonl has the outcome line`);
  }
  // The session that ended before the survey moved on ended cleanly, for the reason of its outcome.
  const quick = await recordedSession(sessionFolder(dataDir, UID));
  check(quick.ended_at !== null && quick.end_reason === 'completed',
        `${UID}'s session.json: ended_at ${quick.ended_at}, end_reason ${quick.end_reason}`);
  const listing = await (await fetch(new URL('api/sessions', base), {
    headers: { Authorization: `Bearer ${ADMIN_TOKEN}` }, signal: AbortSignal.timeout(5000),
  })).json();
  const indexed = [...listing.live, ...listing.recent];
  for (const want of expected) {
    const row = indexed.find((s) => s.uid === want.uid);
    check(row && row.outcome === want.outcome, `the index lists ${want.uid} with outcome ${row && row.outcome}`);
  }

  const pageErrors = [...pageLog.pageErrors, ...strangerLog.pageErrors];
  check(pageErrors.length === 0, `uncaught errors in the pages: ${pageErrors.join(' | ')}`);
  await stopSimCleanly(manager);
  await Promise.all([pageLog.close(), strangerLog.close()]);
}

await runTest(`${env.browser === 'chromium' ? 'browser' : env.browser}_e2e_survey`, 150, main);
