// SPDX-License-Identifier: GPL-2.0-or-later
// Shared parts of the browser end-to-end tests (e2e_walk.mjs, e2e_scenes.mjs, e2e_robot.mjs, e2e_manager.mjs):
// progress and failure, sim_rfb (or sim_manager) processes, a headless Chromium on the participant page (or the
// browser of browser_driver.mjs), canvas pixels, and cleanup whatever happens.
//
// The sim_rfb tests take the same arguments (SIM_RFB ARTIFACTS_DIR [WEB_DIR], see parseArgs); e2e_manager.mjs
// reads its own. Every test ends through runTest, which always stops what was started and exits 0 (passed),
// 1 (a check failed) or 2 (overall timeout).

import { spawn } from 'node:child_process';
import fs from 'node:fs';
import http from 'node:http';
import { createRequire } from 'node:module';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));

// ---------------------------------------------------------------------------------------------------------------
// Settings shared by every test.
// ---------------------------------------------------------------------------------------------------------------
export const READY_TIMEOUT_MS = 30_000;   // sim_rfb must print its ready line within this
export const EXIT_TIMEOUT_MS = 10_000;    // sim_rfb must exit this soon after SIGTERM
export const PIXEL_CHANGE_THRESHOLD = 48; // |dR| + |dG| + |dB| above this counts as a changed pixel
export const CHROMIUM = process.env.RFBSIM_CHROMIUM || '/usr/bin/chromium';
const CHROMIUM_ARGS = [
  '--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
  '--disable-background-networking', '--disable-component-update', '--disable-sync',
];

// ---------------------------------------------------------------------------------------------------------------
// Progress and failure.
// ---------------------------------------------------------------------------------------------------------------
const t0 = Date.now();

// Prints one progress line with the seconds since the test started.
export function log(message) {
  const seconds = ((Date.now() - t0) / 1000).toFixed(1).padStart(5);
  console.log(`[e2e ${seconds}s] ${message}`);
}

// A check that did not hold: reported as `FAIL: message`, without a stack.
export class CheckFailed extends Error {}

export function check(condition, message) {
  if (!condition) {
    throw new CheckFailed(message);
  }
}

export const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

// /proc/PID/stat as { pid, comm, state, ppid, pgrp, start }, or null when there is no such process.
export function procInfo(pid) {
  let stat;
  try {
    stat = fs.readFileSync(`/proc/${pid}/stat`, 'utf8');
  } catch {
    return null;
  }
  const close = stat.lastIndexOf(')');
  const fields = stat.slice(close + 2).split(' ');
  return { pid, comm: stat.slice(stat.indexOf('(') + 1, close), state: fields[0], ppid: Number(fields[1]),
           pgrp: Number(fields[2]), start: fields[19] };
}

// The processes whose parent is ppid, from /proc: procInfo objects.
export function childrenOf(ppid) {
  const out = [];
  for (const entry of fs.readdirSync('/proc')) {
    if (!/^\d+$/.test(entry)) {
      continue;
    }
    const info = procInfo(Number(entry));
    if (info && info.ppid === ppid) {
      out.push(info);
    }
  }
  return out;
}

const STREAM_END_TIMEOUT_MS = 2000;   // a log file gets this long to be written out when it is closed

// Ends a write stream and resolves once what was written reached the file (or it failed, or after
// STREAM_END_TIMEOUT_MS). Calling it again is harmless and waits the same way.
function endStream(stream) {
  return new Promise((resolve) => {
    const timer = setTimeout(resolve, STREAM_END_TIMEOUT_MS);
    stream.end(() => {
      clearTimeout(timer);
      resolve();
    });
  });
}

// Writes to a log stream unless it was closed already (late output after cleanup must not throw).
function writeLog(stream, data) {
  if (!stream.writableEnded) {
    stream.write(data);
  }
}

