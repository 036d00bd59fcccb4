// SPDX-License-Identifier: GPL-2.0-or-later
// Shared parts of the whole-task browser tests (e2e_task.mjs: the task done; e2e_task_timeout.mjs: the time
// runs out): sim_manager with the shipped warehouse scenario, a one-page survey on its own origin that frames
// the participant's /start link and shows the completion code it hears (as docs/survey.md tells surveys to
// listen), the session's folder, and the checks of the end: the task's events in order, the survey's
// messages, session.json, manager.json and the manager's index.

import fs from 'node:fs';
import path from 'node:path';

import { loadDriver } from './browser_driver.mjs';
import { check, log, pageState, poll, recordPage, serveHtmlPage, startSim } from './e2e_support.mjs';

export const ADMIN_TOKEN = 'e2e-task-admin-token-0123';
export const CODE_SUCCESS = 'E2E-TASK-DONE';   // the link's t1
export const CODE_TIMEOUT = 'E2E-TASK-LATE';   // the link's t2
export const SEED = 1;                         // the warehouse's own seed, given in the link: same people each run
const VIEWPORT = { width: 1000, height: 700 };
const FRAME_SIZE = ['--width', '640', '--height', '360'];   // small pictures: two cores run everything
const FIRST_PICTURE_TIMEOUT_MS = 45_000;
const TOKEN_PATH = /^\/s\/[0-9a-f]{32}\/$/;

// The survey page: the simulator in an iframe, and the code it reports. Only messages from sim_manager's
// origin and from this iframe count (docs/survey.md, "The messages").
function surveyHtml(managerOrigin, link) {
  return `<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>Study (test survey)</title>
<style>
  body { margin: 0; font: 16px sans-serif; }
  .frame-box { width: 960px; aspect-ratio: 16 / 9; }
  iframe { width: 100%; height: 100%; border: 0; }
</style>
</head>
<body>
<div class="frame-box"><iframe id="sim" title="Simulation" allow="fullscreen"></iframe></div>
<p>Outcome: <span id="outcome">none yet</span>. Your completion code: <strong id="code">none yet</strong></p>
<script>
  const MANAGER = ${JSON.stringify(managerOrigin)};
  const frame = document.getElementById('sim');
  window.survey = { messages: [], outcome: null, code: null };
  window.addEventListener('message', (event) => {
    if (event.origin !== MANAGER || event.source !== frame.contentWindow) return;
    const data = event.data;
    if (!data || data.type !== 'rfbsim') return;
    window.survey.messages.push({ event: data.event, uid: data.uid, code: data.code });
    if ((data.event === 'completed' || data.event === 'timeout') && window.survey.outcome === null) {
      window.survey.outcome = data.event;
      window.survey.code = data.code;
      document.getElementById('outcome').textContent = data.event;
      document.getElementById('code').textContent = data.code;
    }
  });
  frame.src = ${JSON.stringify(link)};
</script>
</body>
</html>
`;
}

let driver = null;   // browser_driver.mjs's, for env.browser (startTaskSession loads it)

