// SPDX-License-Identifier: GPL-2.0-or-later
// The browser under an end-to-end test: Chromium through playwright-core, or Firefox ESR through puppeteer-core over
// WebDriver BiDi, behind the few calls where the two libraries differ, so that one test body runs in either.
//
// What both libraries share is used directly on their page and frame objects: goto, reload, url, evaluate (with one
// argument), frames, mainFrame, $ and contentFrame, keyboard.down/up, screenshot, close, and the events console,
// pageerror, requestfailed, response and dialog. Everything else goes through a driver from loadDriver: launching
// (profile, viewport, init scripts, HTTP credentials), elements by CSS selector (click, wait until shown or hidden,
// text, attribute, enabled), the page's WebSockets, answering a request in the test's place, and how a frame the
// browser refused looks. The Chromium driver does what the tests did before, through playwright's locators; the
// Firefox one does the same with puppeteer, and its comments say where the two cannot behave alike.

import { spawn } from 'node:child_process';
import fs from 'node:fs';
import { createRequire } from 'node:module';
import os from 'node:os';
import path from 'node:path';

import { CHROMIUM, CheckFailed, adoptBrowser, check, launchBrowser, log, prepareRun } from './e2e_support.mjs';

export const FIREFOX = process.env.RFBSIM_FIREFOX || '/usr/bin/firefox-esr';

// Loads an npm package from WEB_DIR/node_modules (NODE_PATH does not reach ES module imports).
function loadPackage(webDir, name) {
  try {
    return createRequire(path.join(webDir, 'package.json'))(name);
  } catch (err) {
    throw new CheckFailed(`cannot load ${name} from ${webDir}/node_modules (run: npm ci --prefix ${webDir}): ` +
                          err.message);
  }
}

// ---------------------------------------------------------------------------------------------------------------
// Chromium through playwright-core: what the Chromium tests always did.
// ---------------------------------------------------------------------------------------------------------------
function chromiumDriver(webDir) {
  check(fs.existsSync(CHROMIUM), `Chromium not found at ${CHROMIUM}`);
  const { chromium } = loadPackage(webDir, 'playwright-core');
  return {
    name: 'chromium',

    // Resolves with { firstPage(), newPage(), addInitScript(fn) }; cleanup (e2e_support.mjs) closes the browser.
    // credentials: { username, password, origin } sent to that origin only when it asks (HTTP Basic), or undefined.
    async launch(viewport, { credentials } = {}) {
      const context = await launchBrowser(chromium, viewport, credentials ? { httpCredentials: credentials } : {});
      return {
        firstPage: async () => context.pages()[0] || context.newPage(),
        newPage: () => context.newPage(),
        // Runs fn in every page and frame opened from now on, before their own scripts.
        addInitScript: (fn) => context.addInitScript(fn),
      };
    },
    addInitScript: (page, fn) => page.addInitScript(fn),

    // target: a page or a frame; selector: CSS that names one element.
    click: (target, selector) => target.locator(selector).click(),
    waitVisible: (target, selector, timeoutMs) => target.locator(selector).waitFor({ state: 'visible',
                                                                                         timeout: timeoutMs }),
    waitHidden: (target, selector, timeoutMs) => target.locator(selector).waitFor({ state: 'hidden',
                                                                                        timeout: timeoutMs }),
    isHidden: (target, selector) => target.locator(selector).isHidden(),
    isEnabled: (target, selector) => target.locator(selector).isEnabled(),
    innerText: (target, selector) => target.locator(selector).innerText(),
    attribute: (target, selector, name) => target.locator(selector).getAttribute(name),
    count: (target, selector) => target.locator(selector).count(),

    // The page's WebSockets as they open: a live list of { url, openedAt, firstDataAt } (Date.now() times,
    // firstDataAt null until the first frame arrives).
    watchWebSockets(page) {
      const sockets = [];
      page.on('websocket', (ws) => {
        const entry = { url: ws.url(), openedAt: Date.now(), firstDataAt: null };
        sockets.push(entry);
        ws.once('framereceived', () => { entry.firstDataAt = Date.now(); });
      });
      return sockets;
    },

    // Answers the page's requests for pathname with response ({ status, contentType, body }) instead of the
    // server, until the returned function is called.
    async answerInstead(page, pathname, response) {
      const pattern = `**${pathname}`;
      await page.route(pattern, (route) => route.fulfill(response));
      return () => page.unroute(pattern);
    },

    // A frame the browser refused to show (frame-ancestors) is left on Chromium's error page.
    isRefusedFrame: (frame) => frame.url().startsWith('chrome-error:'),
  };
}

