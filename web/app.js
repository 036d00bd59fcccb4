// SPDX-License-Identifier: GPL-2.0-or-later
// rfbsim participant page logic: connects noVNC to this session's simulator and keeps hints and messages in step.

import { installH264Guard } from './h264_guard.js';
import RFB from './novnc/core/rfb.js';
import { SERIES_CALM_MS, classifyClose, nextStep, sessionView } from './reconnect_policy.js';
import { SurveyReporter } from './survey.js';

// ---------------------------------------------------------------------------------------------------------------
// Page elements (all exist in index.html).
// ---------------------------------------------------------------------------------------------------------------
const ui = {
  screen: document.getElementById('screen'),
  status: document.getElementById('status'),
  statusText: document.getElementById('status-text'),
  statusTimer: document.getElementById('status-timer'),
  hint: document.getElementById('hint'),
  panel: document.getElementById('disconnected'),
  panelTitle: document.getElementById('disconnected-title'),
  panelDetail: document.getElementById('disconnected-detail'),
  reconnect: document.getElementById('reconnect'),
  notice: document.getElementById('reconnecting'),
  noticeText: document.getElementById('reconnecting-text'),
  reconnectNow: document.getElementById('reconnect-now'),
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
  lastDisconnect: null,   // what the disconnect panel last said: { kind: 'ended' | 'lost' | 'failed' | 'refused' |
                          //   'taken-over', final, clean, code, wasClean, reason, sessionState, message };
                          //   final: the manager says the session is over for good
  reconnecting: false,    // a connection was lost and the page is trying again by itself (see reconnect_policy.js)
  retries: 0,             // automatic tries in the current series (the notice's "attempt N")
  reconnects: 0,          // lost connections this page got back by itself (a picture showed again)
  lastLoss: null,         // { kind, code, reason, at (performance.now()) } of the last connection tried again
  options: null,          // { quality, compression } taken from the query string (null where absent or invalid)
  firstFrameAt: null,     // ms since the navigation started (performance.now()) when a picture was first drawn
  sessionState: null,     // the manager's last word on this session ('starting', 'running', 'ended', ...), or
                          // null where no manager answers (sim_rfb serving the page itself)
  h264Guarded: false,     // the H.264 guard is installed (the browser has WebCodecs' VideoDecoder)
  h264Offered: null,      // the last connection offered H.264 (encoding 50); null before one sent its encodings
  h264Disabled: false,    // H.264 failed too often here: later connections offer JPEG only
  recovering: false,      // a picture could not be decoded and the connection is being replaced
  pictureFailures: 0,     // pictures this page could not decode (each replaced its connection)
  lastPictureFailure: null,  // { reason, detail, at (performance.now()) } of the last one
};
window.rfbsimState = state;

let rfb = null;           // the current noVNC client, or null while disconnected
let canvas = null;        // that client's canvas (noVNC makes a new one for every client)
let pictureShown = false; // the current client has drawn its first picture
let pictureAt = 0;        // performance.now() when it did

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

// A researcher watching from the admin page (/admin/watch/<token>/, or under a host's path prefix behind a balancer,
// /h2/admin/watch/<token>/): the manager drops this page's keys and pointer anyway; here the view is read-only and
// never invites anyone to walk.
const watching = /\/admin\/watch\/[0-9a-f]{32}\/[^/]*$/.test(window.location.pathname);
state.watching = watching;

// The survey around this page (if any) hears how the session goes; a researcher's watching page tells no one.
const survey = new SurveyReporter(watching ? null : window.parent, window);
state.outcome = null;          // 'completed' | 'timeout' once the task has an outcome (from sim_manager)
state.completionCode = null;   // the code the link carried for that outcome
state.surveyEvents = survey.sent;  // the events posted to the survey so far (a Set, for tests)

// ---------------------------------------------------------------------------------------------------------------
// Addresses, relative to this page so that they work both under sim_manager (/s/<token>/) and from sim_rfb
// itself (/, where any WebSocket path is accepted and 'status' does not exist).
// ---------------------------------------------------------------------------------------------------------------

