// SPDX-License-Identifier: GPL-2.0-or-later
// bench_ros: what the ROS side costs (issue 20's targets), printed as tables. Timings only, no pass/fail.
//
// (a) The bag's CPU: sim_rfb in the warehouse (15 people) for --seconds of wall time with --data-dir, with
//     and without --no-mcap, --runs times each, alternated so that drift in the machine's load hits both
//     alike; first unwatched (nothing is rendered: the bag's share is largest), then watched by a Raw RFB
//     viewer (tests/ros/e2e/rfb_viewer.mjs), as a participant's session always is. CPU is the process's
//     utime + stime from /proc/<pid>/stat over those seconds (from 2 s after start-up to just before SIGTERM).
//     Prints each mode's median, the bag's share of the session's CPU (target < 5 %), and the sizes of
//     session.mcap beside trajectories.csv + events.jsonl, which it mirrors.
// (b) rosbridge latency: --robot-control external on loopback; on each /scan the client publishes a Twist
//     with a v of its own (alternating about 0.1 and 0.2, each distinct). From the scan's stamp: the tick it
//     was published in (the /clock before it on the socket), the tick the simulation took the command in
//     (events.jsonl's robot_command) and the tick the wheels were given it (session.mcap's /cmd_vel, whose
//     log time is that tick; rosbridge does not serve /cmd_vel to subscribers); and the wall time from the
//     scan's arrival to that tick's /clock. Median and max over --scans scans (target: <= 2 ticks plus the
//     round trip).
// (c) --abuse (alone; issue 31): the rosbridge port attacked while a Raw viewer watches the session and a
//     well-behaved rosbridge client listens to /clock, both from 127.0.0.1. Each attack runs against a fresh
//     sim_rfb for --abuse-seconds, from one source address (127.0.0.2) and from --abuse-addresses (127.0.1.x):
//     200 WebSockets held and reopened as they are refused; 10,000 subscribe ops a round on each connection the
//     server lets in; messages of 1 MiB (JSON's costliest shape), just over and of 16 MiB; subscribers that
//     never read. Prints, side by side: the viewer's frame rate and sim_rfb's VmRSS before, during and after,
//     sim_rfb's and this process's CPU during, the listener's /clock rate and longest gap during, how soon a
//     new client is served after, how long SIGTERM then takes, and what the attacker got
//     (tests/ros/e2e/rosbridge_abusers.mjs, run on a worker thread so that its work never delays the viewer's).
//
//   node bench/bench_ros.mjs SIM_RFB NODE_MODULES [--runs 3] [--seconds 20] [--scans 100] [--out DIR]
//   node bench/bench_ros.mjs SIM_RFB NODE_MODULES --abuse [--abuse-seconds 10] [--abuse-addresses 64] [--out DIR]
//   cmake --build build --target bench_ros      (or bench_ros_abuse)

import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import { createRequire } from 'node:module';
import os from 'node:os';
import path from 'node:path';
import { performance } from 'node:perf_hooks';

import { loadBagPackages, readStreamed, schemaDecoders } from '../tests/ros/e2e/ros_bag.mjs';
import { Rosbridge, Sim, sleep } from '../tests/ros/e2e/ros_e2e_support.mjs';
import { attackInWorker, rssMiB, sourceAddresses } from '../tests/ros/e2e/rosbridge_abusers.mjs';
import { watch } from '../tests/ros/e2e/rfb_viewer.mjs';

const TICK_HZ = 60;
const WARM_UP_MS = 2000;  // after the ready line, before CPU is counted
const VIEW_WIDTH = 640;   // the watched sessions' picture: Raw at 30 fps stays near 28 MB/s on loopback
const VIEW_HEIGHT = 360;

