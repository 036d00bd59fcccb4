// SPDX-License-Identifier: GPL-2.0-or-later
// bench_network's browser row: a noVNC page in a headless browser, walking and turning, counting the pictures it
// shows. bench_network starts sim_rfb and a LinkEmulator in front of it and runs this script with the emulator's
// URL; the script prints one line `BENCH_RESULT {json}` and exits 0, or prints `BENCH_ERROR message` and exits 1.
//
// Usage: node bench_network_browser.mjs --url URL --web-dir DIR [--browser chromium|firefox]
//            [--page bundled|novnc13] [--warm-up-ms N] [--measure-ms N] [--presses N] [--threshold MAD]
//            [--chromium PATH] [--firefox PATH]
//   --url         the page, e.g. http://127.0.0.1:PORT/ (a secure context: noVNC 1.7 offers H.264 there)
//   --web-dir     the source web/ folder whose node_modules holds playwright-core and puppeteer-core
//   --browser     chromium (playwright-core) or firefox (Debian's firefox-esr through puppeteer-core, WebDriver BiDi)
//   --page        bundled: our participant page; novnc13: Debian's stock noVNC 1.3 vnc.html (its own canvas, no
//                 rfbsimState: the first picture is its canvas sized and connected)
//   --rtt-ms      the link's round trip: pictures sooner after a press cannot show it (they become its reference)
//   --trace 1     also print `BENCH_TRACE [[ms, MAD], ...] per press` (to check the threshold)
//
// In the page (installed once the first picture shows):
//   - every animation frame, the canvas is drawn into a 320x180 probe (area-averaged) and read back; a probe
//     that differs from the previous one in any byte is one more picture shown (noVNC draws a whole update at
//     once; two updates inside one animation frame, 1/60 s, count as one, so this can only undercount);
//   - WebSocket bytes received are counted through a Proxy on the WebSocket constructor, installed before the
//     page's scripts run;
//   - a press: the probe at the 'd' keydown (seen by a capture listener before noVNC's) is the reference, moved
//     up to the last picture within --rtt-ms of it, and the first later probe whose mean absolute difference
//     from it passes --threshold ends it (performance.now() in that animation frame - the keydown's timeStamp).
// Outside: W held from the first picture on; D for 300 ms about every second at a random phase, never before
// the previous turn showed in full; the measured window starts after the warm-up.

import path from 'node:path';
import { createRequire } from 'node:module';

const args = Object.fromEntries(process.argv.slice(2).reduce((pairs, arg, i, all) => {
  if (arg.startsWith('--')) pairs.push([arg.slice(2), all[i + 1]]);
  return pairs;
}, []));
const URL_ = args.url;
const WEB_DIR = args['web-dir'];
const WARM_UP_MS = Number(args['warm-up-ms'] || 3000);
const MEASURE_MS = Number(args['measure-ms'] || 10000);
const PRESSES = Number(args.presses || 10);
const THRESHOLD = Number(args.threshold || 12);
const RTT_MS = Number(args['rtt-ms'] || 0);
const BROWSER = args.browser || 'chromium';
const PAGE = args.page || 'bundled';
const CHROMIUM = args.chromium || process.env.RFBSIM_CHROMIUM || '/usr/bin/chromium';
const FIREFOX = args.firefox || process.env.RFBSIM_FIREFOX || '/usr/bin/firefox-esr';
// The view: our page's canvas, or noVNC 1.3's.
const VIEW = PAGE === 'novnc13' ? '#noVNC_container canvas' : '#screen canvas';
const TURN_HOLD_MS = 300;
const AFTER_TURN_MS = 200;     // a turn's last pictures are in this long after its hold, from its first one
const PRESS_TIMEOUT_MS = 3000;
const PRESS_EVERY_MS = MEASURE_MS / Math.max(PRESSES, 1);

const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

function fail(message) {
  console.log(`BENCH_ERROR ${message}`);
  process.exit(1);
}

if (!URL_ || !WEB_DIR) fail('usage: --url URL --web-dir DIR');

