// SPDX-License-Identifier: GPL-2.0-or-later
// Browser end-to-end test of the cluster: scripts/run-cluster-demo.sh starts three sim_manager hosts of one slot
// each behind HAProxy, running the light examples/minimal program as the session. A real Chromium then, through
// HAProxy only: opens three participants' links, each of which shows a picture from a /hN/s/<token>/ page; opens the
// admin page, whose Cluster view lists every host and each participant's session under its host; kills one
// participant's host with SIGKILL, after which that participant's page says "Session lost" and sends them back to
// the survey, the other two keep receiving pictures, and the Cluster view marks the host unreachable.
//
// Usage: node e2e_cluster.mjs CLUSTER_SCRIPT BUILD_DIR MINIMAL ARTIFACTS_DIR [WEB_DIR]
//   CLUSTER_SCRIPT  scripts/run-cluster-demo.sh
//   BUILD_DIR       the build folder whose manager/sim_manager the script runs (--build-dir)
//   MINIMAL         the rfbsim_minimal executable each session runs
//   ARTIFACTS_DIR   where screenshots (cluster_*.png), the browser consoles, the script's output and the cluster's
//                   logs (cluster-logs/) are written (created)
//   WEB_DIR         the source web/ folder whose node_modules holds playwright-core (default: ../../web from here)
// Environment: RFBSIM_CHROMIUM (default /usr/bin/chromium), RFBSIM_E2E_TIMEOUT_S (default 180),
// RFBSIM_KEEP_CLUSTER=1 keeps the run dir (data, secrets) under /tmp.
// Exits 0 when every check passed, 1 on the first failed check, 2 on the overall timeout.

import { spawn } from 'node:child_process';
import fs from 'node:fs';
import net from 'node:net';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

import {
  changedFraction, check, launchBrowser, log, onCleanup, openPage, pageState, poll, prepare, recordPage, runTest,
  sleep, snapshot,
} from './e2e_support.mjs';

// ---------------------------------------------------------------------------------------------------------------
// Settings.
// ---------------------------------------------------------------------------------------------------------------
const HOSTS = 3;
const UIDS = ['e2e-cluster-1', 'e2e-cluster-2', 'e2e-cluster-3'];
const READY_TIMEOUT_MS = 90_000;        // the script starts three managers and HAProxy (as cluster_under_test.cpp)
const FIRST_FRAME_TIMEOUT_MS = 30_000;  // a link must show its first picture within this
const FULL_TIMEOUT_MS = 15_000;         // HAProxy's agent check (every 1 s) must see a host full within this
const LOST_TIMEOUT_MS = 15_000;         // issue 18: the killed host's participant is told within 15 s
const ADMIN_TIMEOUT_MS = 20_000;        // the Cluster view refreshes every 5 s (web/admin.js CLUSTER_REFRESH_MS)
const FRAMES_TIMEOUT_MS = 15_000;       // the survivors must get new pictures within this after the kill
const MIN_NEW_FRAMES = 5;               // WebSocket messages a survivor must receive after the kill
const SCRIPT_EXIT_TIMEOUT_MS = 30_000;  // the script stops its managers and HAProxy on SIGTERM (15 s at most)
const VIEWPORT = { width: 800, height: 600 };
const PAGE_PATH = /^\/(h\d+)\/s\/([0-9a-f]{32})\/$/;
const LOST_WORDS = /Please go back to the survey/;

const here = path.dirname(fileURLToPath(import.meta.url));
const [scriptArg, buildArg, minimalArg, artifactsArg, webArg] = process.argv.slice(2);
if (!scriptArg || !buildArg || !minimalArg || !artifactsArg) {
  console.error('usage: node e2e_cluster.mjs CLUSTER_SCRIPT BUILD_DIR MINIMAL ARTIFACTS_DIR [WEB_DIR]');
  process.exit(1);
}
const env = {
  simPath: path.resolve(scriptArg),   // what prepare() checks exists
  buildDir: path.resolve(buildArg),
  minimal: path.resolve(minimalArg),
  artifacts: path.resolve(artifactsArg),
  webDir: path.resolve(webArg || path.join(here, '..', '..', 'web')),
};

