// SPDX-License-Identifier: GPL-2.0-or-later
// rfbsim participant page logic: connects noVNC to this session's simulator and keeps hints and messages in step.

import RFB from './novnc/core/rfb.js';

// ---------------------------------------------------------------------------------------------------------------
// Page elements (all exist in index.html).
// ---------------------------------------------------------------------------------------------------------------
const ui = {
  screen: document.getElementById('screen'),
  status: document.getElementById('status'),
  hint: document.getElementById('hint'),
  panel: document.getElementById('disconnected'),
  panelTitle: document.getElementById('disconnected-title'),
  panelDetail: document.getElementById('disconnected-detail'),
  reconnect: document.getElementById('reconnect'),
};

// ---------------------------------------------------------------------------------------------------------------
// State, also readable by tests as window.rfbsimState (read-only by convention).
// ---------------------------------------------------------------------------------------------------------------
const state = {
  connecting: false,      // a connection attempt is under way
  connected: false,       // the RFB session is up (noVNC 'connect' seen, no 'disconnect' since)
  everConnected: false,   // any attempt on this page has connected
  attempts: 0,            // connection attempts made by this page (1 = the first, no reconnects yet)
  focused: false,         // keyboard focus is on the simulator view (keys reach the simulator)
  desktopName: '',        // name the server gave its desktop
  lastDisconnect: null,   // { kind: 'ended' | 'lost' | 'failed', clean, code, wasClean, reason, message }
  options: null,          // { quality, compression } taken from the query string (null where absent or invalid)
};
window.rfbsimState = state;

let rfb = null;       // the current noVNC client, or null while disconnected
let canvas = null;    // that client's canvas (noVNC makes a new one for every client)

// ---------------------------------------------------------------------------------------------------------------
// Options from the query string: ?quality=0..9&compression=0..9. Anything else is ignored with a warning.
// ---------------------------------------------------------------------------------------------------------------
function readLevel(params, name) {
  const raw = params.get(name);
  if (raw === null) {
    return null;
  }
  const text = raw.trim();
  if (!/^[0-9]$/.test(text)) {
    console.warn(`rfbsim: ignoring ${name}=${JSON.stringify(raw)}; expected an integer 0..9`);
    return null;
  }
  return Number(text);
}

const params = new URLSearchParams(window.location.search);
const options = {
  quality: readLevel(params, 'quality'),           // null = noVNC's default (6)
  compression: readLevel(params, 'compression'),   // null = noVNC's default (2)
};
state.options = options;

// The simulator serves this page and its WebSocket on one port: 'websockify' next to the page, ws: or wss: to
// match http: or https:. For a page at '/' that is '/websockify'.
function websocketUrl() {
  const url = new URL('websockify', window.location.href);
  url.protocol = window.location.protocol === 'https:' ? 'wss:' : 'ws:';
  url.search = '';
  url.hash = '';
  return url.href;
}

// ---------------------------------------------------------------------------------------------------------------
// What the page shows.
// ---------------------------------------------------------------------------------------------------------------
function showStatus(text) {
  ui.status.textContent = text;
  ui.status.hidden = text === '';
}

// The hint shows while a session is up and keys would not reach it (focus elsewhere, or the window/iframe
// itself not focused).
function updateFocus() {
  state.focused = canvas !== null && document.hasFocus() && document.activeElement === canvas;
  ui.hint.hidden = !state.connected || state.focused;
}

function showDisconnected(title, message) {
  ui.panelTitle.textContent = title;
  ui.panelDetail.textContent = message;
  ui.panel.hidden = false;
  ui.reconnect.disabled = false;
  // Only when this page already has the keyboard: never pull focus away from a survey around the iframe.
  if (document.hasFocus()) {
    ui.reconnect.focus({ preventScroll: true });
  }
}