function parseOptions(argv) {
  const [simPath, nodeModules, ...rest] = argv;
  if (!simPath || !nodeModules) {
    console.error('usage: node bench_ros.mjs SIM_RFB NODE_MODULES [--runs N] [--seconds S] [--scans N] [--out DIR]\n' +
                  '       node bench_ros.mjs SIM_RFB NODE_MODULES --abuse [--abuse-seconds S] [--abuse-addresses N] ' +
                  '[--out DIR]');
    process.exit(2);
  }
  const options = { simPath, nodeModules: path.resolve(nodeModules), runs: 3, seconds: 20, scans: 100,
                    abuse: false, abuseSeconds: 10, abuseAddresses: 64,
                    out: path.join(os.tmpdir(), `bench_ros-${process.pid}`) };
  const numeric = { '--runs': 'runs', '--seconds': 'seconds', '--scans': 'scans', '--abuse-seconds': 'abuseSeconds',
                    '--abuse-addresses': 'abuseAddresses' };
  for (let i = 0; i < rest.length; i += 2) {
    const [flag, value] = [rest[i], rest[i + 1]];
    if (flag === '--abuse') {
      options.abuse = true;
      i -= 1;  // a flag without a value
    } else if (flag === '--out' && value) options.out = path.resolve(value);
    else if (numeric[flag] && Number(value) > 0) options[numeric[flag]] = Number(value);
    else {
      console.error(`bench_ros: bad option ${flag} ${value}`);
      process.exit(2);
    }
  }
  return options;
}

const median = (xs) => {
  const s = [...xs].sort((a, b) => a - b);
  return s.length % 2 ? s[(s.length - 1) / 2] : (s[s.length / 2 - 1] + s[s.length / 2]) / 2;
};
const fileSize = (file) => (fs.existsSync(file) ? fs.statSync(file).size : 0);
const kib = (bytes) => `${(bytes / 1024).toFixed(0)} KiB`;

// CPU seconds (user + system) the process has used, from /proc/<pid>/stat (fields 14 and 15, in clock ticks).
function cpuSeconds(pid, clockTicks) {
  const stat = fs.readFileSync(`/proc/${pid}/stat`, 'utf8');
  const fields = stat.slice(stat.lastIndexOf(')') + 2).split(' ');  // fields from the 3rd (state) on
  return (Number(fields[11]) + Number(fields[12])) / clockTicks;
}

// ---------------------------------------------------------------------------------------------------------------
// (a) The bag's CPU and size.
// ---------------------------------------------------------------------------------------------------------------
// One session for (a): its steady-state CPU over options.seconds, its sizes, and the frames a viewer got.
async function bagRun(options, clockTicks, mode, watched, run) {
  const name = `cpu-${watched ? 'watched' : 'unwatched'}-${mode}-${run}`;
  const dir = path.join(options.out, name);
  fs.rmSync(dir, { recursive: true, force: true });  // sim_rfb never overwrites a session
  const args = ['--scenario', 'warehouse', '--port', '0', '--rfb-only', '--data-dir', dir];
  if (watched) args.push('--width', String(VIEW_WIDTH), '--height', String(VIEW_HEIGHT));
  if (mode === 'none') args.push('--no-mcap');
  const sim = await Sim.start(options.simPath, args, options.out, name);
  let viewer = null;
  if (watched) {
    const [, host, port] = await sim.waitLine(/^sim_rfb ready: vnc:\/\/([\d.]+):(\d+)/, 1000);
    viewer = await watch(host, Number(port));
  }
  // Start-up (the scenario, EGL) is the same with or without the bag: measure the steady state after it.
  await sleep(WARM_UP_MS);
  const before = cpuSeconds(sim.child.pid, clockTicks);
  const framesBefore = viewer?.updates() ?? 0;
  await sleep(options.seconds * 1000);
  const cpu = cpuSeconds(sim.child.pid, clockTicks) - before;
  const fps = ((viewer?.updates() ?? 0) - framesBefore) / options.seconds;
  viewer?.stop();
  await sim.stopCleanly();
  const session = JSON.parse(fs.readFileSync(path.join(dir, 'session.json'), 'utf8'));
  return { cpu, fps, simSeconds: session.end_tick / TICK_HZ, mcap: fileSize(path.join(dir, 'session.mcap')),
           csv: fileSize(path.join(dir, 'trajectories.csv')), jsonl: fileSize(path.join(dir, 'events.jsonl')) };
}