// Runs in the page before its own scripts: counts WebSocket bytes received.
function countWebSocketBytes() {
  window.__benchBytes = 0;
  // A Proxy rather than a subclass: the socket stays a plain WebSocket to whoever inspects it (noVNC does).
  window.WebSocket = new Proxy(window.WebSocket, {
    construct(Native, rest) {
      const socket = new Native(...rest);
      socket.addEventListener('message', (event) => {
        const data = event.data;
        window.__benchBytes += data.byteLength ?? data.size ?? data.length ?? 0;
      });
      return socket;
    },
  });
}

// Runs in the page once a picture shows: the probe loop and the press bookkeeping (window.__bench).
function installProbe({ threshold, rttMs, viewSelector }) {
  const W = 320;
  const H = 180;
  const probe = document.createElement('canvas');
  probe.width = W;
  probe.height = H;
  const context = probe.getContext('2d', { willReadFrequently: true });
  // An area-averaging downscale: plain bilinear sampling at 1/4 aliases, and the walk then looks like big changes.
  context.imageSmoothingEnabled = true;
  context.imageSmoothingQuality = 'high';
  const b = { pictures: 0, previous: null, armed: false, press: null, results: [], traces: [] };
  window.__bench = b;
  const mad = (x, y) => {
    let sum = 0;
    for (let i = 0; i < x.length; i += 4) {
      sum += Math.abs(x[i] - y[i]) + Math.abs(x[i + 1] - y[i + 1]) + Math.abs(x[i + 2] - y[i + 2]);
    }
    return sum / ((x.length / 4) * 3);
  };
  window.addEventListener('keydown', (event) => {
    if (b.armed && event.key === 'd' && b.previous) {
      b.armed = false;
      b.press = { t0: event.timeStamp, reference: b.previous, trace: [] };
    }
  }, true);
  const look = () => {
    const now = performance.now();
    const view = document.querySelector(viewSelector);
    if (view && view.width > 0) {
      context.drawImage(view, 0, 0, W, H);
      const pixels = context.getImageData(0, 0, W, H).data;
      let changed = b.previous === null;
      for (let i = 0; !changed && i < pixels.length; i += 1) changed = pixels[i] !== b.previous[i];
      if (changed) {
        b.pictures += 1;
        if (b.press && now - b.press.t0 < rttMs) {
          b.press.reference = pixels;   // cannot show the press yet: the walk's latest picture before it could
          b.press.trace.push([Math.round(now - b.press.t0), -1]);
        } else if (b.press) {
          const m = mad(pixels, b.press.reference);
          b.press.trace.push([Math.round(now - b.press.t0), Math.round(m * 10) / 10]);
          if (m > threshold) {
            b.results.push(now - b.press.t0);
            b.traces.push(b.press.trace);
            b.press = null;
          }
        }
      }
      b.previous = pixels;
    }
    requestAnimationFrame(look);
  };
  requestAnimationFrame(look);
}

// The page in the chosen browser, behind the few calls this script makes (the two drivers name them differently).
async function openPage() {
  const require = createRequire(path.join(WEB_DIR, 'package.json'));
  const viewport = { width: 1280, height: 760 };
  if (BROWSER === 'firefox') {
    let puppeteer;
    try {
      puppeteer = require('puppeteer-core');
    } catch (err) {
      fail(`cannot load puppeteer-core from ${WEB_DIR}/node_modules: ${err.message}`);
    }
    const browser = await puppeteer.launch({ browser: 'firefox', executablePath: FIREFOX, headless: true,
                                             timeout: 30_000 });
    const page = await browser.newPage();
    await page.setViewport(viewport);
    return {
      close: () => browser.close(),
      beforeScripts: (fn) => page.evaluateOnNewDocument(fn),
      goto: (url) => page.goto(url, { waitUntil: 'load', timeout: 30_000 }),
      waitFor: (fn) => page.waitForFunction(fn, { timeout: 30_000, polling: 100 }),
      click: (selector) => page.click(selector),
      evaluate: (fn, arg) => page.evaluate(fn, arg),
      keyboard: page.keyboard,
    };
  }
  let chromium;
  try {
    chromium = require('playwright-core').chromium;
  } catch (err) {
    fail(`cannot load playwright-core from ${WEB_DIR}/node_modules: ${err.message}`);
  }
  const browser = await chromium.launch({
    executablePath: CHROMIUM,
    headless: true,
    args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
           '--disable-component-update', '--disable-sync'],
    timeout: 30_000,
  });
  const page = await browser.newPage({ viewport });
  return {
    close: () => browser.close(),
    beforeScripts: (fn) => page.addInitScript(fn),
    goto: (url) => page.goto(url, { waitUntil: 'load', timeout: 30_000 }),
    waitFor: (fn) => page.waitForFunction(fn, null, { timeout: 30_000, polling: 100 }),
    click: (selector) => page.locator(selector).click(),
    evaluate: (fn, arg) => page.evaluate(fn, arg),
    keyboard: page.keyboard,
  };
}