// The WebSocket next to the page: ws: or wss: to match http: or https:.
function websocketUrl() {
  const url = new URL('ws', window.location.href);
  url.protocol = window.location.protocol === 'https:' ? 'wss:' : 'ws:';
  url.search = '';
  url.hash = '';
  return url.href;
}

const statusUrl = new URL('status', window.location.href);
statusUrl.search = '';
statusUrl.hash = '';

// ---------------------------------------------------------------------------------------------------------------
// The manager's view of this session: GET status -> {"state": "starting" | "running" | "ending" | <final>,
// "ends_as": <the state it ends in>, "elapsed_s": seconds since the link was opened}.
// ---------------------------------------------------------------------------------------------------------------
const STATUS_POLL_MS = 250;       // while no picture shows, the status is asked for this often
const OUTCOME_POLL_MS = 1000;     // in a survey, while the session runs: how soon the survey hears the outcome
const STATUS_TIMEOUT_MS = 2000;   // one status request may take this long

// Why a session is over, in words, by the state it ended in (the manager's `ends_as`).
const SESSION_OVER_WORDS = {
  finished: 'The session is complete.',
  expired: 'The session reached its time limit.',
  idle: 'The session ended because no one was connected to it for a while.',
  ended: 'The session was ended by the researcher.',
  shutdown: 'The session ended because the server was shut down.',
  crashed: 'The simulator stopped unexpectedly.',
  failed: 'The simulator could not start.',
  interrupted: 'The session was interrupted.',
  abandoned: 'The session ended before its picture could reach this browser.',
};
// Behind a balancer, the status of a session whose host went down is answered by the balancer itself: HTTP 410 with
// {"state": "lost"}. Nothing on this page can bring it back, and the link should not be opened again blindly.
const SESSION_LOST_TITLE = 'Session lost';
const SESSION_LOST_WORDS = 'The server running your session stopped. Please go back to the survey and tell the ' +
                           'researcher.';
// Sessions that did not run their course: the study link starts a new one.
const RESTARTABLE_STATES = new Set(['shutdown', 'crashed', 'failed', 'interrupted', 'abandoned']);

let statusAvailable = true;  // false once 'status' answered that there is nothing more to ask (see noStatusView)
let noStatusView = 'none';   // what an unavailable status means: 'none' (sim_rfb's 404) or 'gone' (the manager's)
let managed = false;         // a manager has answered this page's status at least once
let programHintSet = false;  // the hint names no WASD: the session runs another program than sim_rfb
let statusPolling = false;   // the polling loop runs
let startingSince = null;    // { elapsedS, at }: the session's start-up time as last reported, and when
let sessionLost = false;     // the balancer said this session's host is gone (see SESSION_LOST_WORDS)

function timeoutSignal(ms) {
  return typeof AbortSignal.timeout === 'function' ? AbortSignal.timeout(ms) : undefined;
}

// Asks for the session's status. Resolves with { view, state, endsAs, elapsedS }: view is reconnect_policy.js's
// sessionView ('live', 'over', 'gone', 'none' or 'unknown'); the rest are null unless the manager answered.
async function fetchSessionStatus() {
  const none = { state: null, endsAs: null, elapsedS: null };
  if (!statusAvailable) {
    return { ...none, view: noStatusView };
  }
  let response;
  let body = null;
  let json = false;
  try {
    response = await fetch(statusUrl, { cache: 'no-store', signal: timeoutSignal(STATUS_TIMEOUT_MS) });
    const type = response.headers.get('Content-Type') || '';
    if (type.includes('json')) {
      json = true;
      body = await response.json();
    }
  } catch (err) {
    return { ...none, view: 'unknown' };   // network trouble or a body that is not JSON after all: ask again later
  }
  const valid = response.ok && body !== null && typeof body === 'object' && typeof body.state === 'string';
  const view = sessionView({ httpStatus: response.status, json, state: valid ? body.state : null, managed });
  if (!valid) {
    if (json && body !== null && typeof body === 'object' && body.state === 'lost') {
      sessionLost = true;
      state.sessionState = 'lost';
    }
    // sim_rfb serving the page itself answers 404 (text); a manager answers JSON, and 404 or 410 once it no longer
    // knows the session. Either way there is nothing more to ask. Server errors may pass: asked again later.
    if (view === 'none' || view === 'gone') {
      statusAvailable = false;
      noStatusView = view;
    }
    return { ...none, view };
  }
  managed = true;
  const status = {
    view,
    state: body.state,
    endsAs: typeof body.ends_as === 'string' ? body.ends_as : body.state,
    elapsedS: Number.isFinite(body.elapsed_s) ? body.elapsed_s : null,
  };
  state.sessionState = status.state;
  if ((body.outcome === 'completed' || body.outcome === 'timeout') && state.outcome === null) {
    state.outcome = body.outcome;
    state.completionCode = typeof body.code === 'string' ? body.code : null;
    updateFocus();
  }
  // Another program than sim_rfb (the manager's session_kind rfb or x11): its keys are its own, not WASD walking.
  if (typeof body.program === 'string' && body.program !== 'sim_rfb' && !programHintSet) {
    programHintSet = true;
    ui.hint.querySelector('p').textContent = 'Click here to use the keyboard and the mouse';
  }
  survey.update(body);
  startingSince = status.state === 'starting' && status.elapsedS !== null
    ? { elapsedS: status.elapsedS, at: performance.now() } : null;
  return status;
}