// ---------------------------------------------------------------------------------------------------------------
// Ports: a cluster on base P uses P..P+303. As tests/support/cluster_under_test.cpp: bases 400 apart in
// 20000..31600 never overlap one another and stay below the ephemeral ports that clients draw from.
// ---------------------------------------------------------------------------------------------------------------
function portIsFree(port) {
  return new Promise((resolve) => {
    const server = net.createServer();
    server.once('error', () => resolve(false));
    server.listen(port, '127.0.0.1', () => server.close(() => resolve(true)));
  });
}

async function freeClusterBase() {
  for (let attempt = 0; attempt < 50; attempt += 1) {
    const base = (50 + Math.floor(Math.random() * 30)) * 400;
    const wanted = [base, base + 300];
    for (let i = 1; i <= HOSTS; i += 1) {
      wanted.push(base + i, base + 100 + i, base + 200 + i);
    }
    let free = true;
    for (const port of wanted) {
      if (!(await portIsFree(port))) {
        free = false;
        break;
      }
    }
    if (free) {
      return base;
    }
  }
  throw new Error('no free port range for a cluster');
}

// The sessions: examples/minimal (an animated scene of a few clears), as tests/cluster's minimal_sessions_yaml.
function sessionsYaml(minimal) {
  return [
    'session_kind: rfb',
    `session_command: ${minimal}`,
    'session_args: ["{port}"]',
    'scenarios: [demo]',
    'first_connect_timeout_s: 120',
    'idle_timeout_s: 120',
    'max_duration_s: 300',
    'stop_grace_s: 1',
    '',
  ].join('\n');
}

// ---------------------------------------------------------------------------------------------------------------
// The script: its own process group (so that nothing it started can outlive this test), its lines parsed.
// ---------------------------------------------------------------------------------------------------------------

// Whether process pid still runs (a zombie does not).
function running(pid) {
  try {
    const stat = fs.readFileSync(`/proc/${pid}/stat`, 'utf8');
    return stat.slice(stat.lastIndexOf(')') + 2, stat.lastIndexOf(')') + 3) !== 'Z';
  } catch {
    return false;
  }
}