// ---------------------------------------------------------------------------------------------------------------
// One connection attempt. noVNC clients cannot be reused after 'disconnect', so every attempt makes a new one.
// ---------------------------------------------------------------------------------------------------------------
function connect({ focusWhenConnected = false } = {}) {
  if (state.connecting || state.connected) {
    return;
  }
  state.attempts += 1;
  state.connecting = true;
  ui.panel.hidden = true;
  showStatus(state.attempts === 1 ? 'Connecting to the simulator\u2026' : 'Reconnecting to the simulator\u2026');
  updateFocus();

  // Open the WebSocket ourselves so that the close code is known when noVNC reports the disconnect.
  const closeInfo = { code: null, wasClean: false, reason: '' };
  let socket;
  try {
    socket = new WebSocket(websocketUrl());
  } catch (err) {
    finishAttempt({ kind: 'failed', clean: false, code: null, wasClean: false, reason: String(err) });
    return;
  }
  socket.addEventListener('close', (event) => {
    closeInfo.code = event.code;
    closeInfo.wasClean = event.wasClean;
    closeInfo.reason = event.reason;
  });

  let client;
  try {
    client = new RFB(ui.screen, socket, { shared: true });
  } catch (err) {
    socket.close();
    finishAttempt({ kind: 'failed', clean: false, code: null, wasClean: false, reason: String(err) });
    return;
  }
  rfb = client;

  // View: scaled to the window and letterboxed; the session keeps its own size.
  client.scaleViewport = true;
  client.clipViewport = false;
  client.resizeSession = false;
  client.focusOnClick = true;
  client.showDotCursor = true;
  client.background = '#1e1e1e';
  if (options.quality !== null) {
    client.qualityLevel = options.quality;
  }
  if (options.compression !== null) {
    client.compressionLevel = options.compression;
  }

  // The canvas: reachable with Tab, announced to screen readers, and watched for focus.
  canvas = ui.screen.querySelector('canvas');
  if (canvas !== null) {
    canvas.tabIndex = 0;
    canvas.setAttribute('role', 'application');
    canvas.setAttribute('aria-label', 'Simulator view. Use W, A, S and D to walk.');
    canvas.addEventListener('focus', updateFocus);
    canvas.addEventListener('blur', updateFocus);
  }

  let securityReason = '';
  let wasConnected = false;

  client.addEventListener('connect', () => {
    wasConnected = true;
    state.connecting = false;
    state.connected = true;
    state.everConnected = true;
    showStatus('');
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
    client.disconnect();
  });

  client.addEventListener('securityfailure', (event) => {
    securityReason = event.detail.reason ? `The simulator refused the connection: ${event.detail.reason}` : '';
  });

  client.addEventListener('disconnect', (event) => {
    const clean = Boolean(event.detail && event.detail.clean);
    let kind;
    if (!wasConnected) {
      kind = 'failed';
    } else if (clean && (closeInfo.code === null || closeInfo.code === 1000 || closeInfo.code === 1001 ||
                        closeInfo.code === 1005)) {
      kind = 'ended';
    } else {
      kind = 'lost';
    }
    finishAttempt({ kind, clean, code: closeInfo.code, wasClean: closeInfo.wasClean,
                    reason: securityReason || closeInfo.reason });
  });
}

// Called once per attempt when it is over: forget the client and say what happened.
function finishAttempt(info) {
  if (canvas !== null) {
    canvas.removeEventListener('focus', updateFocus);
    canvas.removeEventListener('blur', updateFocus);
  }
  rfb = null;
  canvas = null;
  state.connecting = false;
  state.connected = false;
  showStatus('');
  updateFocus();

  let title;
  let message;
  switch (info.kind) {
    case 'ended':
      title = 'Session ended';
      message = 'The simulator closed the connection.';
      break;
    case 'lost':
      title = 'Connection lost';
      message = 'The connection to the simulator was lost.';
      break;
    default:
      title = 'Could not connect';
      message = 'The simulator could not be reached. It may have stopped, or the network may be down.';
      break;
  }
  if (info.reason) {
    message += ` (${info.reason})`;
  }
  message += ' Press Reconnect to try again.';
  state.lastDisconnect = { ...info, message };
  showDisconnected(title, message);
}

// ---------------------------------------------------------------------------------------------------------------
// Wiring.
// ---------------------------------------------------------------------------------------------------------------
ui.reconnect.addEventListener('click', () => {
  ui.reconnect.disabled = true;
  connect({ focusWhenConnected: true });
});

// A click on the letterbox around the picture also gives the view the keyboard (noVNC only listens on the
// canvas). preventDefault keeps the browser from moving focus to the page body afterwards.
ui.screen.addEventListener('mousedown', (event) => {
  if (rfb !== null && event.target !== canvas) {
    event.preventDefault();
    rfb.focus({ preventScroll: true });
  }
});

window.addEventListener('focus', updateFocus);
window.addEventListener('blur', updateFocus);

connect();