/// Starts sim_manager (warehouse only, its sessions' extra arguments `sessionArgs`), the survey, the browser
/// (env.browser) on the survey page, and waits for the session's first picture in the iframe. Resolves with
/// { manager, driver, page, frame, pageLog, dataDir, folder (the session's data folder), session (its first
/// session.json), shot(name) }. Files are named after `tag`, with a firefox_ prefix in Firefox.
export async function startTaskSession(env, { tag: chromiumTag, uid, sessionArgs = [] }) {
  driver = loadDriver(env);
  const tag = env.browser === 'chromium' ? chromiumTag : `${env.browser}_${chromiumTag}`;
  check(fs.existsSync(env.simRfbPath), `sim_rfb not found at ${env.simRfbPath}`);
  const dataDir = path.join(env.artifacts, `${tag}-data`);
  fs.rmSync(dataDir, { recursive: true, force: true });

  // The survey's origin must be known before sim_manager starts (frame_origins), the manager's before the
  // survey page is written: the page is made on each request.
  let managerBase = null;
  const { origin: surveyOrigin } = await serveHtmlPage('survey server', '/survey.html', () => {
    const link = new URL('start', managerBase);
    link.search = new URLSearchParams({ uid, scenario: 'warehouse', t1: CODE_SUCCESS, t2: CODE_TIMEOUT,
                                        seed: String(SEED) }).toString();
    return surveyHtml(new URL(managerBase).origin, link.href);
  });
  const sessionArgList = [...FRAME_SIZE, ...sessionArgs].flatMap((a) => ['--session-arg', a]);
  const manager = await startSim(env, `sim_manager-${tag}`, [
    '--port', '0', '--data-dir', dataDir, '--scenarios', 'warehouse', '--frame-origins', surveyOrigin,
    '--admin-token', ADMIN_TOKEN, '--session-command', env.simRfbPath, '--web-root', env.webRoot,
    // The task may take its whole 240 s plus 15 s of grace: no expiry before that.
    '--max-duration-s', '600', ...sessionArgList,
  ]);
  managerBase = manager.url;

  const browser = await driver.launch(VIEWPORT);
  const page = await browser.firstPage();
  const pageLog = recordPage(page, path.join(env.artifacts, `${tag}-browser-console.log`));
  const shot = (name) => page.screenshot({ path: path.join(env.artifacts, `${tag}_${name}.png`) });
  const surveyUrl = `${surveyOrigin}/survey.html`;
  log(`opening ${surveyUrl}`);
  const response = await page.goto(surveyUrl, { waitUntil: 'load', timeout: 20_000 });
  check(response && response.ok(), `GET ${surveyUrl} answered HTTP ${response && response.status()}`);

  // The iframe reaches the session page and shows a picture.
  const frame = await poll('the survey iframe to reach a session page', 20_000, 100, async () => {
    const element = await page.$('#sim');
    const f = element && await element.contentFrame();
    return f && TOKEN_PATH.test(new URL(f.url()).pathname) ? f : null;
  });
  log(`session page at ${frame.url()}`);
  await poll('the first picture in the iframe', FIRST_PICTURE_TIMEOUT_MS, 200, async () => {
    const state = await pageState(frame);
    check(!state || !state.lastDisconnect, `the session page reports: ${state?.lastDisconnect?.message}`);
    return state && state.connected && state.firstFrameAt !== null;
  });
  log('the session shows its first picture');

  const folder = sessionFolder(dataDir, uid);
  const session = JSON.parse(fs.readFileSync(path.join(folder, 'session.json'), 'utf8'));
  check(session.scenario === 'warehouse' && path.basename(session.scenario_file) === 'warehouse.yaml' &&
        session.seed === String(SEED) && session.uid === uid,
        `${folder}/session.json: scenario ${session.scenario} from ${session.scenario_file}, seed ${session.seed}, ` +
        `uid ${session.uid}`);
  return { manager, driver, page, frame, pageLog, dataDir, folder, session, shot };
}

// DATA_DIR/sessions/<id>-<uid>, once it holds session.json.
function sessionFolder(dataDir, uid) {
  const root = path.join(dataDir, 'sessions');
  const pattern = new RegExp(`^\\d+-${uid}$`);   // uids are letters, digits, - and _: no escaping needed
  const names = fs.existsSync(root) ? fs.readdirSync(root).filter((name) => pattern.test(name)) : [];
  check(names.length === 1, `expected one folder ${root}/<id>-${uid}, found ${JSON.stringify(names)}`);
  const folder = path.join(root, names[0]);
  check(fs.existsSync(path.join(folder, 'session.json')), `${folder} has no session.json`);
  return folder;
}

/// The survey page's record: { messages, outcome, code } and the code it shows.
export async function surveyState(page) {
  const state = await page.evaluate(() => JSON.parse(JSON.stringify(window.survey)));
  return { ...state, shownCode: (await driver.innerText(page, '#code')).trim(),
           shownOutcome: (await driver.innerText(page, '#outcome')).trim() };
}