// Starts the script and resolves with { child, exited (promise), hosts: Map id -> { pid, port }, haproxyPid, url }
// once it printed `cluster ready: URL`. Cleanup stops it with SIGTERM (SIGKILL to its group if that fails).
async function startCluster(args, outputPath) {
  log(`starting ${env.simPath} ${args.join(' ')}`);
  const output = fs.createWriteStream(outputPath);
  const child = spawn(env.simPath, args, { stdio: ['ignore', 'pipe', 'pipe'], detached: true });
  const cluster = { child, done: null, hosts: new Map(), haproxyPid: 0, url: '' };
  cluster.exited = new Promise((resolve) => {
    child.on('exit', (code, signal) => {
      cluster.done = { code, signal };
      resolve(cluster.done);
    });
  });
  cluster.closed = new Promise((resolve) => child.on('close', resolve));
  process.on('exit', () => {
    if (cluster.done === null) {
      try {
        process.kill(-child.pid, 'SIGKILL');   // last resort: the script and the managers and HAProxy it started
      } catch {
        // already gone
      }
    }
  });
  onCleanup(async () => {
    if (cluster.done === null) {
      log(`cleanup: stopping the cluster script (pid ${child.pid}) with SIGTERM`);
      child.kill('SIGTERM');
      if (!(await Promise.race([cluster.exited, sleep(SCRIPT_EXIT_TIMEOUT_MS).then(() => null)]))) {
        log('cleanup: the script did not exit; SIGKILL to its process group');
      }
    }
    // Whatever is left in its group (nothing, when the script works) goes too.
    try {
      process.kill(-child.pid, 'SIGKILL');
    } catch {
      // the group is empty
    }
    // Its last lines may still be in the pipes after 'exit' ('close' comes once they are read).
    await Promise.race([cluster.closed, sleep(2000)]);
    await new Promise((resolve) => output.end(resolve));
  });

  let text = '';
  const ready = new Promise((resolve, reject) => {
    const timer = setTimeout(() => reject(new Error(`the script was not ready within ${READY_TIMEOUT_MS} ms`)),
                             READY_TIMEOUT_MS);
    cluster.exited.then(({ code, signal }) => {
      clearTimeout(timer);
      reject(new Error(`the script exited before it was ready (code ${code}, signal ${signal})`));
    });
    const take = (chunk) => {
      if (!output.writableEnded) {
        output.write(chunk);
      }
      for (const line of chunk.toString('utf8').split('\n').filter((l) => l.length > 0)) {
        log(`[cluster] ${line}`);
      }
      text += chunk.toString('utf8');
      const match = /^cluster ready: (\S+)\n/m.exec(text);
      if (match) {
        clearTimeout(timer);
        resolve(match[1]);
      }
    };
    child.stdout.on('data', take);
    child.stderr.on('data', take);
  });
  try {
    cluster.url = await ready;
  } catch (err) {
    check(false, err.message);
  }
  for (const match of text.matchAll(/^host (h\d+) pid (\d+) port (\d+) /gm)) {
    cluster.hosts.set(match[1], { pid: Number(match[2]), port: Number(match[3]) });
  }
  const haproxy = /^haproxy pid (\d+)/m.exec(text);
  cluster.haproxyPid = haproxy ? Number(haproxy[1]) : 0;
  check(cluster.hosts.size === HOSTS && cluster.haproxyPid > 0,
        `the script printed ${cluster.hosts.size} host line(s) and haproxy pid ${cluster.haproxyPid}`);
  return cluster;
}

