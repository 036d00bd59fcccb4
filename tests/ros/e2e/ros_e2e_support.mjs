// SPDX-License-Identifier: GPL-2.0-or-later
// Shared parts of the ROS end-to-end tests (tests/ros/e2e/*_test.mjs, label ros): their arguments, the npm
// packages they load from web/node_modules, sim_rfb processes (started, their stdout lines awaited, stopped
// with a signal), the session's recorded files (docs/data.md) and a small rosbridge v2 client over `ws`.
//
// Every test takes the same arguments, SIM_RFB NODE_MODULES ARTIFACTS_DIR, and ends through runTest, which
// kills whatever is left and exits 0 (passed), 1 (a check failed) or 2 (the test's own time limit).

import { spawn } from 'node:child_process';
import fs from 'node:fs';
import { createRequire } from 'node:module';
import path from 'node:path';

// ---------------------------------------------------------------------------------------------------------------
// Progress and failure.
// ---------------------------------------------------------------------------------------------------------------
const startedAt = Date.now();

/// Prints one progress line with the seconds since the test started.
export function log(message) {
  console.log(`[ros ${((Date.now() - startedAt) / 1000).toFixed(1).padStart(5)}s] ${message}`);
}

/// A check that did not hold: reported as `FAIL: message`, without a stack.
export class CheckFailed extends Error {}

/// Throws CheckFailed(message) unless `condition` holds.
export function check(condition, message) {
  if (!condition) throw new CheckFailed(message);
}

/// Resolves after `ms` milliseconds.
export const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

/// Resolves with fn()'s first truthy value, trying every intervalMs; CheckFailed naming `what` after timeoutMs.
export async function poll(what, timeoutMs, intervalMs, fn) {
  const deadline = Date.now() + timeoutMs;
  for (;;) {
    const value = await fn();
    if (value) return value;
    if (Date.now() >= deadline) throw new CheckFailed(`timed out after ${timeoutMs} ms waiting for ${what}`);
    await sleep(intervalMs);
  }
}

// ---------------------------------------------------------------------------------------------------------------
// Arguments and packages.
// ---------------------------------------------------------------------------------------------------------------

/// Reads SIM_RFB NODE_MODULES ARTIFACTS_DIR; returns { simPath, nodeModules, artifacts, require } where
/// artifacts is this test's own folder (emptied first) and require loads packages from NODE_MODULES.
export function parseArgs(testName) {
  const [simPath, nodeModules, artifactsRoot] = process.argv.slice(2);
  if (!simPath || !nodeModules || !artifactsRoot) {
    console.error(`usage: node ${testName}_test.mjs SIM_RFB NODE_MODULES ARTIFACTS_DIR`);
    process.exit(1);
  }
  check(fs.existsSync(simPath), `sim_rfb not found at ${simPath}`);
  const artifacts = path.resolve(artifactsRoot, testName);
  fs.rmSync(artifacts, { recursive: true, force: true });
  fs.mkdirSync(artifacts, { recursive: true });
  // Resolving from a file beside node_modules finds the packages there (ES imports ignore NODE_PATH).
  const fromWeb = createRequire(path.join(path.resolve(nodeModules), '..', 'package.json'));
  const require = (name) => {
    try {
      return fromWeb(name);
    } catch (err) {
      throw new CheckFailed(`cannot load ${name} from ${nodeModules} (run: npm ci --prefix web): ${err.message}`);
    }
  };
  return { simPath, nodeModules: path.resolve(nodeModules), artifacts, require };
}

// ---------------------------------------------------------------------------------------------------------------
// sim_rfb.
// ---------------------------------------------------------------------------------------------------------------
const running = new Set();  // every child still alive, killed by runTest at the end
const cleanups = new Set(); // closers of sockets and servers, run by runTest at the end

/// Registers `fn` to run when the test ends, whatever the outcome.
export function atEnd(fn) {
  cleanups.add(fn);
}

/// One sim_rfb process: its output goes to ARTIFACTS/<name>.log; stdout lines can be awaited.
export class Sim {
  /// Starts `simPath args` and resolves once it printed its ready line (`sim_rfb ready: ...`).
  static async start(simPath, args, logDir, name, readyTimeoutMs = 30_000) {
    const sim = new Sim(simPath, args, path.join(logDir, `${name}.log`), name);
    await sim.waitLine(/^sim_rfb ready: /, readyTimeoutMs);
    return sim;
  }

