// SPDX-License-Identifier: GPL-2.0-or-later
// One connection attempt. noVNC clients cannot be reused after 'disconnect', so every attempt makes a new one.
// The socket is opened at once: under sim_manager it is held until the session is ready, so the first frame
// comes as early as it can; the status is polled meanwhile to show the start-up progress. What follows an
// attempt (trying again, or saying why not) is reconnect.js's, told through the callbacks.

import RFB from './novnc/core/rfb.js';
import { classifyClose } from './reconnect_policy.js';
import { watchForFirstPicture } from './first_picture.js';
import { options, page, state, ui, watching } from './page_state.js';
import { showProgress, updateFocus } from './page_view.js';
import { pictureHeld } from './picture_recovery.js';
import { startStatusPolling } from './session_status.js';

// An automatic try that has not connected after this long is given up (and counts as failed): a network that
// swallows packets would otherwise leave the socket opening for minutes. First attempts have no limit, because
// the manager holds their socket while the session starts.
const RETRY_CONNECT_TIMEOUT_MS = 15_000;

// The WebSocket next to the page, relative to it so that it works both under sim_manager (/s/<token>/ws) and from
// sim_rfb itself (/, where any WebSocket path is accepted): ws: or wss: to match http: or https:.
function websocketUrl() {
  const url = new URL('ws', window.location.href);
  url.protocol = window.location.protocol === 'https:' ? 'wss:' : 'ws:';
  url.search = '';
  url.hash = '';
  return url.href;
}

// Starts an attempt unless one is under way or connected. `onPicture()`: its first picture shows.
// `onOver(info, { view, hadFocus })`: called once when it is over, with info = { kind (reconnect_policy.js's
// classifyClose), clean, code, wasClean, reason }, the attempt's canvas and whether it had the keyboard when the
// connection closed.
export function openConnection({ focusWhenConnected = false, onPicture, onOver }) {
  if (state.connecting || state.connected) {
    return;
  }
  clearTimeout(page.retryTimer);
  page.retryTimer = null;
  state.attempts += 1;
  state.connecting = true;
  page.pictureShown = false;
  ui.panel.hidden = true;
  showProgress();
  updateFocus();

  // Open the WebSocket ourselves so that the close code is known when noVNC reports the disconnect. Its close
  // event comes before noVNC's (registered first), while the view still has the keyboard focus it had.
  const closeInfo = { code: null, wasClean: false, reason: '', hadFocus: false };
  let view = null;
  let socket;
  try {
    socket = new WebSocket(websocketUrl());
  } catch (err) {
    onOver({ kind: 'failed', clean: false, code: null, wasClean: false, reason: String(err) });
    return;
  }
  socket.addEventListener('close', (event) => {
    closeInfo.code = event.code;
    closeInfo.wasClean = event.wasClean;
    closeInfo.reason = event.reason;
    closeInfo.hadFocus = view !== null && document.activeElement === view;
  });

  let client;
  try {
    client = new RFB(ui.screen, socket, { shared: true });
  } catch (err) {
    socket.close();
    onOver({ kind: 'failed', clean: false, code: null, wasClean: false, reason: String(err) });
    return;
  }
  page.rfb = client;
  startStatusPolling();

  // View: scaled to the window and letterboxed; the session keeps its own size.
  client.scaleViewport = true;
  client.clipViewport = false;
  client.resizeSession = false;
  client.focusOnClick = true;
  client.showDotCursor = true;
  client.viewOnly = watching;
  // While a frozen picture is held behind the view (see holdPicture), the view lets it show until it has its own.
  client.background = pictureHeld() ? 'transparent' : '#1e1e1e';
  if (options.quality !== null) {
    client.qualityLevel = options.quality;
  }
  if (options.compression !== null) {
    client.compressionLevel = options.compression;
  }

  // The canvas: reachable with Tab, announced to screen readers, and watched for focus and the first picture.
  const canvas = ui.screen.querySelector('canvas');
  page.canvas = canvas;
  view = canvas;
  if (canvas !== null) {
    canvas.tabIndex = 0;
    canvas.setAttribute('role', 'application');
    canvas.setAttribute('aria-label', watching ? 'Simulator view, watched (view only).'
                                                : 'Simulator view. Use W, A, S and D to walk.');
    canvas.addEventListener('focus', updateFocus);
    canvas.addEventListener('blur', updateFocus);
    watchForFirstPicture(client, canvas, onPicture);
  }

  let securityReason = '';
  let refused = false;
  let wasConnected = false;
  let gaveUp = false;
  const giveUpTimer = state.reconnecting ? setTimeout(() => {
    gaveUp = true;
    client.disconnect();
  }, RETRY_CONNECT_TIMEOUT_MS) : null;

  client.addEventListener('connect', () => {
    clearTimeout(giveUpTimer);
    wasConnected = true;
    state.connecting = false;
    state.connected = true;
    state.everConnected = true;
    showProgress();
    if (focusWhenConnected) {
      client.focus({ preventScroll: true });
    }
    updateFocus();
  });

  client.addEventListener('desktopname', (event) => {
    state.desktopName = event.detail.name || '';
    document.title = state.desktopName ? `${state.desktopName} \u2013 rfbsim` : 'rfbsim';
  });

  client.addEventListener('credentialsrequired', () => {
    securityReason = 'The simulator asked for a password, which this page does not support.';
    refused = true;
    client.disconnect();
  });

  client.addEventListener('securityfailure', (event) => {
    securityReason = event.detail.reason ? `The simulator refused the connection: ${event.detail.reason}` : '';
    refused = true;
  });

  client.addEventListener('disconnect', (event) => {
    clearTimeout(giveUpTimer);
    const clean = Boolean(event.detail && event.detail.clean);
    const kind = classifyClose({ connected: wasConnected, clean, code: closeInfo.code, refused, gaveUp });
    onOver({ kind, clean, code: closeInfo.code, wasClean: closeInfo.wasClean,
             reason: securityReason || closeInfo.reason },
           { view, hadFocus: closeInfo.hadFocus });
  });
}

// The attempt is over: its canvas no longer tells the page about focus, and the page has no client until the next.
export function forgetConnection() {
  if (page.canvas !== null) {
    page.canvas.removeEventListener('focus', updateFocus);
    page.canvas.removeEventListener('blur', updateFocus);
  }
  page.rfb = null;
  page.canvas = null;
}
