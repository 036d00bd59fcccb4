// SPDX-License-Identifier: GPL-2.0-or-later
// What a browser is streamed under sim_rfb --codec auto (the default sim_manager passes on): the participant page on
// sim_rfb's own server, walking, with each viewer's encoding, quality, quality level and frame rate from sim_rfb's
// /status.json logged once a second. Only logs: the codec and the quality a browser ends on are the adaptive
// streaming's decisions, which tests of their own pin; this records them where another browser runs.

import fs from 'node:fs';

import {
  getStatus, log, openPage, recordPage, sleep, startSim, stopSimCleanly, waitForConnection, waitForPicture,
} from './e2e_support.mjs';

// /status.json readings, one a second. 8 keep the test short; RFBSIM_E2E_AUTO_CODEC_S=30 (say) watches longer,
// for whoever studies the adaptive streaming (in one 30 s walk Firefox moved from Tight to H.264 after 24 s).
const SAMPLES = Math.max(3, Number(process.env.RFBSIM_E2E_AUTO_CODEC_S) || 8);
const WALK_FROM_SAMPLE = 2; // W is held from this reading to the last: a moving picture, as a participant's is

// One viewer's stream as a short text: "tight q 80 (level 0), 24.0 fps, rtt 3.1 ms".
function describeStream(s) {
  const quality = s.quality === undefined ? 'lossless' : `q ${s.quality} (level ${s.quality_level})`;
  return `${s.encoding} ${quality}, ${s.fps} fps, rtt ${s.last_rtt_ms} ms`;
}

// Starts sim_rfb (env.simRfbPath) with --codec auto in the lab, opens its page in a new tab of browser (a
// browser_driver.mjs launch), holds W for the later readings, logs every reading and writes them all to jsonPath
// ({ browser, samples: [{ at_s, streams }] }); then closes the tab and stops sim_rfb.
export async function logAutoCodecStream(env, driver, browser, jsonPath) {
  const sim = await startSim({ ...env, simPath: env.simRfbPath }, `${driver.name}_auto_codec_sim_rfb`,
                             ['--port', '0', '--codec', 'auto', '--scenario', 'lab']);
  const tab = await browser.newPage();
  const tabLog = recordPage(tab, jsonPath.replace(/\.json$/, '-console.log'));
  await openPage(tab, sim.url);
  await waitForConnection(tab);
  await waitForPicture(tab, 'auto');
  await driver.click(tab, '#screen canvas');
  const samples = [];
  const started = Date.now();
  try {
    for (let i = 0; i < SAMPLES; i += 1) {
      if (i === WALK_FROM_SAMPLE) {
        await tab.keyboard.down('w');
      }
      await sleep(1000);
      const streams = (await getStatus(sim)).streams || [];
      samples.push({ at_s: (Date.now() - started) / 1000, streams });
      log(`--codec auto in ${driver.name}, ${samples.at(-1).at_s.toFixed(1)} s` +
          `${i >= WALK_FROM_SAMPLE ? ' (walking)' : ''}: ${streams.map(describeStream).join('; ') || 'no viewer'}`);
    }
  } finally {
    await tab.keyboard.up('w').catch(() => {});
  }
  const state = await tab.evaluate(() => ({ h264Offered: window.rfbsimState?.h264Offered ?? null }));
  const last = samples.at(-1)?.streams[0];
  log(`--codec auto in ${driver.name} ended on ${last ? describeStream(last) : 'no stream'}; the page ` +
      `${state.h264Offered ? 'offered' : 'did not offer'} H.264`);
  fs.writeFileSync(jsonPath, `${JSON.stringify({ browser: driver.name, h264Offered: state.h264Offered, samples },
                                               null, 2)}\n`);
  await tab.close();
  await tabLog.close();
  await stopSimCleanly(sim);
}