  constructor(simPath, args, logPath, name) {
    log(`starting ${name}: ${path.basename(simPath)} ${args.join(' ')}`);
    this.name = name;
    this.lines = [];    // every stdout line so far
    this.waiters = [];  // { regex, resolve } for waitLine
    this.logFile = fs.openSync(logPath, 'w');
    this.child = spawn(simPath, args, { stdio: ['ignore', 'pipe', 'pipe'] });
    running.add(this.child);
    this.exit = new Promise((resolve) => {
      this.child.on('exit', (code, signal) => {
        running.delete(this.child);
        this.exited = { code, signal };
        resolve(this.exited);
      });
      this.child.on('error', (err) => {
        running.delete(this.child);
        this.exited = { code: null, signal: null, error: err.message };
        resolve(this.exited);
      });
    });
    // 'close' follows 'exit' once both pipes are drained: then the log holds the last line.
    this.closed = new Promise((resolve) => this.child.on('close', resolve));
    let partial = '';
    this.child.stdout.on('data', (chunk) => {
      fs.writeSync(this.logFile, chunk);
      partial += chunk.toString('utf8');
      const lines = partial.split('\n');
      partial = lines.pop();
      for (const line of lines) this.online(line);
    });
    this.child.stderr.on('data', (chunk) => fs.writeSync(this.logFile, chunk));
  }

  online(line) {
    this.lines.push(line);
    this.waiters = this.waiters.filter((w) => {
      const match = w.regex.exec(line);
      if (match) w.resolve(match);
      return !match;
    });
  }

  /// Resolves with the regex match of the first stdout line (printed so far or later) that matches.
  async waitLine(regex, timeoutMs) {
    for (const line of this.lines) {
      const match = regex.exec(line);
      if (match) return match;
    }
    let timer;
    const found = new Promise((resolve) => this.waiters.push({ regex, resolve }));
    const failed = new Promise((_, reject) => {
      timer = setTimeout(() => reject(new CheckFailed(`${this.name}: no stdout line matching ${regex} within ` +
                                                      `${timeoutMs} ms (see ${this.name}.log)`)), timeoutMs);
    });
    const died = this.exit.then((e) => {
      throw new CheckFailed(`${this.name} exited (${JSON.stringify(e)}) before printing ${regex} ` +
                            `(see ${this.name}.log)`);
    });
    try {
      return await Promise.race([found, failed, died]);
    } finally {
      clearTimeout(timer);
    }
  }

  /// The rosbridge server's URL from the `sim_rfb rosbridge: ws://...` line.
  async rosbridgeUrl(timeoutMs = 5000) {
    return (await this.waitLine(/^sim_rfb rosbridge: (ws:\/\/\S+)/, timeoutMs))[1];
  }

  /// Whether the process is still running.
  get alive() {
    return this.exited === undefined;
  }

  /// Sends `signal` and resolves with { code, signal } once it exited; SIGKILL after timeoutMs.
  async stop(signal = 'SIGTERM', timeoutMs = 10_000) {
    if (this.alive) this.child.kill(signal);
    let timer;
    const late = new Promise((resolve) => {
      timer = setTimeout(() => {
        this.child.kill('SIGKILL');
        resolve(null);
      }, timeoutMs);
    });
    const done = await Promise.race([this.exit, late]);
    clearTimeout(timer);
    await this.closed;
    if (this.logFile !== null) fs.closeSync(this.logFile);
    this.logFile = null;
    check(done !== null, `${this.name} did not exit within ${timeoutMs} ms of ${signal}`);
    return done;
  }

  /// Stops it with SIGTERM and checks that it exited 0 (a clean end writes the bag's summary).
  async stopCleanly() {
    const e = await this.stop('SIGTERM');
    check(e.code === 0, `${this.name} exited with ${JSON.stringify(e)} after SIGTERM, expected 0`);
  }
}

// ---------------------------------------------------------------------------------------------------------------
// The session's files (docs/data.md).
// ---------------------------------------------------------------------------------------------------------------

// The whole lines of a file; a last line without its newline is a write cut short and left out.
function wholeLines(file) {
  if (!fs.existsSync(file)) return [];
  const lines = fs.readFileSync(file, 'utf8').split('\n');
  lines.pop();
  return lines;
}

/// trajectories.csv's rows as { tick, time, kind, id, x, y, yaw, vx, vy } (numbers but kind).
export function readTrajectories(dir) {
  const [header, ...rows] = wholeLines(path.join(dir, 'trajectories.csv'));
  if (header === undefined) return [];
  check(header === 'tick,time,kind,id,x,y,yaw,vx,vy', `${dir}/trajectories.csv: unexpected header '${header}'`);
  return rows.map((line) => {
    const [tick, time, kind, id, x, y, yaw, vx, vy] = line.split(',');
    return { tick: Number(tick), time: Number(time), kind, id: Number(id), x: Number(x), y: Number(y),
             yaw: Number(yaw), vx: Number(vx), vy: Number(vy) };
  });
}

/// events.jsonl's lines, parsed.
export function readEvents(dir) {
  return wholeLines(path.join(dir, 'events.jsonl')).map((line) => JSON.parse(line));
}

/// The robot's rows of trajectories.csv, in tick order.
export function robotRows(dir) {
  return readTrajectories(dir).filter((row) => row.kind === 'robot');
}