// HAProxy's view of server `server` in backend `backend` (UP, DOWN, DRAIN, with details such as "DRAIN (agent)"),
// from its stats page.
async function serverStatus(statsPort, backend, server) {
  const response = await fetch(`http://127.0.0.1:${statsPort}/stats;csv`, { signal: AbortSignal.timeout(3000) });
  const lines = (await response.text()).split('\n');
  const header = lines[0].replace(/^# /, '').split(',');
  const column = header.indexOf('status');
  for (const line of lines.slice(1)) {
    const fields = line.split(',');
    if (fields[0] === backend && fields[1] === server) {
      return fields[column];
    }
  }
  return '';
}

// ---------------------------------------------------------------------------------------------------------------
// The participants' pages.
// ---------------------------------------------------------------------------------------------------------------

// A new tab that counts the WebSocket messages it receives (the pictures, for an RFB session).
async function participantTab(context, uid, first) {
  const page = first ? (context.pages()[0] || await context.newPage()) : await context.newPage();
  const tab = { uid, page, frames: 0, host: '', token: '',
                log: recordPage(page, path.join(env.artifacts, `cluster-${uid}-console.log`)) };
  page.on('websocket', (ws) => ws.on('framereceived', () => { tab.frames += 1; }));
  return tab;
}

const panelText = (page) => page.evaluate(() => ({
  shown: !document.getElementById('disconnected').hidden,
  title: document.getElementById('disconnected-title').textContent,
  detail: document.getElementById('disconnected-detail').textContent,
}));

// ---------------------------------------------------------------------------------------------------------------
// The admin page's Cluster view.
// ---------------------------------------------------------------------------------------------------------------
const clusterState = (page) => page.evaluate(() => JSON.parse(JSON.stringify(window.rfbsimAdminState?.cluster ?? null)));

// The Cluster view's two tables as text: { hosts: [[id, state, live]], sessions: [[host, id, uid, ...]] }.
const clusterTables = (page) => page.evaluate(() => {
  const rows = (selector) => [...document.querySelectorAll(`${selector} tbody tr`)]
    .map((row) => [...row.cells].map((cell) => ({ text: cell.textContent.trim(), className: cell.className })));
  return { shown: !document.getElementById('cluster-section').hidden, hosts: rows('#cluster-hosts'),
           sessions: rows('#cluster-sessions') };
});

// ---------------------------------------------------------------------------------------------------------------
// The test.
// ---------------------------------------------------------------------------------------------------------------
async function main() {
  const chromium = prepare(env);
  check(fs.existsSync(path.join(env.buildDir, 'manager', 'sim_manager')),
        `no sim_manager in ${env.buildDir}/manager (build it first)`);
  check(fs.existsSync(env.minimal), `rfbsim_minimal not found at ${env.minimal}`);

  // 0. Free ports, a run dir of its own (secrets, data, logs), the sessions' config.
  const port = await freeClusterBase();
  const runDir = fs.mkdtempSync(path.join(os.tmpdir(), 'rfbsim-e2e-cluster-'));
  const logsDir = path.join(env.artifacts, 'cluster-logs');
  fs.rmSync(logsDir, { recursive: true, force: true });
  // Runs after the script's hook (hooks run in order): its logs are complete by then.
  const keepLogs = () => {
    fs.mkdirSync(logsDir, { recursive: true });
    for (const name of fs.readdirSync(runDir).filter((n) => /^(h\d+\.log|haproxy\.(log|cfg)|base\.yaml)$/.test(n))) {
      fs.copyFileSync(path.join(runDir, name), path.join(logsDir, name));
    }
    if (process.env.RFBSIM_KEEP_CLUSTER) {
      log(`the run dir is kept: ${runDir}`);
    } else {
      fs.rmSync(runDir, { recursive: true, force: true });
    }
  };
  const configPath = path.join(runDir, 'base.yaml');
  fs.writeFileSync(configPath, sessionsYaml(env.minimal));

  // 1. The cluster: three hosts of one slot each behind HAProxy.
  let cluster;
  try {
    cluster = await startCluster(['--hosts', String(HOSTS), '--port', String(port), '--max-sessions', '1',
                                  '--build-dir', env.buildDir, '--run-dir', runDir, '--config', configPath],
                                 path.join(env.artifacts, 'cluster-script.log'));
  } finally {
    onCleanup(keepLogs);
  }
  const base = cluster.url.endsWith('/') ? cluster.url : `${cluster.url}/`;
  const adminToken = fs.readFileSync(path.join(runDir, 'admin-token'), 'utf8').trim();
  check(adminToken.length > 0, 'the run dir has no admin token');

  // 2. The browser: the admin credentials for HAProxy's origin, sent only when a page asks for them.
  const context = await launchBrowser(chromium, VIEWPORT, {
    httpCredentials: { username: 'researcher', password: adminToken, origin: new URL(base).origin },
  });

  // ---- a. Three participants, each with a picture from a /hN/s/<token>/ page. ----
  // One at a time, and the next only once HAProxy's agent check sees the last one's host full: the pool then hashes
  // the next uid to a host with a free slot, as it would for participants who arrive a little apart.
  const tabs = [];
  for (const uid of UIDS) {
    const tab = await participantTab(context, uid, tabs.length === 0);
    tabs.push(tab);
    await openPage(tab.page, `${base}start?uid=${uid}`);
    const where = PAGE_PATH.exec(new URL(tab.page.url()).pathname);
    check(where !== null, `${uid}'s page is at ${tab.page.url()}, not /hN/s/<token>/`);
    [, tab.host, tab.token] = where;
    check(cluster.hosts.has(tab.host), `${uid}'s page is on ${tab.host}, which the script did not start`);
    await poll(`${uid}'s first picture (rfbsimState.firstFrameAt)`, FIRST_FRAME_TIMEOUT_MS, 200, async () => {
      const state = await pageState(tab.page);
      check(!state?.lastDisconnect, `${uid}'s page reports a disconnect: ${state?.lastDisconnect?.message}`);
      return state && state.firstFrameAt !== null;
    });
    log(`${uid}: a picture on ${tab.host} (/${tab.host}/s/${tab.token}/), ${tab.frames} WebSocket messages so far`);
    await poll(`HAProxy to see ${tab.host} full (DRAIN in the pool)`, FULL_TIMEOUT_MS, 200,
               async () => (await serverStatus(port + 300, 'pool', tab.host)).startsWith('DRAIN'));
  }
  const hostsUsed = new Set(tabs.map((t) => t.host));
  log(`participants on ${tabs.map((t) => t.host).join(', ')}`);
  check(hostsUsed.size >= 2, `all three participants are on ${[...hostsUsed].join(', ')}; expected at least two hosts`);
  check(new Set(tabs.map((t) => t.token)).size === tabs.length, 'two participants share a session token');

  // ---- b. The admin page on h1: every host, and each participant's session under its own host. ----
  const admin = await context.newPage();
  const adminLog = recordPage(admin, path.join(env.artifacts, 'cluster-admin-console.log'));
  const adminResponse = await admin.goto(`${base}h1/admin`, { waitUntil: 'load', timeout: 20_000 });
  check(adminResponse && adminResponse.status() === 200, `GET /h1/admin answered HTTP ${adminResponse?.status()}`);
  const listed = (view) => tabs.every((t) => view.find((h) => h.id === t.host)?.live
    .some((s) => s.token === t.token && s.uid === t.uid));
  const view = await poll('the Cluster view to list every host reachable and the three sessions', ADMIN_TIMEOUT_MS,
                          250, async () => {
    const hosts = await clusterState(admin);
    return hosts && hosts.length === HOSTS && hosts.every((h) => h.reachable) && listed(hosts) ? hosts : null;
  });
  log(`Cluster view: ${JSON.stringify(view.map((h) => [h.id, h.reachable, h.live.map((s) => s.uid)]))}`);
  check(JSON.stringify(view.map((h) => h.id).sort()) === JSON.stringify([...cluster.hosts.keys()].sort()),
        `the Cluster view lists ${view.map((h) => h.id).join(', ')}`);
  const tables = await clusterTables(admin);
  check(tables.shown, 'the Cluster section is hidden');
  for (const id of cluster.hosts.keys()) {
    const row = tables.hosts.find((r) => r[0].text === id);
    check(row && row[1].text === 'up', `the Cluster hosts table shows ${id} as ${JSON.stringify(row?.[1].text)}`);
  }
  for (const tab of tabs) {
    check(tables.sessions.some((r) => r[0].text === tab.host && r[2].text === tab.uid),
          `the Cluster sessions table has no row of ${tab.uid} under ${tab.host}`);
  }
  check(tables.sessions.length === tabs.length, `the Cluster sessions table has ${tables.sessions.length} rows`);
  await admin.screenshot({ path: path.join(env.artifacts, 'cluster_admin.png'), fullPage: true });

  // ---- c. kill -9 one participant's host (not h1, which serves the admin page). ----
  const victim = tabs.find((t) => t.host !== 'h1');
  const survivors = tabs.filter((t) => t.host !== victim.host);
  const pidFile = path.join(runDir, `${victim.host}.pid`);
  const victimPid = Number(fs.readFileSync(pidFile, 'utf8').trim());
  check(victimPid === cluster.hosts.get(victim.host).pid, `${pidFile} says ${victimPid}, the script printed ` +
        `${cluster.hosts.get(victim.host).pid}`);
  const before = new Map();
  for (const tab of survivors) {
    check((await snapshot(tab.page, 'before-kill')).ok, `${tab.uid}'s canvas has no picture before the kill`);
    before.set(tab, tab.frames);
  }
  log(`SIGKILL to ${victim.host}'s manager (pid ${victimPid}), the host of ${victim.uid}`);
  process.kill(victimPid, 'SIGKILL');

  const lost = await poll(`${victim.uid}'s page to say "Session lost"`, LOST_TIMEOUT_MS, 200, async () => {
    const state = await pageState(victim.page);
    const panel = await panelText(victim.page);
    return state.sessionState === 'lost' && state.lastDisconnect?.final && panel.shown &&
           panel.title === 'Session lost' && LOST_WORDS.test(panel.detail) ? { state, panel } : null;
  });
  log(`${victim.uid}: "${lost.panel.title}: ${lost.panel.detail}" (lastDisconnect.kind ` +
      `${lost.state.lastDisconnect.kind}, sessionState ${lost.state.sessionState})`);
  check(lost.state.lastDisconnect.sessionState === 'lost',
        `${victim.uid}'s lastDisconnect.sessionState is ${lost.state.lastDisconnect.sessionState}`);
  await victim.page.screenshot({ path: path.join(env.artifacts, 'cluster_lost.png') });

  for (const tab of survivors) {
    await poll(`${tab.uid} on ${tab.host} to keep receiving pictures`, FRAMES_TIMEOUT_MS, 250, async () => {
      const state = await pageState(tab.page);
      check(state.connected && !state.lastDisconnect && !state.reconnecting,
            `${tab.uid}'s page lost its connection: ${JSON.stringify(state.lastDisconnect ?? state.lastLoss)}`);
      if (tab.frames < before.get(tab) + MIN_NEW_FRAMES || !(await snapshot(tab.page, 'after-kill')).ok) {
        return false;
      }
      return (await changedFraction(tab.page, 'before-kill', 'after-kill', 0)) > 0;
    });
    log(`${tab.uid} on ${tab.host}: ${tab.frames - before.get(tab)} WebSocket messages since the kill, the picture ` +
        'moved');
  }

  const down = await poll(`the Cluster view to mark ${victim.host} unreachable`, ADMIN_TIMEOUT_MS, 250, async () => {
    const hosts = await clusterState(admin);
    const tables = await clusterTables(admin);
    const row = tables.hosts.find((r) => r[0].text === victim.host);
    return hosts && hosts.find((h) => h.id === victim.host)?.reachable === false && row &&
           row[1].className === 'unreachable' && /^unreachable/.test(row[1].text) ? { hosts, tables } : null;
  });
  log(`Cluster view after the kill: ${JSON.stringify(down.tables.hosts.map((r) => r.map((c) => c.text)))}`);
  for (const tab of survivors) {
    check(down.hosts.find((h) => h.id === tab.host)?.reachable, `the Cluster view marks ${tab.host} unreachable too`);
    check(down.tables.sessions.some((r) => r[0].text === tab.host && r[2].text === tab.uid),
          `after the kill the Cluster sessions table has no row of ${tab.uid} under ${tab.host}`);
  }
  await admin.screenshot({ path: path.join(env.artifacts, 'cluster_admin_down.png'), fullPage: true });

  const pageErrors = [...tabs.flatMap((t) => t.log.pageErrors), ...adminLog.pageErrors];
  check(pageErrors.length === 0, `uncaught errors in the pages: ${pageErrors.join('; ')}`);
  await Promise.all([...tabs.map((t) => t.log.close()), adminLog.close()]);

  // ---- d. SIGTERM stops the script and everything it started. ----
  const started = [...[...cluster.hosts.values()].map((h) => h.pid), cluster.haproxyPid];
  log('SIGTERM to the cluster script');
  cluster.child.kill('SIGTERM');
  const exit = await Promise.race([cluster.exited, sleep(SCRIPT_EXIT_TIMEOUT_MS).then(() => null)]);
  check(exit !== null, `the script did not exit within ${SCRIPT_EXIT_TIMEOUT_MS} ms of SIGTERM`);
  log(`the script exited: code ${exit.code}, signal ${exit.signal}`);
  const left = started.filter(running);
  check(left.length === 0, `still running after the script stopped: pid(s) ${left.join(', ')}`);
}

runTest('e2e_cluster', 180, main);
