// SPDX-License-Identifier: GPL-2.0-or-later
// What the participant page knows and shares between its modules: its elements, its state (window.rfbsimState),
// the options from its query string, whether a researcher is watching, and the survey reporter. Importing this
// module sets rfbsimState up, so every other module of the page imports it first (app.js's first import).

import { SurveyReporter } from './survey.js';

// ---------------------------------------------------------------------------------------------------------------
// Page elements (all exist in index.html).
// ---------------------------------------------------------------------------------------------------------------
export const ui = {
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
export const state = {
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

// ---------------------------------------------------------------------------------------------------------------
// What the page's modules share beyond rfbsimState, not shown to tests. ES modules cannot assign one another's
// variables, so each value that one module writes and another reads lives here; the comment names the writer.
// ---------------------------------------------------------------------------------------------------------------
export const page = {
  rfb: null,             // the current noVNC client, or null while disconnected (connection.js)
  canvas: null,          // that client's canvas; noVNC makes a new one for every client (connection.js)
  pictureShown: false,   // the current client has drawn its first picture (connection.js, reconnect.js)
  pictureAt: 0,          // performance.now() when it did (reconnect.js)
  startingSince: null,   // { elapsedS, at }: the session's start-up time as last reported, and when
                         // (session_status.js)
  recoveringSince: 0,    // performance.now() of the picture failure being recovered from (picture_recovery.js)
  retryTimer: null,      // the wait before the next automatic try, or null (reconnect.js; cleared as an attempt
                         // starts, connection.js)
};

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
export const options = {
  quality: readLevel(params, 'quality'),           // null = noVNC's default (6)
  compression: readLevel(params, 'compression'),   // null = noVNC's default (2)
};
state.options = options;

// A researcher watching from the admin page (/admin/watch/<token>/, or under a host's path prefix behind a balancer,
// /h2/admin/watch/<token>/): the manager drops this page's keys and pointer anyway; here the view is read-only and
// never invites anyone to walk.
export const watching = /\/admin\/watch\/[0-9a-f]{32}\/[^/]*$/.test(window.location.pathname);
state.watching = watching;

// The survey around this page (if any) hears how the session goes; a researcher's watching page tells no one.
export const survey = new SurveyReporter(watching ? null : window.parent, window);
state.outcome = null;          // 'completed' | 'timeout' | 'watched' once the task has an outcome (from sim_manager)
state.watcher = false;         // a video-condition session (sim_manager's status): the participant only watches
state.completionCode = null;   // the code the link carried for that outcome
state.surveyEvents = survey.sent;  // the events posted to the survey so far (a Set, for tests)