async function main() {
  const page = await openPage();
  try {
    await page.beforeScripts(countWebSocketBytes);
    await page.goto(URL_);
    // The first picture: our page records it in rfbsimState.firstFrameAt; noVNC 1.3 marks the document
    // connected and sizes its canvas to the session.
    if (PAGE === 'novnc13') {
      await page.waitFor(() => document.documentElement.classList.contains('noVNC_connected') &&
                               (document.querySelector('#noVNC_container canvas')?.width ?? 0) > 100);
    } else {
      await page.waitFor(() => window.rfbsimState && window.rfbsimState.firstFrameAt !== null);
    }
    await page.click(VIEW);
    await page.evaluate(installProbe, { threshold: THRESHOLD, rttMs: RTT_MS, viewSelector: VIEW });
    await page.keyboard.down('w');

    // The press schedule runs through the warm-up too; only the window's presses count.
    const start = Date.now();
    const windowStart = start + WARM_UP_MS;
    let counted = false;
    let base = null;
    const latencies = [];
    let timeouts = 0;
    let presses = 0;
    let nextPress = start + PRESS_EVERY_MS * (0.8 + 0.4 * Math.random());
    for (;;) {
      const now = Date.now();
      if (!counted && now >= windowStart) {
        counted = true;
        base = await page.evaluate(() => ({ pictures: window.__bench.pictures, bytes: window.__benchBytes,
                                            results: window.__bench.results.length, at: performance.now() }));
      }
      if (counted && now >= windowStart + MEASURE_MS && presses >= PRESSES) break;
      if (now < nextPress) {
        await sleep(Math.min(50, nextPress - now));
        continue;
      }
      // One press: arm, D down for the hold, then wait for the picture (or the timeout).
      const inWindow = counted;
      const before = await page.evaluate(() => { window.__bench.armed = true; return window.__bench.results.length; });
      const t0 = Date.now();
      await page.keyboard.down('d');
      await sleep(TURN_HOLD_MS);
      await page.keyboard.up('d');
      let latency = null;
      while (Date.now() - t0 < PRESS_TIMEOUT_MS) {
        const results = await page.evaluate(() => window.__bench.results);
        if (results.length > before) {
          latency = results[results.length - 1];
          break;
        }
        await sleep(20);
      }
      const seen = latency === null ? Date.now() : t0 + latency;
      if (latency === null) await page.evaluate(() => { window.__bench.press = null; window.__bench.armed = false; });
      if (inWindow) {
        presses += 1;
        if (latency === null) timeouts += 1;
        else latencies.push(latency);
      }
      const clear = seen + (latency === null ? 0 : TURN_HOLD_MS) + AFTER_TURN_MS;
      nextPress = Math.max(t0 + PRESS_EVERY_MS * (0.8 + 0.4 * Math.random()), clear);
    }
    const end = await page.evaluate(() => ({ pictures: window.__bench.pictures, bytes: window.__benchBytes,
                                             at: performance.now() }));
    await page.keyboard.up('w');
    const seconds = (end.at - base.at) / 1000;
    const state = await page.evaluate(() => JSON.parse(JSON.stringify(window.rfbsimState ?? { connected: null })));
    if (args.trace) console.log(`BENCH_TRACE ${JSON.stringify(await page.evaluate(() => window.__bench.traces))}`);
    console.log(`BENCH_RESULT ${JSON.stringify({
      seconds, fps: (end.pictures - base.pictures) / seconds, mbit: ((end.bytes - base.bytes) * 8) / seconds / 1e6,
      presses, timeouts, latencies, connected: state.connected,
    })}`);
  } finally {
    await page.close();
  }
}

main().catch((err) => fail(err && err.stack ? err.stack.replace(/\n/g, ' | ') : String(err)));
