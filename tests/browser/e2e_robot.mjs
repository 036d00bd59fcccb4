// SPDX-License-Identifier: GPL-2.0-or-later
// Browser end-to-end test: in the warehouse the robot sets off for its goal and crosses toward it (status.json),
// and sim_rfb --debug-overlay draws its planned path in the page; the same scene without the flag shows no such
// path.
//
// Usage: node e2e_robot.mjs SIM_RFB ARTIFACTS_DIR [WEB_DIR]
//   SIM_RFB        the sim_rfb executable to start (twice: with and without --debug-overlay)
//   ARTIFACTS_DIR  where screenshots (robot_overlay.png, robot_no_overlay.png, each + _canvas.png), the numbers
//                  (robot.json), the simulators' output and the browser console are written (created)
//   WEB_DIR        the source web/ folder whose node_modules holds playwright-core (default: ../../web from here)
// Environment: RFBSIM_CHROMIUM (default /usr/bin/chromium), RFBSIM_E2E_TIMEOUT_S (default 120).
// Exits 0 when every check passed, 1 on the first failed check, 2 on the overall timeout.

import fs from 'node:fs';
import path from 'node:path';

import * as e2e from './e2e_support.mjs';

// ---------------------------------------------------------------------------------------------------------------
// Settings. Each threshold sits far from both what the warehouse measures and what a failure gives; the
// measurements (llvmpipe, JPEG quality 80, seed 1, default start poses, 1280x720) are in the comments.
// ---------------------------------------------------------------------------------------------------------------
const SIM_WIDTH = 1280;                // framebuffer size asked of sim_rfb, pixels
const SIM_HEIGHT = 720;
const SIM_ARGS = ['--scenario', 'warehouse', '--port', '0', '--width', String(SIM_WIDTH),
                  '--height', String(SIM_HEIGHT)];
// The warehouse's robot starts at north_middle and its mission sends it to the participant's start, the dock,
// where the camera stands behind the avatar looking north: the robot comes toward the camera.
const ROBOT_START = { x: 10, y: 27.8 };
const DOCK = { x: 10, y: 2.8 };
const START_TOLERANCE_M = 1;           // the first status.json's robot is this close to ROBOT_START (it is exact)
const MOVING_TIMEOUT_MS = 10_000;      // the robot reports "moving" within this (it does after 0.02 s)
// Over MOTION_WINDOW_S of simulated time from the start, the robot moves at least MIN_MOVED_M (straight line)
// and ends at least MIN_CLOSER_M closer to the dock. It drives at 0.3 m/s: it first swerves east round the
// shelving, then heads south down the aisle; both were reached after 8.5-9.0 s, both about 5.7 m by 20 s. A robot
// that never plans, stands still or drives away fails. Simulated time runs at about wall time here;
// MOTION_WALL_TIMEOUT_MS only bounds a simulator that slows down.
const MOTION_WINDOW_S = 20;
const MIN_MOVED_M = 2;
const MIN_CLOSER_M = 2;
const MOTION_WALL_TIMEOUT_MS = 30_000;
const POLL_MS = 500;                   // status.json and the canvas are looked at this often
// The global path's ribbon (path_color 0.1, 0.75, 0.3) comes out on the canvas as about (0-31, 224-255, 64-95)
// in its middle, (60-100, 185-220, 95-125) on its JPEG-blurred edges. The scene's other greens stay out: goods
// boxes (0x5a8a4a) render about (100-127, 160-191, 64-95), the green shirt (0x4f8f4a: g 143, g - r 64
// before shading) is as far off, the teal shirt has g = b. So a "path green" pixel has a high green well above
// its red and blue.
const PATH_GREEN = { minG: 180, minGminusR: 100, minGminusB: 70 };
// Path-green pixels on the canvas, looked at every POLL_MS over the same simulated time in both runs. With the
// overlay the 5 cm ribbon runs from behind the middle shelving down the aisle to the goal disc at the avatar's
// feet, partly hidden by the avatar and the people: measured medians 946-974 over 14-15 looks (single looks
// 698-980; eight runs). Without it: 0 in every look (the loosest colour test tried, g - r >= 40 and
// g - b >= 20, still finds 1100-2100 there, on goods and shirts). The median with the overlay (a person passing
// the camera may hide the ribbon for a moment) and the maximum without it are checked: >= 6x apart.
const MIN_OVERLAY_GREEN = 300;
const MAX_PLAIN_GREEN = 50;
const env = e2e.parseArgs('e2e_robot.mjs');

const distance = (a, b) => Math.hypot(a.x - b.x, a.y - b.y);
const formatXY = (p) => `(${p.x.toFixed(2)}, ${p.y.toFixed(2)})`;
const median = (values) => [...values].sort((a, b) => a - b)[values.length >> 1];