// Resolves with fn()'s first truthy value, polling every intervalMs; throws CheckFailed after timeoutMs.
// A CheckFailed thrown by fn ends the wait at once; other errors (a refused fetch, say) are retried.
export async function poll(what, timeoutMs, intervalMs, fn) {
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
// Arguments: [--browser chromium|firefox] SIM_RFB ARTIFACTS_DIR [WEB_DIR]. Prints the usage and exits 1 when they
// are missing.
// ---------------------------------------------------------------------------------------------------------------

// The command line's arguments without `--browser NAME`, and NAME (default chromium; null if not one we drive).
function takeBrowserOption() {
  const args = process.argv.slice(2);
  let browser = 'chromium';
  const option = args.indexOf('--browser');
  if (option !== -1) {
    browser = args[option + 1];
    args.splice(option, 2);
  }
  return { args, browser: ['chromium', 'firefox'].includes(browser) ? browser : null };
}

// Returns { browser, simPath, artifacts, webDir } with absolute artifacts and webDir (default: ../../web from
// here). Arguments: [--browser chromium|firefox] SIM_RFB ARTIFACTS_DIR [WEB_DIR]; only the tests that run in
// either browser (browser_driver.mjs) read `browser`.
export function parseArgs(scriptName) {
  const { args, browser } = takeBrowserOption();
  const [simPath, artifactsArg, webArg] = args;
  if (!simPath || !artifactsArg || !browser) {
    console.error(`usage: node ${scriptName} [--browser chromium|firefox] SIM_RFB ARTIFACTS_DIR [WEB_DIR]`);
    process.exit(1);
  }
  return {
    browser,
    simPath,
    artifacts: path.resolve(artifactsArg),
    webDir: path.resolve(webArg || path.join(here, '..', '..', 'web')),
  };
}

// The arguments of the sim_manager tests: [--browser chromium|firefox] SIM_MANAGER SIM_RFB WEB_ROOT ARTIFACTS_DIR
// [WEB_DIR]. Returns { browser, simPath (sim_manager: what startSim starts), simRfbPath, webRoot, artifacts,
// webDir }, paths absolute. Only the tests that run in either browser (browser_driver.mjs) read `browser`.
export function parseManagerArgs(scriptName) {
  const { args, browser } = takeBrowserOption();
  const [managerPath, simRfbPath, webRoot, artifactsArg, webArg] = args;
  if (!managerPath || !simRfbPath || !webRoot || !artifactsArg || !browser) {
    console.error(`usage: node ${scriptName} [--browser chromium|firefox] SIM_MANAGER SIM_RFB WEB_ROOT ` +
                  'ARTIFACTS_DIR [WEB_DIR]');
    process.exit(1);
  }
  return {
    browser,
    simPath: managerPath,
    simRfbPath: path.resolve(simRfbPath),
    webRoot: path.resolve(webRoot),
    artifacts: path.resolve(artifactsArg),
    webDir: path.resolve(webArg || path.join(here, '..', '..', 'web')),
  };
}

// Checks that the simulator (env.simPath) exists and creates the artifacts folder.
export function prepareRun(env) {
  check(fs.existsSync(env.simPath), `sim_rfb not found at ${env.simPath}`);
  fs.mkdirSync(env.artifacts, { recursive: true });
  log(`artifacts go to ${env.artifacts}`);
}

// Checks that sim_rfb and Chromium exist, creates the artifacts folder, and returns playwright's chromium.
export function prepare(env) {
  prepareRun(env);
  check(fs.existsSync(CHROMIUM), `Chromium not found at ${CHROMIUM}`);

  // playwright-core lives in web/node_modules (NODE_PATH does not reach ES module imports).
  try {
    return createRequire(path.join(env.webDir, 'package.json'))('playwright-core').chromium;
  } catch (err) {
    throw new CheckFailed(`cannot load playwright-core from ${env.webDir}/node_modules ` +
                          `(run: npm ci --prefix ${env.webDir}): ${err.message}`);
  }
}

// ---------------------------------------------------------------------------------------------------------------
// The simulator process: start, wait for the ready line, stop.
// ---------------------------------------------------------------------------------------------------------------
const sims = [];   // every sim_rfb started, for cleanup

// Starts env.simPath with args (its output goes to ARTIFACTS/<name>.log) and resolves with the sim
// { name, child, url, exited, ... } once it printed its ready line.
export function startSim(env, name, args) {
  log(`starting ${name}: ${env.simPath} ${args.join(' ')}`);
  const logPath = path.join(env.artifacts, `${name}.log`);
  const logFile = fs.createWriteStream(logPath);
  const child = spawn(env.simPath, args, { stdio: ['ignore', 'pipe', 'pipe'] });
  const sim = { name, child, exited: null, logFile, logPath, tail: [] };
  sims.push(sim);

  const exited = new Promise((resolve) => {
    child.on('exit', (code, signal) => {
      sim.exited = { code, signal };
      resolve(sim.exited);
    });
  });
  sim.exitedPromise = exited;
  // 'close' comes after 'exit' once stdout and stderr are read to the end: the last lines are in the log then.
  sim.closedPromise = new Promise((resolve) => {
    child.on('close', resolve);
    child.on('error', resolve);
  });

  // Keep the last lines of output for failure messages; everything goes to the log file.
  const remember = (stream, label) => {
    let partial = '';
    stream.on('data', (chunk) => {
      writeLog(logFile, chunk);
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
      reject(new CheckFailed(`could not start ${env.simPath}: ${err.message}`));
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
export async function stopSim(sim, timeoutMs) {
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

// Stops the sim with SIGTERM and checks that it exited by itself with code 0.
export async function stopSimCleanly(sim) {
  const exit = await stopSim(sim, EXIT_TIMEOUT_MS);
  log(`${sim.name} exited: code ${exit.code}, signal ${exit.signal}`);
  check(exit.code === 0 && exit.signal === null,
        `${sim.name} did not exit with code 0 on SIGTERM (code ${exit.code}, signal ${exit.signal})`);
}

export async function getStatus(sim) {
  const response = await fetch(new URL('status.json', sim.url), { signal: AbortSignal.timeout(3000) });
  check(response.ok, `GET status.json answered HTTP ${response.status}`);
  return response.json();
}

// The first status.json with an avatar. It may be published a moment after the ready line, so allow a few
// seconds for it.
export function firstStatus(sim) {
  return poll(`status.json of ${sim.name} to report the avatar`, 5000, 100, async () => {
    const status = await getStatus(sim);
    return status && status.avatar ? status : null;
  });
}

// ---------------------------------------------------------------------------------------------------------------
// The browser: one per test, in a fresh profile, closed by cleanup (Chromium here; Firefox through
// browser_driver.mjs, which hands its browser to cleanup with adoptBrowser).
// ---------------------------------------------------------------------------------------------------------------
let browserClose = null;   // async: closes the browser politely (cleanup)
let browserKill = null;    // sync: kills what is left of it (the exit handler), or null where its library does
let userDataDir = null;
const consoleLogs = [];   // every log stream recordPage opened, for cleanup

// Makes a browser cleanup's to stop: close() (async) first, then its profile folder goes; kill() (sync, may be
// null) runs when the process ends without cleanup. Once per test, like launchBrowser, which uses it.
export function adoptBrowser({ profileDir, close, kill = null }) {
  if (userDataDir !== null) {
    throw new Error('a second browser in one test: a test has one browser; use the one it has');
  }
  userDataDir = profileDir;
  browserClose = close;
  browserKill = kill;
}

// Launches headless Chromium with a window of viewport { width, height } and resolves with its context.
// contextOptions: more of playwright's launchPersistentContext options (httpCredentials, say).
// Once per test: cleanup knows one browser, so a second call throws rather than leak the first and its profile.
export async function launchBrowser(chromium, viewport, contextOptions = {}) {
  if (userDataDir !== null) {
    throw new Error('launchBrowser called a second time: a test has one browser; use the context it returned');
  }
  const profileDir = fs.mkdtempSync(path.join(os.tmpdir(), 'rfbsim-e2e-chromium-'));
  let context = null;
  // Playwright kills the browser it launched when the process exits, so there is nothing to kill here.
  adoptBrowser({ profileDir, close: () => (context ? context.close() : Promise.resolve()) });
  log(`launching ${CHROMIUM}`);
  context = await chromium.launchPersistentContext(profileDir, {
    ...contextOptions,
    executablePath: CHROMIUM,
    headless: true,
    args: CHROMIUM_ARGS,
    viewport,
    timeout: 30_000,
    // runTest handles these: playwright's own SIGINT handler would exit 130 before cleanup stopped the sims.
    handleSIGINT: false,
    handleSIGTERM: false,
  });
  return context;
}

// What Firefox says, as a script error of the page, when a WebSocket cannot connect or is cut while it loads.
const FIREFOX_SOCKET_REPORT = new RegExp('^(Firefox can[\u2019\']t establish a connection to the server at wss?:' +
                                         '|The connection to wss?:\\S+ was interrupted while the page was loading)');

// Writes the page's console, uncaught errors, failed requests and HTTP errors to logPath. Returns
// { pageErrors, badResponses, cspReports, close() }: the lists fill as the page runs (cspReports: the browser's
// Content-Security-Policy refusals); close() resolves once the log is written out. Cleanup closes it too, if the
// test did not get that far. Works on a playwright and on a puppeteer page alike.
export function recordPage(page, logPath) {
  const consoleLog = fs.createWriteStream(logPath);
  consoleLogs.push(consoleLog);
  const write = (line) => writeLog(consoleLog, `${line}\n`);
  const pageErrors = [];
  const badResponses = [];
  const cspReports = [];
  page.on('console', (msg) => {
    write(`${msg.type()}: ${msg.text()}`);
    if (/Content[- ]Security[- ]Policy/i.test(msg.text())) {
      cspReports.push(msg.text());
    }
  });
  page.on('pageerror', (err) => {
    // Firefox reports a Content-Security-Policy refusal (a frame-ancestors one, say) as a script error of the page
    // that was refused, where Chromium logs it on the console: either way it is the browser refusing, which the
    // tests expect, not the page failing.
    if (/^Content-Security-Policy:/.test(err.message)) {
      cspReports.push(err.message);
      write(`error (CSP): ${err.message}`);
      return;
    }
    // The same for a WebSocket that could not connect or was cut (Chromium: "WebSocket connection to ... failed"
    // on the console): the page sees it as the socket's error and close events, which it handles.
    if (FIREFOX_SOCKET_REPORT.test(err.message)) {
      write(`error (network): ${err.message}`);
      return;
    }
    pageErrors.push(err.message);
    write(`pageerror: ${err.message}`);
  });
  page.on('requestfailed', (req) => write(`requestfailed: ${req.url()} ${req.failure()?.errorText}`));
  page.on('response', (res) => {
    if (res.status() >= 400) {
      badResponses.push(`${res.status()} ${res.url()}`);
      write(`response: HTTP ${res.status()} for ${res.url()}`);
    }
  });
  return { pageErrors, badResponses, cspReports, close: () => endStream(consoleLog) };
}

// window.rfbsimState as plain data (null before app.js set it).
export const pageState = (page) => page.evaluate(() => JSON.parse(JSON.stringify(window.rfbsimState || null)));

// Opens url and resolves with the page's first rfbsimState once app.js has started.
export async function openPage(page, url) {
  log(`opening ${url}`);
  const response = await page.goto(url, { waitUntil: 'load', timeout: 20_000 });
  check(response && response.ok(), `GET ${url} answered HTTP ${response && response.status()}`);
  const compatMode = await page.evaluate(() => document.compatMode);
  check(compatMode === 'CSS1Compat', `page renders in quirks mode (${compatMode})`);
  // app.js may still be evaluating when 'load' fires (seen with Chromium 156), so wait for its state object.
  return poll('app.js to start (window.rfbsimState)', 10_000, 100, () => pageState(page));
}

// Waits until noVNC reports the RFB session up; a disconnect on the way fails at once.
export async function waitForConnection(page) {
  await poll('the RFB connection (window.rfbsimState.connected)', 20_000, 200, async () => {
    const state = await pageState(page);
    check(state !== null, 'the page did not set window.rfbsimState (app.js not loaded?)');
    check(!state.lastDisconnect, `the page reports a disconnect: ${state.lastDisconnect?.message}`);
    return state.connected;
  });
  log('noVNC connected');
}

// ---------------------------------------------------------------------------------------------------------------
// Canvas pixels, compared inside the page (no megabytes through the protocol).
// ---------------------------------------------------------------------------------------------------------------

// Stores the canvas' pixels under `name` and returns simple statistics about them:
// { ok, width, height, lumaRange (0..255), colours (distinct among every 7th pixel, counted up to 1000) }.
export function snapshot(page, name) {
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

// Share of pixels (0..1) that differ by more than threshold between two stored snapshots; -1 if they do not
// both exist at the same size.
export function changedFraction(page, a, b, threshold) {
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

// A cols x rows greyscale thumbnail of a stored snapshot: each cell the mean luma (0..255) of its block of
// pixels, row by row. Returns null if the snapshot does not exist.
export function thumbnail(page, name, cols, rows) {
  return page.evaluate(({ name, cols, rows }) => {
    const image = window.__e2eSnapshots && window.__e2eSnapshots[name];
    if (!image) {
      return null;
    }
    const sums = new Array(cols * rows).fill(0);
    const counts = new Array(cols * rows).fill(0);
    const d = image.data;
    for (let y = 0; y < image.height; y += 1) {
      const row = Math.floor((y * rows) / image.height);
      for (let x = 0; x < image.width; x += 1) {
        const cell = row * cols + Math.floor((x * cols) / image.width);
        const i = 4 * (y * image.width + x);
        sums[cell] += (d[i] * 299 + d[i + 1] * 587 + d[i + 2] * 114) / 1000;
        counts[cell] += 1;
      }
    }
    return sums.map((sum, cell) => sum / counts[cell]);
  }, { name, cols, rows });
}

// Writes the canvas itself (unscaled, no overlays) as a PNG.
export async function saveCanvasPng(page, file) {
  const dataUrl = await page.evaluate(() => document.querySelector('#screen canvas').toDataURL('image/png'));
  fs.writeFileSync(file, Buffer.from(dataUrl.slice(dataUrl.indexOf(',') + 1), 'base64'));
}

// A picture with content: a real size and more than one colour. Resolves with its snapshot statistics.
export async function waitForPicture(page, name) {
  return poll(`a picture with content on the canvas (${name})`, 15_000, 250, async () => {
    const s = await snapshot(page, name);
    return s.ok && s.colours > 8 && s.lumaRange > 16 ? s : null;
  });
}

// ---------------------------------------------------------------------------------------------------------------
// Running a test: overall timeout, interruption, and cleanup always, once, whatever happened.
// ---------------------------------------------------------------------------------------------------------------
let cleanupPromise = null;
const cleanupHooks = [];   // onCleanup's functions

// Adds fn (sync or async) to what cleanup does once the browser is closed and the started processes are stopped:
// a test's own servers, or processes its processes started. Errors in fn are logged and otherwise ignored.
export function onCleanup(fn) {
  cleanupHooks.push(fn);
}

function cleanup() {
  if (cleanupPromise) {
    return cleanupPromise;
  }
  cleanupPromise = (async () => {
    if (browserClose) {
      await Promise.race([browserClose().catch(() => {}), sleep(10_000)]);
    }
    if (browserKill) {
      browserKill();   // whatever a close that failed or took too long left behind
    }
    const logsWritten = consoleLogs.map(endStream);
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
      // The sim's last lines may still be in its pipes after 'exit': read them into the log before it ends.
      await Promise.race([sim.closedPromise, sleep(STREAM_END_TIMEOUT_MS)]);
      logsWritten.push(endStream(sim.logFile));
    }
    for (const hook of cleanupHooks) {
      try {
        await hook();
      } catch (err) {
        log(`cleanup: ${err && err.message ? err.message : err}`);
      }
    }
    await Promise.all(logsWritten);
    if (userDataDir) {
      fs.rmSync(userDataDir, { recursive: true, force: true });
    }
  })();
  return cleanupPromise;
}

// Last resort when the process ends without cleanup (an uncaught error, EPIPE on a closed stdout): no simulator
// outlives it, and the browser profile goes. Only synchronous work is possible here.
process.on('exit', () => {
  for (const sim of sims) {
    if (!sim.exited) {
      sim.child.kill('SIGKILL');
    }
  }
  if (browserKill) {
    browserKill();
  }
  if (userDataDir) {
    fs.rmSync(userDataDir, { recursive: true, force: true });
  }
});

function printSimTails() {
  for (const sim of sims) {
    if (sim.tail.length > 0) {
      console.error(`--- last output of ${sim.name} (full log: ${sim.logPath}) ---`);
      console.error(sim.tail.join('\n'));
    }
  }
}

// The exit code of the first failure reported (null while none): it is the one printed and the one that stands.
let failureExitCode = null;

// Prints `FAIL: message` and the sims' last output for the first failure only. A later one (main failing because
// the watchdog's cleanup closed the browser under it, say) is only logged, as `message` without its stack.
function reportFailure(message, exitCode) {
  if (failureExitCode === null) {
    failureExitCode = exitCode;
    console.error(`FAIL: ${message}`);
    printSimTails();
  } else {
    log(`after the failure above: ${message.split('\n')[0]}`);
  }
}

// Runs main() under an overall timeout (RFBSIM_E2E_TIMEOUT_S, else defaultTimeoutS), prints PASS or FAIL,
// cleans up and exits the process: 0 passed, 1 a check failed or interrupted, 2 overall timeout.
// Starts a tiny HTTP server on a free loopback port, standing in for a survey site on its own origin: GET
// `pathname` answers the HTML that page(url) returns, anything else 404. Resolves with { server, origin };
// cleanup closes it.
export async function serveHtmlPage(name, pathname, page) {
  const server = http.createServer((req, res) => {
    const url = new URL(req.url, 'http://survey');
    if (url.pathname !== pathname) {
      res.writeHead(404, { 'Content-Type': 'text/plain' });
      res.end('not found\n');
      return;
    }
    res.writeHead(200, { 'Content-Type': 'text/html; charset=utf-8', 'Cache-Control': 'no-store' });
    res.end(page(url));
  });
  await new Promise((resolve, reject) => {
    server.once('error', reject);
    server.listen(0, '127.0.0.1', resolve);
  });
  onCleanup(() => new Promise((resolve) => {
    server.closeAllConnections();
    server.close(resolve);
  }));
  const origin = `http://127.0.0.1:${server.address().port}`;
  log(`${name} serves ${origin}${pathname}`);
  return { server, origin };
}

export async function runTest(testName, defaultTimeoutS, main) {
  const overallTimeoutMs = 1000 * Number(process.env.RFBSIM_E2E_TIMEOUT_S || defaultTimeoutS);
  const watchdog = setTimeout(() => {
    reportFailure(`overall timeout of ${overallTimeoutMs / 1000} s reached`, 2);
    const hardExit = setTimeout(() => process.exit(failureExitCode), 15_000);
    hardExit.unref();
    cleanup().finally(() => process.exit(failureExitCode));
  }, overallTimeoutMs);

  for (const signal of ['SIGINT', 'SIGTERM']) {
    process.on(signal, () => {
      reportFailure(`interrupted by ${signal}`, 1);
      cleanup().finally(() => process.exit(failureExitCode));
    });
  }

  try {
    await main();
    if (failureExitCode === null) {
      log(`PASS: ${testName}`);
    }
  } catch (err) {
    if (err instanceof CheckFailed) {
      reportFailure(err.message, 1);
    } else {
      reportFailure(`unexpected error: ${err && err.stack ? err.stack : err}`, 1);
    }
  } finally {
    await cleanup();
    clearTimeout(watchdog);
  }
  process.exit(failureExitCode ?? 0);
}
