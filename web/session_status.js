// SPDX-License-Identifier: GPL-2.0-or-later
// The manager's view of this session, asked of its status (GET status -> {"state": "starting" | "running" |
// "ending" | <final>, "ends_as": <the state it ends in>, "elapsed_s": seconds since the link was opened, and the
// outcome, code, program and survey origins}): the page polls it while it waits for a picture, inside a survey
// while the session runs, and after every connection to learn whether the session is over for good.

import { sessionView } from './reconnect_policy.js';
import { page, state, survey, ui } from './page_state.js';
import { showProgress, updateFocus } from './page_view.js';

// The address is relative to this page so that it works both under sim_manager (/s/<token>/) and from sim_rfb
// itself (/, where 'status' does not exist).
const statusUrl = new URL('status', window.location.href);
statusUrl.search = '';
statusUrl.hash = '';

const STATUS_POLL_MS = 250;       // while no picture shows, the status is asked for this often
const OUTCOME_POLL_MS = 1000;     // in a survey, while the session runs: how soon the survey hears the outcome
const STATUS_TIMEOUT_MS = 2000;   // one status request may take this long

let statusAvailable = true;  // false once 'status' answered that there is nothing more to ask (see noStatusView)
let noStatusView = 'none';   // what an unavailable status means: 'none' (sim_rfb's 404) or 'gone' (the manager's)
let managed = false;         // a manager has answered this page's status at least once
let programHintSet = false;  // the hint names no WASD: the session runs another program than sim_rfb
let statusPolling = false;   // the polling loop runs
let sessionLost = false;     // the balancer said this session's host is gone (see disconnect_words.js)

/** True once a balancer answered that this session's host is gone (HTTP 410 with {"state": "lost"}). */
export function sessionIsLost() {
  return sessionLost;
}

function timeoutSignal(ms) {
  return typeof AbortSignal.timeout === 'function' ? AbortSignal.timeout(ms) : undefined;
}

// Asks for the session's status. Resolves with { view, state, endsAs, elapsedS }: view is reconnect_policy.js's
// sessionView ('live', 'over', 'gone', 'none' or 'unknown'); the rest are null unless the manager answered.
export async function fetchSessionStatus() {
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
  // A video-condition session: its participant watches a recording, and their keys do nothing.
  if (body.condition === 'video' && !state.watcher) {
    state.watcher = true;
    updateFocus();
  }
  if ((body.outcome === 'completed' || body.outcome === 'timeout' || body.outcome === 'watched') &&
      state.outcome === null) {
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
  page.startingSince = status.state === 'starting' && status.elapsedS !== null
    ? { elapsedS: status.elapsedS, at: performance.now() } : null;
  return status;
}

// Polls the status while a connection is being made or its first picture is awaited, updating the progress line;
// once the picture shows, asks once more so that rfbsimState.sessionState is current.
export function startStatusPolling() {
  if (statusPolling) {
    return;
  }
  statusPolling = true;
  (async () => {
    while (statusAvailable && (state.connecting || state.connected) && !page.pictureShown) {
      await fetchSessionStatus();
      showProgress();
      await new Promise((resolve) => setTimeout(resolve, STATUS_POLL_MS));
    }
    if (page.pictureShown) {
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
