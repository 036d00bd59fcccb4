// SPDX-License-Identifier: GPL-2.0-or-later
// Browser end-to-end test: each shipped scenario (warehouse, lab) loads in sim_rfb and shows in a real Chromium;
// the warehouse's people move the picture with no input, and the two scenes look different.
//
// Usage: node e2e_scenes.mjs SIM_RFB ARTIFACTS_DIR [WEB_DIR]
//   SIM_RFB        the sim_rfb executable to start (once per scenario)
//   ARTIFACTS_DIR  where screenshots (scene_<name>.png, scene_<name>_canvas.png), the thumbnails and numbers
//                  (scenes.json), the simulators' output and the browser console are written (created)
//   WEB_DIR        the source web/ folder whose node_modules holds playwright-core (default: ../../web from here)
// Environment: RFBSIM_CHROMIUM (default /usr/bin/chromium), RFBSIM_E2E_TIMEOUT_S (default 120).
// Exits 0 when every check passed, 1 on the first failed check, 2 on the overall timeout.

import fs from 'node:fs';
import path from 'node:path';

import * as e2e from './e2e_support.mjs';

// ---------------------------------------------------------------------------------------------------------------
// Settings. Each threshold sits far from both what the shipped scenes measure and what a failure gives; the
// measurements (llvmpipe, JPEG quality 80, default start poses, 1280x720) are in the comments.
// ---------------------------------------------------------------------------------------------------------------
const SIM_WIDTH = 1280;                // framebuffer size asked of sim_rfb, pixels
const SIM_HEIGHT = 720;
const SETTLE_MS = 1000;                // after the first picture, let the rest of the first frames arrive
const MIN_COLOURS = 200;               // distinct colours among every 7th pixel (both scenes: 1000+, the cap)
const MIN_LUMA_RANGE = 100;            // max - min luma, 0..255 (warehouse 248-255, lab 243-254; flat: 0)
const MOTION_WINDOW_MS = 8000;         // the warehouse picture must change within this, with no input
// Share of pixels changed by the warehouse's people with no input. Measured 18-30 % against the first look at
// 1..9 s after it, 4-29 % between looks 0.9 s apart; a frozen picture changes 0 % (unchanged tiles are not
// sent again).
const MIN_MOTION_FRACTION = 0.01;
const DRIFT_MS = 2000;                 // the lab's second look, to log how much it varies by itself
const THUMB_COLS = 32;                 // greyscale thumbnail of each scene, cells (40x40 pixel blocks)
const THUMB_ROWS = 18;
// Median over the thumbnail cells of |warehouse - lab|, luma 0..255. The median, not the mean: people walking
// close past the camera change a few cells a lot, the scene behind them changes most cells. Measured over
// looks 0.9 s apart for 10 s (five runs, the lab seen from inside its door and from the corridor): warehouse vs
// lab 24.9-46.3 (first looks 33-38), one scene against itself at most 2.9. The mean separates them far less
// well: 37.7-53.9 against up to 28.5.
const MIN_SCENE_DIFFERENCE = 10;
// people: the count status.json must report; checkMotion: the people must change the picture with no input
// (the warehouse has several in view from the start; the lab's one pedestrian may be out of view).
const SCENES = [
  { name: 'warehouse', people: 15, checkMotion: true },
  { name: 'lab', people: 1, checkMotion: false },
];
const env = e2e.parseArgs('e2e_scenes.mjs');

// How far apart two thumbnails are: { median, mean } of the cells' absolute differences, luma 0..255.
function thumbnailDifference(a, b) {
  e2e.check(a && b && a.length === b.length, 'thumbnails missing or of different sizes');
  const cells = a.map((value, i) => Math.abs(value - b[i])).sort((x, y) => x - y);
  return { median: cells[cells.length >> 1], mean: cells.reduce((sum, d) => sum + d, 0) / cells.length };
}

const formatDifference = (d) => `median ${d.median.toFixed(2)}, mean ${d.mean.toFixed(2)}`;