function robotOf(status, what) {
  const robot = status && status.robot;
  e2e.check(robot && Number.isFinite(robot.x) && Number.isFinite(robot.y) && typeof robot.state === 'string',
            `${what}: status.json reports no robot with a numeric x / y and a state: ${JSON.stringify(status)}`);
  return robot;
}

// How many pixels of a stored snapshot are path green, and the box around them (null when none).
function countPathGreen(page, name) {
  return page.evaluate(({ name, minG, minGminusR, minGminusB }) => {
    const image = window.__e2eSnapshots[name];
    const d = image.data;
    let count = 0;
    let box = null;
    for (let i = 0; i < d.length; i += 4) {
      const g = d[i + 1];
      if (g >= minG && g - d[i] >= minGminusR && g - d[i + 2] >= minGminusB) {
        count += 1;
        const x = (i >> 2) % image.width;
        const y = Math.floor((i >> 2) / image.width);
        box = box ? { x0: Math.min(box.x0, x), y0: Math.min(box.y0, y), x1: Math.max(box.x1, x),
                      y1: Math.max(box.y1, y) } : { x0: x, y0: y, x1: x, y1: y };
      }
    }
    return { count, box };
  }, { name, ...PATH_GREEN });
}

// Looks at the canvas once: a fresh snapshot (under one name, so they do not pile up) and its path-green count.
async function lookForPath(page, tag) {
  const s = await e2e.snapshot(page, `${tag}-look`);
  e2e.check(s.ok, `${tag}: canvas unreadable: ${s.why}`);
  return (await countPathGreen(page, `${tag}-look`)).count;
}

// ---------------------------------------------------------------------------------------------------------------
// One run: start sim_rfb and check its robot (startRun), show the warehouse in a new page (showRun), keep
// screenshots and stop (closeRun). A run is { sim, status, page, recorder }.
// ---------------------------------------------------------------------------------------------------------------
async function startRun(tag, extraArgs) {
  const sim = await e2e.startSim(env, `sim_rfb-robot-${tag}`, [...SIM_ARGS, ...extraArgs]);
  const status = await e2e.firstStatus(sim);
  e2e.log(`${tag} status.json: ${JSON.stringify(status)}`);
  const robot = robotOf(status, tag);
  e2e.check(distance(robot, ROBOT_START) <= START_TOLERANCE_M,
            `${tag}: the robot starts at ${formatXY(robot)}, not near north_middle ${formatXY(ROBOT_START)}`);
  return { sim, status };
}

async function showRun(context, run, tag) {
  const { sim } = run;
  const page = await context.newPage();
  const recorder = e2e.recordPage(page, path.join(env.artifacts, `robot_${tag}_browser-console.log`));
  await e2e.openPage(page, sim.url);
  await e2e.waitForConnection(page);
  const picture = await e2e.waitForPicture(page, `${tag}-first`);
  e2e.check(picture.width === SIM_WIDTH && picture.height === SIM_HEIGHT,
            `${tag}: canvas is ${picture.width}x${picture.height}, expected ${SIM_WIDTH}x${SIM_HEIGHT}`);
  run.page = page;
  run.recorder = recorder;
}

// Keeps the page's screenshot and its canvas, stops the simulator cleanly, checks the page made no errors.
async function closeRun(run, tag) {
  await run.page.screenshot({ path: path.join(env.artifacts, `robot_${tag}.png`) });
  await e2e.saveCanvasPng(run.page, path.join(env.artifacts, `robot_${tag}_canvas.png`));
  await e2e.stopSimCleanly(run.sim);
  e2e.check(run.recorder.pageErrors.length === 0,
            `${tag}: uncaught errors in the page: ${run.recorder.pageErrors.join(' | ')}`);
  await run.page.close();
  await run.recorder.close();
}

