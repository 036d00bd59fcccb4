// SPDX-License-Identifier: GPL-2.0-or-later
// Browser end-to-end test of network blips (issue 17): a real browser (Chromium, or Firefox ESR with --browser
// firefox) reaches sim_manager through a TCP relay
// (tcp_relay.mjs) that plays the network. Mid-session the relay cuts every connection and refuses new ones for a
// few seconds, without the session ending: the page must say that it is reconnecting, try again by itself with
// growing waits, and get the same session's picture back with no click, the keyboard on the view again. Then the
// same link opens in a second tab, and the manager closes the first with code 4001 ("opened in another window"):
// the page must say so, must not reconnect by itself, and must take the session back when asked. Last, the researcher ends the session: the
// page must show the ending and stay quiet.
//
// Usage: node e2e_reconnect.mjs [--browser chromium|firefox] SIM_MANAGER SIM_RFB WEB_ROOT ARTIFACTS_DIR [WEB_DIR]
//   (as e2e_manager.mjs; writes reconnect_*.png, sim_manager's output, its data folder (reconnect-data) and the
//   browser console (reconnect-browser-console.log) to ARTIFACTS_DIR, with a firefox_ (firefox-) prefix in Firefox)
// Environment: RFBSIM_CHROMIUM (default /usr/bin/chromium), RFBSIM_FIREFOX (default /usr/bin/firefox-esr),
// RFBSIM_E2E_TIMEOUT_S (default 150).
// Exits 0 when every check passed, 1 on the first failed check, 2 on the overall timeout.

import fs from 'node:fs';
import path from 'node:path';

import { loadDriver } from './browser_driver.mjs';
import {
  PIXEL_CHANGE_THRESHOLD, changedFraction, check, log, onCleanup, openPage, pageState,
  parseManagerArgs, poll, recordPage, runTest, sleep, snapshot, startSim, stopSimCleanly,
  waitForConnection, waitForPicture,
} from './e2e_support.mjs';
import { startTcpRelay } from './tcp_relay.mjs';

// ---------------------------------------------------------------------------------------------------------------
// Settings.
// ---------------------------------------------------------------------------------------------------------------
const ADMIN_TOKEN = 'e2e-admin-token-reconnect';
const SCENARIO = 'lab';
const UID = 'blip-1';
const IDLE_TIMEOUT_S = 60;        // far longer than the outage: the session must not end meanwhile
const OUTAGE_MS = 3000;           // how long the relay refuses connections (the page's waits: ~0.5, 1, 2 s)
const MIN_TRIES_IN_OUTAGE = 2;    // automatic tries the page must make while the relay refuses them
const RECOVERY_TIMEOUT_MS = 20_000;
const QUIET_MS = 4000;            // after a 4001, no new try may come in this long (the page's first wait: ~0.5 s)
const HOLD_W_MS = 1500;
const MIN_CHANGED_FRACTION = 0.03;
const VIEWPORT = { width: 1024, height: 720 };
const NOTICE_TEXT = /^Connection lost, reconnecting\u2026 \(attempt (\d+)\)/;

const env = parseManagerArgs('e2e_reconnect.mjs');
// The Chromium test's files keep their names; the Firefox run's beside them get a firefox_ (firefox-) prefix.
const PREFIX = env.browser === 'chromium' ? '' : `${env.browser}_`;
const artifact = (name) => path.join(env.artifacts, `${PREFIX}${name}`);
const artifactDir = (name) => path.join(env.artifacts, `${PREFIX.replace('_', '-')}${name}`);

// ---------------------------------------------------------------------------------------------------------------
// Helpers.
// ---------------------------------------------------------------------------------------------------------------
let managerBase = '';   // http://127.0.0.1:PORT/ of sim_manager itself (the admin API goes there directly)

// The admin API's list of sessions: { live: [...], recent: [...] }.
async function listSessions() {
  const response = await fetch(new URL('api/sessions', managerBase), {
    headers: { Authorization: `Bearer ${ADMIN_TOKEN}` }, signal: AbortSignal.timeout(5000),
  });
  check(response.status === 200, `GET /api/sessions answered HTTP ${response.status}`);
  return response.json();
}

// The one live session of UID (checks that there is exactly one).
async function liveSession(what) {
  const live = (await listSessions()).live.filter((s) => s.uid === UID);
  check(live.length === 1, `${what}: expected one live session for ${UID}, got ${JSON.stringify(live)}`);
  return live[0];
}