// ---------------------------------------------------------------------------------------------------------------
// One scene: start its simulator, check status.json, show it in a new page, keep screenshots and a thumbnail.
// ---------------------------------------------------------------------------------------------------------------
async function showScene(context, scene) {
  const { name } = scene;

  // The simulator loads the scenario and reports its people and robot.
  const sim = await e2e.startSim(env, `sim_rfb-${name}`, [
    '--scenario', name, '--port', '0', '--width', String(SIM_WIDTH), '--height', String(SIM_HEIGHT)]);
  const status0 = await e2e.firstStatus(sim);
  e2e.log(`${name} status.json: ${JSON.stringify(status0)}`);
  e2e.check(status0.people === scene.people,
            `${name}: status.json reports ${status0.people} people, expected ${scene.people}`);
  const robot = status0.robot;
  e2e.check(robot && Number.isFinite(robot.x) && Number.isFinite(robot.y),
            `${name}: status.json reports no robot with a numeric x / y: ${JSON.stringify(robot)}`);

  // A new page connects and shows a full-size picture with content.
  const page = await context.newPage();
  const recorder = e2e.recordPage(page, path.join(env.artifacts, `scene_${name}_browser-console.log`));
  await e2e.openPage(page, sim.url);
  await e2e.waitForConnection(page);
  await e2e.waitForPicture(page, `${name}-first`);
  await e2e.sleep(SETTLE_MS);
  const picture = await e2e.snapshot(page, name);
  e2e.check(picture.ok, `${name}: canvas unreadable: ${picture.why}`);
  e2e.log(`${name}: canvas ${picture.width}x${picture.height}, ${picture.colours}+ colours, ` +
          `luma range ${picture.lumaRange.toFixed(0)}`);
  e2e.check(picture.width === SIM_WIDTH && picture.height === SIM_HEIGHT,
            `${name}: canvas is ${picture.width}x${picture.height}, expected ${SIM_WIDTH}x${SIM_HEIGHT}`);
  e2e.check(picture.colours >= MIN_COLOURS,
            `${name}: the picture has only ${picture.colours} colours (need >= ${MIN_COLOURS})`);
  e2e.check(picture.lumaRange >= MIN_LUMA_RANGE,
            `${name}: the picture's luma range is ${picture.lumaRange.toFixed(0)} (need >= ${MIN_LUMA_RANGE})`);
  await page.screenshot({ path: path.join(env.artifacts, `scene_${name}.png`) });
  await e2e.saveCanvasPng(page, path.join(env.artifacts, `scene_${name}_canvas.png`));
  const thumb = await e2e.thumbnail(page, name, THUMB_COLS, THUMB_ROWS);

  // With no input at all, the scene goes on by itself: the tick advances, and in the warehouse people walk
  // through the view. The second look also measures how much a scene's thumbnail varies by itself.
  const tick0 = status0.tick;
  let motion = null;
  if (scene.checkMotion) {
    motion = await e2e.poll(`the ${name} picture to change with no input`, MOTION_WINDOW_MS, 250, async () => {
      await e2e.snapshot(page, `${name}-later`);
      const fraction = await e2e.changedFraction(page, name, `${name}-later`, e2e.PIXEL_CHANGE_THRESHOLD);
      return fraction >= MIN_MOTION_FRACTION ? fraction : null;
    });
    e2e.log(`${name}: ${(100 * motion).toFixed(2)} % of the pixels changed with no input ` +
            `(need >= ${(100 * MIN_MOTION_FRACTION).toFixed(2)} %)`);
  } else {
    await e2e.sleep(DRIFT_MS);
    await e2e.snapshot(page, `${name}-later`);
  }
  const laterFraction = await e2e.changedFraction(page, name, `${name}-later`, e2e.PIXEL_CHANGE_THRESHOLD);
  const drift = thumbnailDifference(thumb, await e2e.thumbnail(page, `${name}-later`, THUMB_COLS, THUMB_ROWS));
  const status1 = await e2e.getStatus(sim);
  e2e.log(`${name}: tick ${tick0} -> ${status1.tick}; second look: ${(100 * laterFraction).toFixed(2)} % pixels ` +
          `changed, thumbnail drift ${formatDifference(drift)}`);
  e2e.check(status1.tick > tick0, `${name}: status.json's tick did not advance (${tick0} -> ${status1.tick})`);

  // SIGTERM ends the simulator cleanly; the page made no errors.
  await e2e.stopSimCleanly(sim);
  e2e.check(recorder.pageErrors.length === 0,
            `${name}: uncaught errors in the page: ${recorder.pageErrors.join(' | ')}`);
  await page.close();
  await recorder.close();
  return { name, status: status0, picture, motion, laterFraction, drift, thumbnail: thumb };
}

// ---------------------------------------------------------------------------------------------------------------
// The test.
// ---------------------------------------------------------------------------------------------------------------
async function main() {
  const chromium = e2e.prepare(env);
  const context = await e2e.launchBrowser(chromium, { width: SIM_WIDTH, height: SIM_HEIGHT });

  const results = {};
  for (const scene of SCENES) {
    results[scene.name] = await showScene(context, scene);
  }

  // The two scenes look different: a test that loaded one scene twice fails here.
  const difference = thumbnailDifference(results.warehouse.thumbnail, results.lab.thumbnail);
  const report = { thumbnailSize: [THUMB_COLS, THUMB_ROWS], difference, scenes: results };
  fs.writeFileSync(path.join(env.artifacts, 'scenes.json'), JSON.stringify(report, null, 1));
  e2e.log(`warehouse vs lab thumbnails: ${formatDifference(difference)} (need median >= ${MIN_SCENE_DIFFERENCE})`);
  e2e.check(difference.median >= MIN_SCENE_DIFFERENCE,
            'the warehouse and the lab look alike: was one scene loaded twice?');
  e2e.log('screenshots: scene_warehouse.png, scene_lab.png (+ *_canvas.png), numbers in scenes.json');
}

await e2e.runTest('browser_e2e_scenes', 120, main);