async function benchBag(options, clockTicks) {
  console.log(`\n(a) session.mcap's cost: warehouse, 15 people, ${options.seconds} s of wall time after ` +
              `${WARM_UP_MS / 1000} s of start-up, ${options.runs} runs each, alternated; watched = a Raw viewer ` +
              `at ${VIEW_WIDTH}x${VIEW_HEIGHT} asking for every frame`);
  console.log('| session | bag | CPU s per run | median CPU s | % of one core | viewer fps | session.mcap | trajectories.csv + events.jsonl |');
  console.log('|---|---|---|---|---|---|---|---|');
  const shares = [];
  let sizes = null;
  for (const watched of [false, true]) {
    const results = { bag: [], none: [] };
    for (let run = 0; run < options.runs; ++run) {
      for (const mode of run % 2 === 0 ? ['bag', 'none'] : ['none', 'bag']) {
        results[mode].push(await bagRun(options, clockTicks, mode, watched, run));
      }
    }
    for (const mode of ['bag', 'none']) {
      const rs = results[mode];
      const cpu = median(rs.map((r) => r.cpu));
      const last = rs[rs.length - 1];
      console.log(`| ${watched ? 'watched' : 'unwatched'} | ${mode === 'bag' ? 'yes' : '--no-mcap'} | ` +
                  `${rs.map((r) => r.cpu.toFixed(2)).join(', ')} | ${cpu.toFixed(2)} | ` +
                  `${(100 * cpu / options.seconds).toFixed(1)} | ${median(rs.map((r) => r.fps)).toFixed(1)} | ` +
                  `${kib(last.mcap)} | ${kib(last.csv + last.jsonl)} |`);
    }
    const withBag = median(results.bag.map((r) => r.cpu));
    const without = median(results.none.map((r) => r.cpu));
    shares.push(`${watched ? 'watched' : 'unwatched'} ${(100 * (withBag - without) / withBag).toFixed(1)} % ` +
                `(${(1000 * (withBag - without) / options.seconds).toFixed(1)} ms of CPU per s)`);
    sizes ??= results.bag[results.bag.length - 1];
  }
  console.log(`the bag's share of the session's CPU (target < 5 %): ${shares.join(', ')}`);
  console.log(`session.mcap is ${(sizes.mcap / Math.max(1, sizes.csv + sizes.jsonl)).toFixed(1)} x trajectories.csv + ` +
              `events.jsonl: ${kib(sizes.mcap / Math.max(1, sizes.simSeconds) * 60)} per simulated minute`);
}

// ---------------------------------------------------------------------------------------------------------------
// (b) /scan -> the wheels, over rosbridge.
// ---------------------------------------------------------------------------------------------------------------

// The first message on `topic` in the finished bag for which `match(msg)` holds, for each key: Map key -> tick.
function bagTicks(pkgs, file, topic, keyOf) {
  const bag = readStreamed(pkgs, file);
  const decoders = schemaDecoders(pkgs, bag.schemas);
  const ticks = new Map();
  for (const m of bag.messages) {
    const channel = bag.channels.get(m.channelId);
    if (channel.topic !== topic) continue;
    const key = keyOf(decoders.get(channel.schemaId)(m.data));
    if (!ticks.has(key)) ticks.set(key, Math.round(Number(m.logTime) * TICK_HZ / 1e9));
  }
  return ticks;
}