// ---------------------------------------------------------------------------------------------------------------
// Firefox ESR through puppeteer-core (WebDriver BiDi; Debian has no geckodriver).
// ---------------------------------------------------------------------------------------------------------------

// Whether the element selector names is shown, as playwright counts it: it has a box and is not visibility:hidden.
function shown(selector) {
  const element = document.querySelector(selector);
  return element !== null && element.getClientRects().length > 0 &&
         getComputedStyle(element).visibility !== 'hidden';
}

// A small shell process that waits for this one to end: if it ends without cleaning up (SIGKILL from a ctest
// timeout, say), the guard kills Firefox's process group and removes its profile. Chromium needs none: playwright
// talks to it through a pipe, and it exits when the pipe closes; Firefox is talked to over a WebSocket and would
// stay. Returns a function that stops the guard, for the ends that clean up themselves.
function startOrphanGuard(firefoxPid, profileDir) {
  // dash's kill takes no -- after -KILL, only after -s KILL.
  const script = 'while kill -0 "$1" 2>/dev/null; do sleep 1; done; ' +
                 'kill -s KILL -- "-$2" 2>/dev/null; rm -rf -- "$3"';
  const guard = spawn('/bin/sh', ['-c', script, 'rfbsim-e2e-firefox-guard', String(process.pid), String(firefoxPid),
                                  profileDir], { detached: true, stdio: 'ignore' });
  guard.unref();
  return () => {
    try {
      guard.kill('SIGKILL');
    } catch {
      // already gone
    }
  };
}