// Records, in the page, every text the reconnecting notice shows and whether the panel ever shows:
// window.__e2eNotices (texts in order), window.__e2ePanelSeen.
function recordNotices() {
  window.__e2eNotices = [];
  window.__e2ePanelSeen = false;
  const record = () => {
    const notice = document.getElementById('reconnecting');
    const panel = document.getElementById('disconnected');
    if (notice && !notice.hidden) {
      const text = notice.textContent.replace(/\s+/g, ' ').trim();
      const seen = window.__e2eNotices;
      if (seen[seen.length - 1] !== text) {
        seen.push(text);
      }
    }
    if (panel && !panel.hidden) {
      window.__e2ePanelSeen = true;
    }
  };
  new MutationObserver(record).observe(document, { subtree: true, childList: true, characterData: true,
                                                   attributes: true, attributeFilter: ['hidden'] });
}

// The canvas has the keyboard (document.activeElement), as the page's own state says too.
const canvasFocused = (page) => page.evaluate(() => document.activeElement === document.querySelector('#screen canvas'));

// Holds W and waits for the picture to change from snapshot `before` (input and frames flow on this connection).
async function walkAndSeeChange(page, before, after) {
  await snapshot(page, before);
  await page.keyboard.down('w');
  await sleep(HOLD_W_MS);
  await page.keyboard.up('w');
  await poll(`the picture to change after walking (${after})`, 10_000, 250, async () => {
    await snapshot(page, after);
    return (await changedFraction(page, before, after, PIXEL_CHANGE_THRESHOLD)) >= MIN_CHANGED_FRACTION;
  });
  return changedFraction(page, before, after, PIXEL_CHANGE_THRESHOLD);
}

// The processes whose parent is ppid (pid and start time, from /proc), so that cleanup can stop session processes
// should sim_manager itself not get to it.
function childrenOf(ppid) {
  const out = [];
  for (const entry of fs.readdirSync('/proc')) {
    let stat;
    try {
      stat = /^\d+$/.test(entry) ? fs.readFileSync(`/proc/${entry}/stat`, 'utf8') : null;
    } catch {
      stat = null;   // gone meanwhile
    }
    const fields = stat ? stat.slice(stat.lastIndexOf(')') + 2).split(' ') : [];
    if (fields.length > 19 && Number(fields[1]) === ppid) {
      out.push({ pid: Number(entry), start: fields[19] });
    }
  }
  return out;
}