// Polls the status while a connection is being made or its first picture is awaited, updating the progress line;
// once the picture shows, asks once more so that rfbsimState.sessionState is current.
function startStatusPolling() {
  if (statusPolling) {
    return;
  }
  statusPolling = true;
  (async () => {
    while (statusAvailable && (state.connecting || state.connected) && !pictureShown) {
      await fetchSessionStatus();
      showProgress();
      await new Promise((resolve) => setTimeout(resolve, STATUS_POLL_MS));
    }
    if (pictureShown) {
      await fetchSessionStatus();
    }
    // Inside a survey, keep asking while the session runs, so that the survey hears the outcome within a second.
    while (statusAvailable && survey.enabled && state.connected && state.outcome === null) {
      await new Promise((resolve) => setTimeout(resolve, OUTCOME_POLL_MS));
      await fetchSessionStatus();
    }
    statusPolling = false;
  })();
}

// ---------------------------------------------------------------------------------------------------------------
// What the page shows.
// ---------------------------------------------------------------------------------------------------------------

// The progress line; `counter` (e.g. "3 s") is shown but not announced, and text is only set when it changes,
// so that screen readers hear each phase once.
function showStatus(text, counter = '') {
  if (ui.statusText.textContent !== text) {
    ui.statusText.textContent = text;
  }
  if (ui.statusTimer.textContent !== counter) {
    ui.statusTimer.textContent = counter;
  }
  ui.status.hidden = text === '';
}

// The progress line for where the current attempt stands: starting (with the manager's clock), connecting,
// loading the first picture, or nothing once the picture shows.
function showProgress() {
  if (state.reconnecting) {
    showStatus('');
    showReconnecting();
    return;
  }
  if (state.recovering) {
    const waited = performance.now() - recoveringSince;
    showStatus(waited >= RECOVERY_NOTICE_MS ? 'Restoring the picture\u2026' : '');
    return;
  }
  if (state.connected) {
    showStatus(pictureShown ? '' : 'Loading the picture\u2026');
  } else if (state.connecting) {
    if (state.sessionState === 'starting' && startingSince !== null) {
      const seconds = startingSince.elapsedS + (performance.now() - startingSince.at) / 1000;
      showStatus('Starting your simulation\u2026', `${Math.floor(seconds)} s`);
    } else {
      const again = state.attempts > 1;
      showStatus(again ? 'Reconnecting to the simulator\u2026' : 'Connecting to the simulator\u2026');
    }
  }
}

// The hint shows while a session is up and keys would not reach it (focus elsewhere, or the window/iframe
// itself not focused).
function updateFocus() {
  state.focused = canvas !== null && document.hasFocus() && document.activeElement === canvas;
  // After the outcome the hint would cover the completion code drawn in the picture.
  ui.hint.hidden = watching || !state.connected || state.focused || state.outcome !== null;
}