/// The difference of two angles, wrapped to (-pi, pi].
export function angleDiff(a, b) {
  let d = (a - b) % (2 * Math.PI);
  if (d > Math.PI) d -= 2 * Math.PI;
  if (d <= -Math.PI) d += 2 * Math.PI;
  return d;
}

// ---------------------------------------------------------------------------------------------------------------
// A rosbridge v2 client (JSON ops over a WebSocket).
// ---------------------------------------------------------------------------------------------------------------

/// One WebSocket to a rosbridge server: every op received is kept in `received`, in order, so that a test
/// waits for what it needs without racing the socket.
export class Rosbridge {
  /// Connects to `url` with the `ws` package's WebSocket class.
  static async connect(WebSocket, url, name, timeoutMs = 5000) {
    const bridge = new Rosbridge(new WebSocket(url, { maxPayload: 64 << 20 }), name);
    await Promise.race([
      new Promise((resolve, reject) => {
        bridge.ws.once('open', resolve);
        bridge.ws.once('error', reject);
      }),
      sleep(timeoutMs).then(() => {
        throw new CheckFailed(`${name}: no connection to ${url} within ${timeoutMs} ms`);
      }),
    ]);
    return bridge;
  }

  constructor(ws, name) {
    this.ws = ws;
    this.name = name;
    this.received = [];
    this.waiters = new Set();
    this.closed = new Promise((resolve) => ws.on('close', (code, reason) => resolve({ code, reason: `${reason}` })));
    ws.on('error', () => {});  // a refused or reset socket shows as 'close'
    this.badFrames = [];  // frames that were not a JSON object: rosbridge v2 sends only those
    ws.on('message', (data, isBinary) => {
      let op = null;
      try {
        op = isBinary ? null : JSON.parse(data.toString('utf8'));
      } catch {
        // kept below
      }
      if (op === null || typeof op !== 'object') {
        this.badFrames.push(data.toString('utf8').slice(0, 200));
        return;
      }
      op.receivedAt = Date.now();
      this.received.push(op);
      for (const waiter of this.waiters) waiter();
    });
    atEnd(() => ws.terminate());
  }

  /// Sends an op (an object) as JSON.
  send(op) {
    this.ws.send(JSON.stringify(op));
  }

  /// Sends raw text (for malformed input).
  sendText(text) {
    this.ws.send(text);
  }

  /// The index the next received op will have: pass it to waitFor to see only what comes after now.
  mark() {
    return this.received.length;
  }

  /// Resolves with the first op at index >= from that satisfies `predicate`; CheckFailed naming `what` after
  /// timeoutMs.
  async waitFor(what, predicate, timeoutMs = 5000, from = 0) {
    let index = from;
    const scan = () => {
      for (; index < this.received.length; ++index) {
        if (predicate(this.received[index])) return this.received[index];
      }
      return null;
    };
    const now = scan();
    if (now) return now;
    let waiter;
    let timer;
    try {
      return await new Promise((resolve, reject) => {
        waiter = () => {
          const found = scan();
          if (found) resolve(found);
        };
        this.waiters.add(waiter);
        timer = setTimeout(() => reject(new CheckFailed(`${this.name}: no ${what} within ${timeoutMs} ms`)),
                           timeoutMs);
      });
    } finally {
      this.waiters.delete(waiter);
      clearTimeout(timer);
    }
  }

  /// The first publish on `topic` at index >= from.
  waitForPublish(topic, timeoutMs = 5000, from = 0) {
    return this.waitFor(`publish on ${topic}`, (op) => op.op === 'publish' && op.topic === topic, timeoutMs, from);
  }

  /// The first status op of `level` at index >= from.
  waitForStatus(level, timeoutMs = 5000, from = 0) {
    return this.waitFor(`${level} status`, (op) => op.op === 'status' && op.level === level, timeoutMs, from);
  }

  /// Every status op received so far at index >= from, of `level` when given.
  statuses(level = null, from = 0) {
    return this.received.slice(from).filter((op) => op.op === 'status' && (level === null || op.level === level));
  }
}

// ---------------------------------------------------------------------------------------------------------------
// The test's frame.
// ---------------------------------------------------------------------------------------------------------------

/// Runs `body`, prints PASS or FAIL, kills every sim_rfb left and closes every socket, and exits 0, 1 or 2
/// (2: still running after limitMs).
export async function runTest(name, limitMs, body) {
  let code = 0;
  const limit = setTimeout(() => {
    console.log(`FAIL: ${name} still running after ${limitMs} ms`);
    finish(2);
  }, limitMs);
  try {
    await body();
    console.log(`PASS: ${name}`);
  } catch (err) {
    code = 1;
    console.log(err instanceof CheckFailed ? `FAIL: ${err.message}` : `FAIL: ${err.stack || err}`);
  }
  clearTimeout(limit);
  finish(code);
}

function finish(code) {
  for (const fn of cleanups) {
    try {
      fn();
    } catch {
      // closing what is already gone
    }
  }
  for (const child of running) child.kill('SIGKILL');
  process.exit(code);
}