// Kills the process group of each process in procs that is still the same process (same start time).
function killLeftovers(procs) {
  for (const proc of procs) {
    let stat = '';
    try {
      stat = fs.readFileSync(`/proc/${proc.pid}/stat`, 'utf8');
    } catch {
      continue;   // gone
    }
    if (stat.slice(stat.lastIndexOf(')') + 2).split(' ')[19] === proc.start) {
      log(`cleanup: killing session process group ${proc.pid}`);
      try {
        process.kill(-proc.pid, 'SIGKILL');
      } catch {
        // already gone
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------------------------
// The test.
// ---------------------------------------------------------------------------------------------------------------
async function main() {
  const driver = loadDriver(env);
  check(fs.existsSync(env.simRfbPath), `sim_rfb not found at ${env.simRfbPath}`);
  const dataDir = artifactDir('reconnect-data');
  fs.rmSync(dataDir, { recursive: true, force: true });

  // 1. sim_manager, and the relay in front of it: the browser only ever talks to the relay.
  const manager = await startSim(env, `${PREFIX}sim_manager-reconnect`, [
    '--port', '0', '--data-dir', dataDir, '--scenarios', SCENARIO, '--admin-token', ADMIN_TOKEN,
    '--idle-timeout-s', String(IDLE_TIMEOUT_S), '--session-command', env.simRfbPath, '--web-root', env.webRoot,
  ]);
  managerBase = manager.url;
  const managerUrl = new URL(managerBase);
  const relay = await startTcpRelay({ host: managerUrl.hostname, port: Number(managerUrl.port) });
  onCleanup(() => relay.close());
  const base = `http://127.0.0.1:${relay.port}/`;
  log(`relay on ${base} -> ${managerBase}`);

  const browser = await driver.launch(VIEWPORT);
  await browser.addInitScript(recordNotices);
  const page = await browser.firstPage();
  const pageLog = recordPage(page, artifact('reconnect-browser-console.log'));

  // 2. The link, through the relay, to a picture; the view gets the keyboard and walks.
  await openPage(page, new URL(`start?uid=${UID}&scenario=${SCENARIO}`, base).href);
  const pageUrl = page.url();
  check(/^\/s\/[0-9a-f]{32}\/$/.test(new URL(pageUrl).pathname), `the link led to ${pageUrl}`);
  await waitForConnection(page);
  await waitForPicture(page, 'A0');
  const session = await liveSession('before the blip');
  const sessionProcs = childrenOf(manager.child.pid);
  onCleanup(() => killLeftovers(sessionProcs));
  check(session.state === 'running', `the session is ${session.state}, expected running`);
  check(pageUrl.endsWith(`/s/${session.token}/`), `the page (${pageUrl}) is not session ${session.token}'s`);
  await driver.click(page, '#screen canvas');
  await driver.waitHidden(page, '#hint', 5000);
  check(await canvasFocused(page), 'the canvas does not have the keyboard after a click');
  const walked = await walkAndSeeChange(page, 'A', 'B');
  log(`session ${session.id} (${session.token}) shows and walks (${(100 * walked).toFixed(1)} % of pixels changed)`);
  const upgradesBefore = relay.upgrades;
  const attemptsBefore = (await pageState(page)).attempts;

  // 3. The blip: every connection cut without a close frame, new ones refused for OUTAGE_MS.
  relay.setRefusing(true);
  relay.cutAll();
  log(`relay: connections cut, refusing new ones for ${OUTAGE_MS} ms`);
  await poll('the page to notice and start reconnecting', 5000, 50, async () => (await pageState(page)).reconnecting);
  await driver.waitVisible(page, '#reconnecting', 5000);
  await sleep(OUTAGE_MS);
  const during = await pageState(page);
  const noticeText = (await driver.innerText(page, '#reconnecting-text')).trim();
  await page.screenshot({ path: artifact('reconnect_outage.png') });
  log(`during the outage: "${noticeText}", ${during.attempts - attemptsBefore} tries, lost with close ` +
      `${during.lastLoss?.code} (${during.lastLoss?.kind})`);
  check(NOTICE_TEXT.test(noticeText), `the notice says "${noticeText}"`);
  check(during.attempts - attemptsBefore >= MIN_TRIES_IN_OUTAGE,
        `only ${during.attempts - attemptsBefore} tries in ${OUTAGE_MS} ms (expected >= ${MIN_TRIES_IN_OUTAGE})`);
  check(during.lastLoss && during.lastLoss.kind === 'lost' && during.lastLoss.code === 1006,
        `the loss is recorded as ${JSON.stringify(during.lastLoss)}, expected lost with 1006`);
  check(!during.lastDisconnect && await driver.isHidden(page, '#disconnected'),
        `the disconnect panel shows during a blip: ${during.lastDisconnect?.message}`);
  check(!await driver.isHidden(page, '#reconnect-now'), 'no Reconnect now button in the notice');

  // 4. The network comes back: the picture returns with no click, same session, keyboard on the view.
  relay.setRefusing(false);
  log('relay: accepting connections again');
  const back = await poll('the page to reconnect by itself', RECOVERY_TIMEOUT_MS, 100, async () => {
    const state = await pageState(page);
    check(!state.lastDisconnect, `the page gave up: ${state.lastDisconnect?.message}`);
    return state.connected && !state.reconnecting ? state : null;
  });
  await waitForPicture(page, 'C0');
  check(await driver.isHidden(page, '#reconnecting'), 'the notice still shows after reconnecting');
  check(page.url() === pageUrl, `the page moved to ${page.url()}`);
  check(back.reconnects === 1, `rfbsimState.reconnects is ${back.reconnects}, expected 1`);
  check(relay.upgrades > upgradesBefore, 'no new WebSocket went through the relay');
  const sameSession = await liveSession('after the blip');
  check(sameSession.id === session.id && sameSession.token === session.token && sameSession.state === 'running',
        `after the blip the live session is ${JSON.stringify(sameSession)}, expected id ${session.id} running`);
  check(await canvasFocused(page), 'the view did not get the keyboard back after reconnecting');
  const walkedAgain = await walkAndSeeChange(page, 'C', 'D');
  const notices = await page.evaluate(() => window.__e2eNotices);
  check(!(await page.evaluate(() => window.__e2ePanelSeen)), 'the disconnect panel showed during the blip');
  log(`reconnected with no click after ${back.attempts - attemptsBefore} tries: same session ${session.id}, ` +
      `keyboard on the view, walks again (${(100 * walkedAgain).toFixed(1)} %); notices: ${notices.join(' | ')}`);
  await page.screenshot({ path: artifact('reconnect_back.png') });

  // 5. The same link opened in a second tab (straight to the manager, not through the relay): the manager hands
  // the session to the newer browser and closes this one with 4001 ("opened in another window"); the page says
  // so and does not reconnect by itself.
  const upgradesAtTakeover = relay.upgrades;
  const attemptsAtTakeover = (await pageState(page)).attempts;
  const secondTab = await browser.newPage();
  await secondTab.goto(new URL(`s/${session.token}/`, managerBase).href);
  await waitForPicture(secondTab, 'T');
  await driver.waitVisible(page, '#disconnected', 10_000);
  await secondTab.close();
  await sleep(QUIET_MS);
  const takenOver = await pageState(page);
  const panelText = (await driver.innerText(page, '#disconnected')).replace(/\s+/g, ' ').trim();
  log(`after 4001: "${panelText}" (${JSON.stringify({ kind: takenOver.lastDisconnect?.kind,
    code: takenOver.lastDisconnect?.code, reason: takenOver.lastDisconnect?.reason })})`);
  check(panelText.includes('This session was opened in another window or tab.'),
        `the panel says "${panelText}"`);
  check(takenOver.lastDisconnect?.kind === 'taken-over' && takenOver.lastDisconnect.code === 4001 &&
        takenOver.lastDisconnect.final === false, `lastDisconnect: ${JSON.stringify(takenOver.lastDisconnect)}`);
  check(!takenOver.reconnecting && takenOver.attempts === attemptsAtTakeover && relay.upgrades === upgradesAtTakeover,
        `the page tried again by itself after 4001 (${takenOver.attempts - attemptsAtTakeover} tries)`);
  check(await driver.isHidden(page, '#reconnecting'), 'the reconnecting notice shows after 4001');
  await page.screenshot({ path: artifact('reconnect_taken_over.png') });

  // 6. Taking it back: one click, one try, the picture again.
  // The panel's one button (#reconnect) says what it does.
  const takeBackText = await driver.isHidden(page, '#reconnect')
    ? '' : (await driver.innerText(page, '#reconnect')).trim();
  check(takeBackText === 'Use it here', `no "Use it here" button after 4001 (the panel's button: "${takeBackText}")`);
  await driver.click(page, '#reconnect');
  const retaken = await poll('the page to take the session back', RECOVERY_TIMEOUT_MS, 100, async () => {
    const state = await pageState(page);
    return state.connected ? state : null;
  });
  await waitForPicture(page, 'E');
  check(retaken.attempts === attemptsAtTakeover + 1, `${retaken.attempts - attemptsAtTakeover} tries to take it back`);
  check(await driver.isHidden(page, '#disconnected'), 'the panel still shows after taking the session back');
  check(await canvasFocused(page), 'the view does not have the keyboard after taking the session back');
  check((await liveSession('after taking it back')).id === session.id, 'taking it back changed the session');
  log('took the session back with one click');

  // 7. The researcher ends the session: an ending, never retried.
  const ended = await fetch(new URL(`api/sessions/${session.id}/end`, managerBase), {
    method: 'POST', signal: AbortSignal.timeout(5000),
    headers: { Authorization: `Bearer ${ADMIN_TOKEN}`, 'X-Rfbsim-Admin': '1' },
  });
  check(ended.status === 200, `POST /api/sessions/${session.id}/end answered HTTP ${ended.status}`);
  await poll('the page to show the ending', 10_000, 100, async () => (await pageState(page)).lastDisconnect?.final);
  const attemptsAtEnd = (await pageState(page)).attempts;
  await sleep(QUIET_MS / 2);
  const final = await pageState(page);
  check(final.attempts === attemptsAtEnd && !final.reconnecting, 'the page tried again after the session ended');
  check(await driver.isHidden(page, '#reconnect'), 'a Reconnect button shows for a session that is over');
  log(`ended: "${final.lastDisconnect.message}" (close ${final.lastDisconnect.code}); no further tries`);

  check(pageLog.pageErrors.length === 0, `uncaught errors in the page: ${pageLog.pageErrors.join(' | ')}`);
  await stopSimCleanly(manager);
  await pageLog.close();
}

await runTest(`${env.browser === 'chromium' ? 'browser' : env.browser}_e2e_reconnect`, 150, main);