async function benchLatency(options, require) {
  const dir = path.join(options.out, 'latency');
  fs.rmSync(dir, { recursive: true, force: true });
  const sim = await Sim.start(options.simPath, [
    '--scenario', 'warehouse', '--port', '0', '--rfb-only', '--crowd', '0', '--robot-start', 'cross_west',
    '--robot-control', 'external', '--rosbridge-port', '0', '--data-dir', dir,
  ], options.out, 'latency');
  const bridge = await Rosbridge.connect(require('ws'), await sim.rosbridgeUrl(), 'bench');
  const toTick = (stamp) => Math.round((stamp.sec + stamp.nanosec * 1e-9) * TICK_HZ);

  // Each scan answered at once with a v of its own; every /clock's arrival kept, to time ticks on the wall.
  const clockArrival = new Map();  // tick -> performance.now() when its /clock arrived
  const sent = new Map();          // v -> { scanTick (its stamp), publishTick, arrivedAt }
  let clockTick = -1;              // the tick of the last /clock: a tick's messages follow its /clock
  let k = 0;
  bridge.ws.on('message', (data) => {
    const op = JSON.parse(data.toString('utf8'));
    if (op.op !== 'publish') return;
    if (op.topic === '/clock') {
      clockTick = toTick(op.msg.clock);
      clockArrival.set(clockTick, performance.now());
    } else if (op.topic === '/scan' && k < options.scans) {
      k += 1;
      const v = Number(((k % 2 ? 0.1 : 0.2) + 0.0001 * k).toFixed(4));  // alternating, and each one distinct
      sent.set(v, { scanTick: toTick(op.msg.header.stamp), publishTick: clockTick, arrivedAt: performance.now() });
      bridge.send({ op: 'publish', topic: '/cmd_vel', msg: { linear: { x: v, y: 0, z: 0 }, angular: { x: 0, y: 0, z: 0 } } });
    }
  });
  bridge.send({ op: 'advertise', topic: '/cmd_vel', type: 'geometry_msgs/msg/Twist' });
  for (const topic of ['/clock', '/scan']) bridge.send({ op: 'subscribe', topic });
  const deadline = Date.now() + options.scans * 100 + 20_000;
  while (k < options.scans && Date.now() < deadline) await sleep(100);
  await sleep(500);
  await sim.stopCleanly();

  // When the simulation took each command in (events.jsonl) and when the wheels were given it (the bag's
  // /cmd_vel, published after the tick that applied it).
  const takenIn = new Map(fs.readFileSync(path.join(dir, 'events.jsonl'), 'utf8').split('\n').filter(Boolean)
    .map((line) => JSON.parse(line)).filter((e) => e.type === 'robot_command').map((e) => [e.v, e.tick]));
  const applied = bagTicks(loadBagPackages(require), path.join(dir, 'session.mcap'), '/cmd_vel', (msg) => msg.linear.x);
  const rows = [];
  for (const [v, { scanTick, publishTick, arrivedAt }] of sent) {
    const tick = applied.get(v);
    if (tick === undefined || !takenIn.has(v) || !clockArrival.has(tick)) continue;
    rows.push({ published: publishTick - scanTick, taken: takenIn.get(v) - scanTick, applied: tick - scanTick,
                wallMs: clockArrival.get(tick) - arrivedAt });
  }
  const line = (what, xs, unit = (x) => String(x)) => console.log(`| ${what} | ${unit(median(xs))} | ${unit(Math.max(...xs))} |`);
  console.log(`\n(b) /scan -> /cmd_vel -> wheels over rosbridge on loopback: ${rows.length} of ${k} scans traced, ` +
              'the client answering each scan at once');
  console.log('| ticks (1 tick = 16.7 ms simulated) from the scan\'s stamp | median | max |');
  console.log('|---|---|---|');
  line('to the tick the scan was published in (the /clock before it)', rows.map((r) => r.published));
  line('to the tick the command was taken in (events.jsonl robot_command)', rows.map((r) => r.taken));
  line('to the tick the wheels were given it (session.mcap /cmd_vel)', rows.map((r) => r.applied));
  line('wall ms from the scan\'s arrival to that tick\'s /clock', rows.map((r) => r.wallMs), (x) => x.toFixed(1));
}

// ---------------------------------------------------------------------------------------------------------------
// (c) The rosbridge port under abuse.
// ---------------------------------------------------------------------------------------------------------------