function firefoxDriver(webDir) {
  check(fs.existsSync(FIREFOX), `Firefox not found at ${FIREFOX}`);
  const puppeteer = loadPackage(webDir, 'puppeteer-core');
  return {
    name: 'firefox',

    async launch(viewport, { credentials } = {}) {
      const profileDir = fs.mkdtempSync(path.join(os.tmpdir(), 'rfbsim-e2e-firefox-'));
      let browser = null;
      let stopGuard = () => {};
      // Puppeteer kills Firefox's process group itself when this process exits; the kill here also covers a close
      // that failed, and stops the guard before it could act on a process group id that is no longer ours.
      const kill = () => {
        stopGuard();
        const pid = browser?.process()?.pid;
        if (pid) {
          try {
            process.kill(-pid, 'SIGKILL');
          } catch {
            // the group is gone already
          }
        }
      };
      adoptBrowser({ profileDir, close: () => (browser ? browser.close() : Promise.resolve()), kill });
      log(`launching ${FIREFOX}`);
      browser = await puppeteer.launch({
        browser: 'firefox',
        executablePath: FIREFOX,
        headless: true,
        userDataDir: profileDir,
        defaultViewport: viewport,
        timeout: 30_000,
        // runTest handles these, as for Chromium: puppeteer's handlers would exit before cleanup stopped the sims.
        handleSIGINT: false,
        handleSIGTERM: false,
        handleSIGHUP: false,
      });
      stopGuard = startOrphanGuard(browser.process().pid, profileDir);
      log(`launched ${await browser.version()}`);

      // Playwright's context has init scripts and credentials for all its pages; puppeteer has them per page.
      const initScripts = [];
      const prepared = new WeakSet();
      const preparePage = async (page) => {
        if (!prepared.has(page)) {
          prepared.add(page);
          for (const fn of initScripts) {
            await page.evaluateOnNewDocument(fn);
          }
          // Puppeteer answers every HTTP Basic challenge with these, not only the origin's: in the tests only
          // sim_manager's admin pages ask.
          if (credentials) {
            await page.authenticate({ username: credentials.username, password: credentials.password });
          }
        }
        return page;
      };
      return {
        // Not the tab Firefox opens at start: headless, that one never gets the window's focus
        // (document.hasFocus() stays false however it is clicked, so the page rightly keeps its "click here"
        // hint and the test could not tell whether keys reach it), while a tab opened over BiDi does, as a
        // participant's tab in a window of theirs does.
        firstPage: async () => {
          const [startTab] = await browser.pages();
          const page = await preparePage(await browser.newPage());
          await startTab?.close();
          return page;
        },
        newPage: async () => preparePage(await browser.newPage()),
        addInitScript: async (fn) => {
          initScripts.push(fn);
          for (const page of await browser.pages()) {
            if (prepared.has(page)) {
              await page.evaluateOnNewDocument(fn);
            }
          }
        },
      };
    },
    // Over WebDriver BiDi a preload script runs in the page's frames too, as playwright's does.
    addInitScript: (page, fn) => page.evaluateOnNewDocument(fn),

    click: (target, selector) => target.click(selector),
    waitVisible: (target, selector, timeoutMs) => target.waitForSelector(selector, { visible: true,
                                                                                      timeout: timeoutMs }),
    waitHidden: (target, selector, timeoutMs) => target.waitForSelector(selector, { hidden: true,
                                                                                     timeout: timeoutMs }),
    isHidden: async (target, selector) => !await target.evaluate(shown, selector),
    isEnabled: (target, selector) => target.$eval(selector, (element) => !element.disabled),
    innerText: (target, selector) => target.$eval(selector, (element) => element.innerText),
    attribute: (target, selector, name) => target.$eval(selector, (element, attr) => element.getAttribute(attr),
                                                        name),
    count: (target, selector) => target.evaluate((selector) => document.querySelectorAll(selector).length, selector),

    // WebDriver BiDi has no WebSocket events; Firefox does report each WebSocket's handshake as a request
    // answered 101, which is when the socket opened. Its frames are not seen, so firstDataAt stays null.
    watchWebSockets(page) {
      const sockets = [];
      page.on('response', (response) => {
        if (response.status() === 101) {
          const url = new URL(response.url());
          url.protocol = url.protocol === 'https:' ? 'wss:' : 'ws:';
          sockets.push({ url: url.href, openedAt: Date.now(), firstDataAt: null });
        }
      });
      return sockets;
    },

    async answerInstead(page, pathname, response) {
      const handler = (request) => {
        if (request.isInterceptResolutionHandled()) {
          return;
        }
        if (new URL(request.url()).pathname === pathname) {
          request.respond(response);
        } else {
          request.continue();
        }
      };
      await page.setRequestInterception(true);
      page.on('request', handler);
      return async () => {
        page.off('request', handler);
        await page.setRequestInterception(false);
      };
    },

    // Firefox shows a frame refused by the page's Content-Security-Policy as its own error page.
    isRefusedFrame: (frame) => frame.url().startsWith('about:neterror?e=cspBlocked'),
  };
}

// Checks that the simulator exists and creates the artifacts folder (prepareRun), then returns the driver for
// env.browser ('chromium' or 'firefox') once that browser and its npm package are found.
export function loadDriver(env) {
  prepareRun(env);
  const driver = env.browser === 'firefox' ? firefoxDriver(env.webDir) : chromiumDriver(env.webDir);
  log(`browser: ${driver.name}`);
  return driver;
}