// ---------------------------------------------------------------------------------------------------------------
// With the overlay: the robot sets off, crosses toward the dock, and its path shows in green.
// ---------------------------------------------------------------------------------------------------------------
async function overlayRun(context) {
  const tag = 'overlay';
  const run = await startRun(tag, ['--debug-overlay']);
  const start = robotOf(run.status, tag);
  const startTime = run.status.time;
  const startToDock = distance(start, DOCK);

  // The navigation stack plans and the robot drives off.
  const moving = await e2e.poll('the robot to report state "moving"', MOVING_TIMEOUT_MS, 100, async () => {
    const status = await e2e.getStatus(run.sim);
    const robot = robotOf(status, tag);
    e2e.check(robot.state !== 'failed', `the robot's navigation failed: ${JSON.stringify(robot)}`);
    return robot.state === 'moving' ? status : null;
  });
  e2e.log(`robot moving at ${moving.time.toFixed(2)} s simulated, at ${formatXY(moving.robot)}`);
  await showRun(context, run, tag);

  // It crosses toward the dock within MOTION_WINDOW_S simulated; the canvas is looked at on the way.
  const greens = [];
  const crossed = await e2e.poll(`the robot to move ${MIN_MOVED_M} m and come ${MIN_CLOSER_M} m closer to the dock`,
                                 MOTION_WALL_TIMEOUT_MS, POLL_MS, async () => {
    greens.push(await lookForPath(run.page, tag));
    const status = await e2e.getStatus(run.sim);
    const robot = robotOf(status, tag);
    const moved = distance(robot, start);
    const closer = startToDock - distance(robot, DOCK);
    const elapsed = status.time - startTime;
    e2e.check(robot.state !== 'failed', `the robot's navigation failed: ${JSON.stringify(robot)}`);
    e2e.check(elapsed <= MOTION_WINDOW_S,
              `after ${elapsed.toFixed(1)} s simulated the robot at ${formatXY(robot)} (${robot.state}) moved only ` +
              `${moved.toFixed(2)} m and came ${closer.toFixed(2)} m closer to the dock (need ${MIN_MOVED_M} m ` +
              `and ${MIN_CLOSER_M} m within ${MOTION_WINDOW_S} s)`);
    return moved >= MIN_MOVED_M && closer >= MIN_CLOSER_M ? { status, robot, moved, closer, elapsed } : null;
  });
  e2e.log(`robot at ${formatXY(crossed.robot)} (${crossed.robot.state}) after ${crossed.elapsed.toFixed(2)} s ` +
          `simulated: moved ${crossed.moved.toFixed(2)} m, ${crossed.closer.toFixed(2)} m closer to the dock ` +
          `(need ${MIN_MOVED_M} m and ${MIN_CLOSER_M} m)`);

  // The planned path shows in green.
  const last = await countPathGreen(run.page, `${tag}-look`);
  e2e.log(`${tag}: path-green pixels over ${greens.length} looks: median ${median(greens)}, min ` +
          `${Math.min(...greens)}, max ${Math.max(...greens)}; last look ${last.count} within ` +
          `${JSON.stringify(last.box)} (need median >= ${MIN_OVERLAY_GREEN})`);
  e2e.check(median(greens) >= MIN_OVERLAY_GREEN,
            `with --debug-overlay the canvas shows a median of only ${median(greens)} path-green pixels ` +
            `(need >= ${MIN_OVERLAY_GREEN}): is the global path drawn?`);
  await closeRun(run, tag);
  return { start, moving: moving.robot, movingTime: moving.time, crossed, greens, until: crossed.status.time };
}

// ---------------------------------------------------------------------------------------------------------------
// Without the overlay: the same scene over the same simulated time has next to no path green.
// ---------------------------------------------------------------------------------------------------------------
async function plainRun(context, until) {
  const tag = 'no_overlay';
  const run = await startRun(tag, []);
  await showRun(context, run, tag);
  const greens = [];
  const status = await e2e.poll(`${tag} to reach ${until.toFixed(1)} s simulated`, MOTION_WALL_TIMEOUT_MS,
                                POLL_MS, async () => {
    greens.push(await lookForPath(run.page, tag));
    const s = await e2e.getStatus(run.sim);
    return s.time >= until ? s : null;
  });
  e2e.log(`${tag}: path-green pixels over ${greens.length} looks up to ${status.time.toFixed(2)} s simulated: ` +
          `median ${median(greens)}, max ${Math.max(...greens)} (need max <= ${MAX_PLAIN_GREEN})`);
  e2e.check(Math.max(...greens) <= MAX_PLAIN_GREEN,
            `without --debug-overlay the canvas shows up to ${Math.max(...greens)} path-green pixels ` +
            `(need <= ${MAX_PLAIN_GREEN}): the colour test does not single out the overlay`);
  await closeRun(run, tag);
  return { greens, robot: status.robot };
}

// ---------------------------------------------------------------------------------------------------------------
// The test.
// ---------------------------------------------------------------------------------------------------------------
async function main() {
  const chromium = e2e.prepare(env);
  const context = await e2e.launchBrowser(chromium, { width: SIM_WIDTH, height: SIM_HEIGHT });

  const overlay = await overlayRun(context);
  const plain = await plainRun(context, overlay.until);
  const report = { pathGreen: PATH_GREEN, overlay, noOverlay: plain };
  fs.writeFileSync(path.join(env.artifacts, 'robot.json'), JSON.stringify(report, null, 1));
  e2e.log('screenshots: robot_overlay.png, robot_no_overlay.png (+ *_canvas.png), numbers in robot.json');
}

await e2e.runTest('browser_e2e_robot', 120, main);