// Each attack: the function of rosbridge_abusers.mjs that runs it (on a worker thread), its options, and what the
// attacker got, from its stats.
const ATTACKS = {
  'none (baseline)': null,
  '200 connections, reopened': {
    fn: 'holdConnections', options: { count: 200, reopen: true },
    got: (s) => `${s.opened} let in and held (the listener has the 8th), ${s.refused} x HTTP ` +
                `${Object.keys(s.statuses).join('/') || '-'}, ${s.reset} closed at accept`,
  },
  '10,000 subscribes a round': {
    fn: 'floodSubscriptions', options: { connections: 7, rounds: Infinity },
    got: (s) => `${s.sent} subscribes on ${7 - s.refusedConnections} connections in ${s.rounds} rounds, ` +
                `${s.errors} refused with an error status`,
  },
  '1 MiB / just over / 16 MiB messages': {
    fn: 'sendLarge', options: { connections: 7 },
    got: (s) => `${s.atLimit} at 1 MiB (JSON objects), ${s.over} just over, ${s.farOver} of 16 MiB; ` +
                `closes seen ${JSON.stringify(s.closes)}`,
  },
  'never-reading subscribers': {
    fn: 'neverRead', options: { connections: 7, replies: 20_000 },
    got: (s) => `${s.accepted} subscribed to every topic (32 x /map) and asked for 20 MiB of replies each, ` +
                `never reading; ${s.refused} refused`,
  },
};

// Updates per second of `viewer` over the next `ms`, with sim_rfb's RSS sampled meanwhile ({ fps, rss: [] }).
async function sampleWindow(viewer, pid, ms) {
  const updates = viewer.updates();
  const rss = [rssMiB(pid)];
  const until = Date.now() + ms;
  while (Date.now() < until) {
    await sleep(Math.min(250, until - Date.now()));
    rss.push(rssMiB(pid));
  }
  return { fps: (viewer.updates() - updates) * 1000 / ms, rss };
}

// One attack from `sources` against a fresh sim_rfb: the row's numbers.
async function abuseRun(options, require, clockTicks, name, sources) {
  const WebSocket = require('ws');
  const label = `abuse-${Object.keys(ATTACKS).indexOf(name)}-${sources.length}`;
  const sim = await Sim.start(options.simPath, [
    '--scenario', 'warehouse', '--port', '0', '--rfb-only', '--rosbridge-port', '0',
    '--width', String(VIEW_WIDTH), '--height', String(VIEW_HEIGHT),
  ], options.out, label);
  const pid = sim.child.pid;
  const url = await sim.rosbridgeUrl();
  const [, host, port] = await sim.waitLine(/^sim_rfb ready: vnc:\/\/([\d.]+):(\d+)/, 1000);
  const viewer = await watch(host, Number(port));
  // The well-behaved listener, there before the attack (it holds one of the 8 connections).
  const listener = await Rosbridge.connect(WebSocket, url, 'listener');
  listener.send({ op: 'subscribe', topic: '/clock' });
  await sleep(WARM_UP_MS);
  const before = await sampleWindow(viewer, pid, 4000);

  // During: from the moment the attack runs (its worker has connected and sent its first ops).
  const spec = ATTACKS[name];
  const attack = spec ? await attackInWorker(spec.fn, url, options.nodeModules, { ...spec.options, sources }) : null;
  const cpuBefore = cpuSeconds(pid, clockTicks);
  const ownBefore = process.cpuUsage();
  const clocksBefore = listener.received.length;
  const during = await sampleWindow(viewer, pid, options.abuseSeconds * 1000);
  const clocks = listener.received.slice(clocksBefore).map((op) => op.receivedAt);
  const clockHz = clocks.length / options.abuseSeconds;
  // The listener's longest wait for a /clock (one network thread serves every client, the attacker too).
  const clockGapMs = clocks.length < 2 ? null : Math.max(...clocks.slice(1).map((t, i) => t - clocks[i]));
  const cpu = cpuSeconds(pid, clockTicks) - cpuBefore;
  const own = process.cpuUsage(ownBefore);
  const got = attack ? spec.got(await attack.stop()) : '';

  // After: a new client is served (time to its first /clock), then the session settles.
  const t0 = performance.now();
  let servedMs = null;
  try {
    const late = await Rosbridge.connect(WebSocket, url, 'late client');
    late.send({ op: 'subscribe', topic: '/clock' });
    await late.waitForPublish('/clock', 5000);
    servedMs = performance.now() - t0;
    late.ws.close();
  } catch {
    // left null: not served
  }
  await sleep(1000);
  const after = await sampleWindow(viewer, pid, 4000);
  const alive = sim.alive;
  viewer.stop();
  listener.ws.close();
  // How long SIGTERM takes: a network thread still busy with the attack holds the exit up.
  let stopMs = null;
  if (alive) {
    const stopping = performance.now();
    try {
      await sim.stop('SIGTERM');
      stopMs = performance.now() - stopping;
    } catch {
      // SIGKILLed after 10 s: left null
    }
  }
  return { before, during, after, clockHz, clockGapMs, servedMs, got, alive, stopMs,
           cpu: 100 * cpu / options.abuseSeconds, own: 100 * (own.user + own.system) / 1e6 / options.abuseSeconds };
}