// The notice while the page reconnects by itself: it leaves the (held) picture visible and asks for nothing, and
// its button tries at once instead of waiting; the text is only set when it changes (one announcement per try).
function showReconnecting() {
  const text = `Connection lost, reconnecting\u2026 (attempt ${state.retries})`;
  if (ui.noticeText.textContent !== text) {
    ui.noticeText.textContent = text;
  }
  ui.reconnectNow.disabled = retryTimer === null;
  ui.notice.hidden = false;
}

// The panel after a disconnect. `final`: the session is over for good, so there is nothing to reconnect to;
// `action`: the button's words where there is something to do.
function showDisconnected(title, message, final, action = 'Reconnect') {
  ui.notice.hidden = true;
  ui.panelTitle.textContent = title;
  ui.panelDetail.textContent = message;
  ui.reconnect.textContent = action;
  ui.reconnect.hidden = final;
  ui.reconnect.disabled = final;
  ui.panel.hidden = false;
  // Only when this page already has the keyboard: never pull focus away from a survey around the iframe.
  if (document.hasFocus()) {
    (final ? ui.panel : ui.reconnect).focus({ preventScroll: true });
  }
}

// ---------------------------------------------------------------------------------------------------------------
// The first picture. noVNC draws into its canvas only when a whole framebuffer update is in, and until then the
// canvas is transparent (it is cleared whenever noVNC sizes it): the first opaque pixel is the first picture.
// Looked for once per animation frame in an 8x8 copy, so noVNC's own canvas is never read back (a canvas read
// from often is moved off the GPU). Hidden pages get no animation frames: a picture counts once it can be seen.
// ---------------------------------------------------------------------------------------------------------------
const PROBE_SIZE = 8;

function watchForFirstPicture(client, view) {
  const probe = document.createElement('canvas');
  probe.width = PROBE_SIZE;
  probe.height = PROBE_SIZE;
  const probeContext = probe.getContext('2d', { willReadFrequently: true });
  const look = () => {
    if (rfb !== client) {
      return;   // that attempt is over
    }
    if (view.width > 0 && view.height > 0) {
      probeContext.clearRect(0, 0, PROBE_SIZE, PROBE_SIZE);
      probeContext.drawImage(view, 0, 0, PROBE_SIZE, PROBE_SIZE);
      const pixels = probeContext.getImageData(0, 0, PROBE_SIZE, PROBE_SIZE).data;
      for (let i = 3; i < pixels.length; i += 4) {
        if (pixels[i] !== 0) {
          firstPictureShown();
          return;
        }
      }
    }
    window.requestAnimationFrame(look);
  };
  window.requestAnimationFrame(look);
}

function firstPictureShown() {
  pictureShown = true;
  pictureAt = performance.now();
  if (state.reconnecting) {
    state.reconnects += 1;
    stopReconnecting();
  }
  if (state.recovering || heldPicture) {
    endRecovery();
  }
  if (state.firstFrameAt === null) {
    state.firstFrameAt = performance.now();
  }
  survey.started();
  showProgress();
  startStatusPolling();
}

// ---------------------------------------------------------------------------------------------------------------
// A picture the browser could not decode (H.264 only, see h264_guard.js): noVNC 1.7 would wait for it forever, so
// the connection is replaced without a word. A new connection gets a new decoder, and the server starts its stream
// with a whole picture (an IDR). Meanwhile the frozen picture stays on screen, and if no new one shows within
// RECOVERY_NOTICE_MS the progress line says that it is being restored. Failures that follow one another wait longer
// each time (RECOVERY_BACKOFF_MS), so that a browser that fails on every picture never reconnects in a tight loop;
// after H264_FAILURES_BEFORE_JPEG of them the page stops offering H.264 and the server streams JPEG instead.
// ---------------------------------------------------------------------------------------------------------------
// Wait before the 1st, 2nd and 3rd reconnect in a row; the 3rd is the last one H.264 gets (the page then asks for
// JPEG, which needs no decoder), the last wait stands for any later one.
const RECOVERY_BACKOFF_MS = [0, 1000, 3000];
const RECOVERY_CALM_MS = 60_000;     // a failure this long after the last one starts a new series
const RECOVERY_NOTICE_MS = 2000;     // without a picture for this long, the participant is told
const H264_FAILURES_BEFORE_JPEG = 3; // failures in one series after which H.264 is no longer offered
const H264_ENCODING = 50;            // RFB encoding number of H.264 rectangles