/// The task's story in events.jsonl, one string per timer, task, outcome and session-end event:
/// 'timer started', 'task started 0 find_robot', 'task done 0 find_robot', 'outcome completed CODE',
/// 'session end completed'.
export function taskStory(events) {
  return events.flatMap((e) => {
    switch (e.type) {
      case 'timer': return [`timer ${e.event}`];
      case 'task': return [`task ${e.event} ${e.index} ${e.task}`];
      case 'outcome': return [`outcome ${e.outcome} ${e.code}`];
      case 'session': return e.event === 'end' ? [`session end ${e.reason}`] : [];
      default: return [];
    }
  });
}

/// The whole lines of a session file (events.jsonl as objects).
export function readEvents(folder) {
  const text = fs.readFileSync(path.join(folder, 'events.jsonl'), 'utf8');
  return text.split('\n').slice(0, -1).map((line) => JSON.parse(line));
}

/// Waits for the session's end and checks it everywhere it is recorded: the survey heard `outcome` with
/// `code` and then 'ended'; the page in the iframe knows the outcome; session.json, manager.json and the
/// manager's index agree. Resolves with session.json.
export async function checkEnd({ page, frame, folder, manager }, uid, outcome, code) {
  const survey = await poll('the survey to hear "ended"', 40_000, 250, async () => {
    const s = await surveyState(page);
    return s.messages.some((m) => m.event === 'ended') ? s : null;
  });
  const order = survey.messages.map((m) => `${m.event}${m.code ? `(${m.code})` : ''}`).join(', ');
  log(`survey messages: ${order}; the survey shows "${survey.shownOutcome}" and code "${survey.shownCode}"`);
  check(order === `started, ${outcome}(${code}), ended(${code})` && survey.messages.every((m) => m.uid === uid),
        `the survey heard ${JSON.stringify(survey.messages)}; expected started, ${outcome}(${code}), ended(${code}) ` +
        `for ${uid}`);
  check(survey.outcome === outcome && survey.code === code && survey.shownCode === code &&
        survey.shownOutcome === outcome,
        `the survey page shows outcome "${survey.shownOutcome}", code "${survey.shownCode}"; expected ${outcome}, ${code}`);
  const framed = await pageState(frame);
  check(framed.outcome === outcome && framed.completionCode === code,
        `the session page's rfbsimState: outcome ${framed.outcome}, code ${framed.completionCode}`);

  const session = await poll(`${folder}/session.json to record the end`, 20_000, 250, () => {
    const s = JSON.parse(fs.readFileSync(path.join(folder, 'session.json'), 'utf8'));
    return s.ended_at ? s : null;
  });
  check(session.outcome === outcome && session.end_reason === outcome && session.completion &&
        session.completion.code === code && session.codes.success === CODE_SUCCESS &&
        session.codes.timeout === CODE_TIMEOUT,
        `session.json: outcome ${session.outcome}, end_reason ${session.end_reason}, completion ` +
        `${JSON.stringify(session.completion)}, codes ${JSON.stringify(session.codes)}`);
  const record = await poll(`${folder}/manager.json to say the session finished`, 20_000, 250, () => {
    const m = JSON.parse(fs.readFileSync(path.join(folder, 'manager.json'), 'utf8'));
    return m.state !== 'running' && m.state !== 'starting' ? m : null;
  });
  check(record.state === 'finished' && record.outcome === outcome,
        `manager.json: state ${record.state}, outcome ${record.outcome}, detail "${record.detail}"`);
  const listing = await (await fetch(new URL('api/sessions', manager.url), {
    headers: { Authorization: `Bearer ${ADMIN_TOKEN}` }, signal: AbortSignal.timeout(5000),
  })).json();
  const row = [...listing.live, ...listing.recent].find((s) => s.uid === uid);
  check(row && row.outcome === outcome && listing.live.every((s) => s.uid !== uid),
        `the manager's index lists ${uid} as ${JSON.stringify(row)} (live: ${listing.live.length})`);
  log(`end state: session.json ${session.outcome} (${session.completion.code}), manager.json ${record.state}, ` +
      `index ${row.outcome}`);
  return session;
}