async function benchAbuse(options, require, clockTicks) {
  const many = sourceAddresses(options.abuseAddresses);
  console.log(`\n(c) the rosbridge port under abuse: warehouse (15 people) at ${VIEW_WIDTH}x${VIEW_HEIGHT}, a Raw ` +
              `viewer and a /clock listener from 127.0.0.1; each attack ${options.abuseSeconds} s against a fresh ` +
              `sim_rfb, from 127.0.0.2 (one) or ${many.length} addresses from ${many[0]} (many); before and after: ` +
              '4 s windows');
  console.log('| attack | from | viewer fps before / during / after | sim_rfb RSS MiB before / peak during / after | ' +
              'sim_rfb CPU % | bench CPU % | listener /clock Hz, longest gap | new client served after | ' +
              'SIGTERM to exit | ' +
              'what the attacker got |');
  console.log('|---|---|---|---|--:|--:|--:|--:|--:|---|');
  const max = (xs) => Math.max(...xs.filter(Number.isFinite));
  const last = (xs) => xs[xs.length - 1];
  for (const name of Object.keys(ATTACKS)) {
    for (const sources of name.startsWith('none') ? [['127.0.0.2']] : [['127.0.0.2'], many]) {
      const r = await abuseRun(options, require, clockTicks, name, sources);
      console.log(`| ${name} | ${name.startsWith('none') ? '-' : sources.length === 1 ? 'one' : 'many'} | ` +
                  `${r.before.fps.toFixed(1)} / ${r.during.fps.toFixed(1)} / ${r.after.fps.toFixed(1)} | ` +
                  `${last(r.before.rss).toFixed(1)} / ${max(r.during.rss).toFixed(1)} / ` +
                  `${last(r.after.rss).toFixed(1)} | ` +
                  `${r.cpu.toFixed(0)} | ${r.own.toFixed(0)} | ` +
                  `${r.clockHz.toFixed(1)}, ${r.clockGapMs === null ? '-' : `${r.clockGapMs.toFixed(0)} ms`} | ` +
                  `${r.servedMs === null ? 'not in 5 s' : `${r.servedMs.toFixed(0)} ms`} | ` +
                  `${r.stopMs === null ? 'killed after 10 s' : `${r.stopMs.toFixed(0)} ms`} | ` +
                  `${r.alive ? '' : 'sim_rfb DIED; '}${r.got} |`);
    }
  }
}

const options = parseOptions(process.argv.slice(2));
const require = createRequire(path.join(options.nodeModules, '..', 'package.json'));
fs.mkdirSync(options.out, { recursive: true });
let clockTicks = 100;
try {
  clockTicks = Number(execFileSync('getconf', ['CLK_TCK']).toString().trim()) || 100;
} catch {
  // Linux's usual value
}
console.log(`bench_ros on ${os.cpus().length} CPUs (${os.cpus()[0]?.model ?? 'unknown'}), load ` +
            `${os.loadavg().map((x) => x.toFixed(2)).join(' ')}, node ${process.version}; sim_rfb ${options.simPath}; ` +
            `sessions in ${options.out}`);
if (options.abuse) {
  await benchAbuse(options, require, clockTicks);
} else {
  await benchLatency(options, require);
  await benchBag(options, clockTicks);
}
process.exit(0);