let recovery = null;           // { delayMs, focus } from a failure until its connection has closed
let recoveringSince = 0;       // performance.now() of the failure being recovered from
let recoveryNoticeTimer = null;
let failuresInARow = 0;        // failures in the current series
let lastFailureAt = -Infinity; // performance.now() of the last failure
let heldPicture = false;       // #screen's background shows the frozen picture

const h264Guard = installH264Guard({ onFailure: pictureFailed });
state.h264Guarded = h264Guard.installed;

// noVNC offers H.264 whenever the browser can decode it and has no option to stop; once H.264 is given up here,
// its encodings message (sent on every connection) goes out without encoding 50.
const writeClientEncodings = RFB.messages.clientEncodings;
RFB.messages.clientEncodings = function clientEncodings(sock, encodings) {
  const offered = state.h264Disabled ? encodings.filter((encoding) => encoding !== H264_ENCODING) : encodings;
  state.h264Offered = offered.includes(H264_ENCODING);
  return writeClientEncodings.call(this, sock, offered);
};

// The guard's report: replace the current connection (its 'disconnect' reaches finishAttempt, which reconnects).
function pictureFailed({ reason, detail }) {
  if (rfb === null || recovery !== null) {
    return;   // no connection to replace, or one already on its way out
  }
  const now = performance.now();
  failuresInARow = now - lastFailureAt > RECOVERY_CALM_MS ? 1 : failuresInARow + 1;
  lastFailureAt = now;
  state.pictureFailures += 1;
  state.lastPictureFailure = { reason, detail, at: now };
  console.warn(`rfbsim: the picture could not be decoded (${detail}); reconnecting`);
  if (failuresInARow >= H264_FAILURES_BEFORE_JPEG && !state.h264Disabled) {
    state.h264Disabled = true;
    console.warn(`rfbsim: H.264 failed ${failuresInARow} times in a row; asking for JPEG from now on`);
  }

  // The view's keyboard focus is noted now: noVNC's disconnect takes the canvas away, and the focus with it.
  recovery = {
    delayMs: RECOVERY_BACKOFF_MS[Math.min(failuresInARow, RECOVERY_BACKOFF_MS.length) - 1],
    focus: state.focused,
  };
  state.recovering = true;
  recoveringSince = now;
  clearTimeout(recoveryNoticeTimer);
  recoveryNoticeTimer = setTimeout(showProgress, RECOVERY_NOTICE_MS);
  holdPicture(canvas);
  rfb.disconnect();
}

// Keeps a still copy of the frozen picture behind noVNC's (transparent, see connect) view until the new connection
// draws its first picture; 'contain' letterboxes it the way noVNC's scaleViewport does.
function holdPicture(view) {
  if (view === null || view.width === 0 || view.height === 0) {
    return;
  }
  try {
    const url = view.toDataURL('image/jpeg', 0.9);
    ui.screen.style.background = `#1e1e1e url("${url}") center / contain no-repeat`;
    heldPicture = true;
  } catch (err) {
    console.warn('rfbsim: could not keep the last picture on screen:', err);
  }
}

// The recovery (or a reconnection) is over: a new picture shows, or the page says why there is none. Either way
// the held picture goes.
function endRecovery() {
  state.recovering = false;
  clearTimeout(recoveryNoticeTimer);
  recoveryNoticeTimer = null;
  if (heldPicture) {
    ui.screen.style.background = '';
    heldPicture = false;
  }
  if (rfb !== null) {
    rfb.background = '#1e1e1e';
  }
}

// ---------------------------------------------------------------------------------------------------------------
// One connection attempt. noVNC clients cannot be reused after 'disconnect', so every attempt makes a new one.
// The socket is opened at once: under sim_manager it is held until the session is ready, so the first frame
// comes as early as it can; the status is polled meanwhile to show the start-up progress.
// ---------------------------------------------------------------------------------------------------------------
// An automatic try that has not connected after this long is given up (and counts as failed): a network that
// swallows packets would otherwise leave the socket opening for minutes. First attempts have no limit, because
// the manager holds their socket while the session starts.
const RETRY_CONNECT_TIMEOUT_MS = 15_000;

function connect({ focusWhenConnected = false } = {}) {
  if (state.connecting || state.connected) {
    return;
  }
  clearTimeout(retryTimer);
  retryTimer = null;
  state.attempts += 1;
  state.connecting = true;
  pictureShown = false;
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
    finishAttempt({ kind: 'failed', clean: false, code: null, wasClean: false, reason: String(err) });
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
    finishAttempt({ kind: 'failed', clean: false, code: null, wasClean: false, reason: String(err) });
    return;
  }
  rfb = client;
  startStatusPolling();

  // View: scaled to the window and letterboxed; the session keeps its own size.
  client.scaleViewport = true;
  client.clipViewport = false;
  client.resizeSession = false;
  client.focusOnClick = true;
  client.showDotCursor = true;
  client.viewOnly = watching;
  // While a frozen picture is held behind the view (see holdPicture), the view lets it show until it has its own.
  client.background = heldPicture ? 'transparent' : '#1e1e1e';
  if (options.quality !== null) {
    client.qualityLevel = options.quality;
  }
  if (options.compression !== null) {
    client.compressionLevel = options.compression;
  }

  // The canvas: reachable with Tab, announced to screen readers, and watched for focus and the first picture.
  canvas = ui.screen.querySelector('canvas');
  view = canvas;
  if (canvas !== null) {
    canvas.tabIndex = 0;
    canvas.setAttribute('role', 'application');
    canvas.setAttribute('aria-label', watching ? 'Simulator view, watched (view only).'
                                                : 'Simulator view. Use W, A, S and D to walk.');
    canvas.addEventListener('focus', updateFocus);
    canvas.addEventListener('blur', updateFocus);
    watchForFirstPicture(client, canvas);
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
    finishAttempt({ kind, clean, code: closeInfo.code, wasClean: closeInfo.wasClean,
                    reason: securityReason || closeInfo.reason },
                  { view, hadFocus: closeInfo.hadFocus });
  });
}

// ---------------------------------------------------------------------------------------------------------------
// Reconnecting by itself after a lost connection (the rule is reconnect_policy.js's): the last picture stays on
// screen with a notice over it, tries follow with growing waits for as long as the session is alive, and the
// first new picture ends it all; keys reach the view again if it had them when the connection was lost.
// ---------------------------------------------------------------------------------------------------------------
let retryTimer = null;    // the wait before the next automatic try, or null
let retryFocus = false;   // the view gets the keyboard back once a try connects

// The next try, after delayMs; `loss` is the attempt that just ended ({ info, view, hadFocus, hadPicture }).
function scheduleRetry(retry, delayMs, { info, view, hadFocus, hadPicture }) {
  if (!state.reconnecting) {
    state.reconnecting = true;
    state.lastLoss = { kind: info.kind, code: info.code, reason: info.reason, at: performance.now() };
    if (hadPicture && !heldPicture) {
      holdPicture(view);
    }
  }
  // A picture failure whose new connection did not get through is a lost connection now.
  state.recovering = false;
  clearTimeout(recoveryNoticeTimer);
  retryFocus = retryFocus || hadFocus;
  state.retries = retry;
  clearTimeout(retryTimer);
  retryTimer = setTimeout(retryNow, delayMs);
  showProgress();
}

function retryNow() {
  clearTimeout(retryTimer);
  retryTimer = null;
  connect({ focusWhenConnected: retryFocus });
}

// Reconnecting is over: a picture is back, or the page shows why there will be none.
function stopReconnecting() {
  clearTimeout(retryTimer);
  retryTimer = null;
  state.reconnecting = false;
  retryFocus = false;
  ui.notice.hidden = true;
}

// Called once per attempt when it is over: forget the client, ask the manager (if any) whether the session is
// over for good, and then try again, or say what happened. `view` and `hadFocus`: the attempt's canvas, and
// whether it had the keyboard when the connection closed.
async function finishAttempt(info, { view = null, hadFocus = false } = {}) {
  if (canvas !== null) {
    canvas.removeEventListener('focus', updateFocus);
    canvas.removeEventListener('blur', updateFocus);
  }
  const hadPicture = pictureShown;
  const upMs = pictureShown ? performance.now() - pictureAt : 0;
  // The connection's decoders are gone with it: nothing they do from now on is a failure of the next one.
  h264Guard.retire();
  rfb = null;
  canvas = null;
  state.connecting = false;
  state.connected = false;
  showStatus('');
  updateFocus();

  // Over for good when the manager says the session is neither starting nor running, or no longer knows it: a
  // reconnect cannot help.
  const session = await fetchSessionStatus();
  if (session.view === 'gone' && sessionLost) {
    survey.ended();
    recovery = null;
    stopReconnecting();
    endRecovery();
    state.lastDisconnect = { ...info, kind: 'ended', final: true, sessionState: 'lost', message: SESSION_LOST_WORDS };
    showDisconnected(SESSION_LOST_TITLE, SESSION_LOST_WORDS, true);
    return;
  }
  if (session.view === 'over' || session.view === 'gone') {
    let message;
    if (session.view === 'gone') {
      message = 'This session is no longer available on the server.';
    } else {
      message = SESSION_OVER_WORDS[session.endsAs] || `The session is over (${session.endsAs}).`;
      if (RESTARTABLE_STATES.has(session.endsAs)) {
        message += ' Opening your study link again starts a new session.';
      }
    }
    if (state.completionCode !== null) {
      message += ` Your completion code: ${state.completionCode}`;
    }
    survey.ended();
    recovery = null;
    stopReconnecting();
    endRecovery();
    state.lastDisconnect = { ...info, kind: 'ended', final: true, sessionState: session.state, message };
    showDisconnected('Session ended', message, true);
    return;
  }

  // A connection replaced after a picture failure: connect again, quietly, after the series' wait.
  if (recovery !== null) {
    const { delayMs, focus } = recovery;
    recovery = null;
    showProgress();
    setTimeout(() => connect({ focusWhenConnected: focus }), delayMs);
    return;
  }

  // A lost connection: try again by itself. A connection that showed a picture long enough ended the last series
  // of tries, so a new loss starts from the shortest wait.
  if (!state.reconnecting && hadPicture && upMs >= SERIES_CALM_MS) {
    state.retries = 0;
  }
  const step = nextStep({ kind: info.kind, session: session.view, retries: state.retries });
  if (step.action === 'retry') {
    scheduleRetry(step.retry, step.delayMs, { info, view, hadFocus, hadPicture });
    return;
  }
  stopReconnecting();
  endRecovery();

  let title;
  let message;
  let action = 'Reconnect';
  switch (info.kind) {
    case 'taken-over':
      title = 'Opened elsewhere';
      message = 'This session was opened in another window or tab.';
      action = 'Use it here';
      break;
    case 'ended':
      title = 'Session ended';
      message = 'The simulator closed the connection.';
      break;
    case 'refused':
      title = 'Connection refused';
      message = 'The simulator refused the connection.';
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
  if (info.kind === 'taken-over') {
    message += ' Press \u201cUse it here\u201d to continue in this window (the other one then stops).';
  } else {
    if (info.reason) {
      message += ` (${info.reason})`;
    }
    message += ' Press Reconnect to try again.';
  }
  state.lastDisconnect = { ...info, final: false, sessionState: session.state, message };
  showDisconnected(title, message, false, action);
}

// ---------------------------------------------------------------------------------------------------------------
// Wiring.
// ---------------------------------------------------------------------------------------------------------------
// The panel's button: one attempt at the person's word (after the tries ran out, a refusal, or a takeover), and a
// new series of tries should it fail.
ui.reconnect.addEventListener('click', () => {
  ui.reconnect.disabled = true;
  state.retries = 0;
  connect({ focusWhenConnected: true });
});

// The notice's button: the next try now rather than after its wait.
ui.reconnectNow.addEventListener('click', () => {
  if (retryTimer !== null) {
    retryFocus = true;
    retryNow();
  }
});

// The browser saw the network come back: no reason to sit out the rest of a wait.
window.addEventListener('online', () => {
  if (retryTimer !== null) {
    retryNow();
  }
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
