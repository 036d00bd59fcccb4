// SPDX-License-Identifier: GPL-2.0-or-later
// What follows each connection attempt. A first picture ends any series of tries; an attempt that is over asks the
// manager (if any) whether the session is, and then the page says so, replaces a connection whose picture could not
// be decoded, tries a lost one again by itself, or shows the panel with a button.
//
// Reconnecting by itself after a lost connection (the rule is reconnect_policy.js's): the last picture stays on
// screen with a notice over it, tries follow with growing waits for as long as the session is alive, and the first
// new picture ends it all; keys reach the view again if it had them when the connection was lost.

import { SERIES_CALM_MS, nextStep } from './reconnect_policy.js';
import { forgetConnection, openConnection } from './connection.js';
import { SESSION_LOST_TITLE, SESSION_LOST_WORDS, disconnectPanel, sessionOverMessage } from './disconnect_words.js';
import { page, state, survey, ui } from './page_state.js';
import { showDisconnected, showProgress, showStatus, updateFocus } from './page_view.js';
import { endRecovery, holdPicture, pictureHeld, recoveryBecameLoss, retireDecoders, takeRecovery }
  from './picture_recovery.js';
import { fetchSessionStatus, sessionIsLost, startStatusPolling } from './session_status.js';

let retryFocus = false;   // the view gets the keyboard back once a try connects (page.retryTimer: the wait itself)

/** Starts a connection attempt (none while one is under way or connected); `focusWhenConnected`: give the view the
 *  keyboard once it connects. */
export function connect({ focusWhenConnected = false } = {}) {
  openConnection({ focusWhenConnected, onPicture: firstPictureShown, onOver: finishAttempt });
}

/** Makes the waiting automatic try now rather than after its wait (none waiting: nothing); `focus`: the view gets
 *  the keyboard once it connects. */
export function retryWithoutWaiting({ focus = false } = {}) {
  if (page.retryTimer !== null) {
    if (focus) {
      retryFocus = true;
    }
    retryNow();
  }
}

// The current attempt's first picture: any reconnecting or recovery is over, and the survey hears that it started.
function firstPictureShown() {
  page.pictureShown = true;
  page.pictureAt = performance.now();
  if (state.reconnecting) {
    state.reconnects += 1;
    stopReconnecting();
  }
  if (state.recovering || pictureHeld()) {
    endRecovery();
  }
  if (state.firstFrameAt === null) {
    state.firstFrameAt = performance.now();
  }
  survey.started();
  showProgress();
  startStatusPolling();
}

// The next try, after delayMs; `loss` is the attempt that just ended ({ info, view, hadFocus, hadPicture }).
function scheduleRetry(retry, delayMs, { info, view, hadFocus, hadPicture }) {
  if (!state.reconnecting) {
    state.reconnecting = true;
    state.lastLoss = { kind: info.kind, code: info.code, reason: info.reason, at: performance.now() };
    if (hadPicture && !pictureHeld()) {
      holdPicture(view);
    }
  }
  // A picture failure whose new connection did not get through is a lost connection now.
  recoveryBecameLoss();
  retryFocus = retryFocus || hadFocus;
  state.retries = retry;
  clearTimeout(page.retryTimer);
  page.retryTimer = setTimeout(retryNow, delayMs);
  showProgress();
}

function retryNow() {
  clearTimeout(page.retryTimer);
  page.retryTimer = null;
  connect({ focusWhenConnected: retryFocus });
}

// Reconnecting is over: a picture is back, or the page shows why there will be none.
function stopReconnecting() {
  clearTimeout(page.retryTimer);
  page.retryTimer = null;
  state.reconnecting = false;
  retryFocus = false;
  ui.notice.hidden = true;
}

// Called once per attempt when it is over: forget the client, ask the manager (if any) whether the session is
// over for good, and then try again, or say what happened. `view` and `hadFocus`: the attempt's canvas, and
// whether it had the keyboard when the connection closed.
async function finishAttempt(info, { view = null, hadFocus = false } = {}) {
  const hadPicture = page.pictureShown;
  const upMs = page.pictureShown ? performance.now() - page.pictureAt : 0;
  retireDecoders();
  forgetConnection();
  state.connecting = false;
  state.connected = false;
  showStatus('');
  updateFocus();

  // Over for good when the manager says the session is neither starting nor running, or no longer knows it: a
  // reconnect cannot help.
  const session = await fetchSessionStatus();
  if (session.view === 'gone' && sessionIsLost()) {
    survey.ended();
    takeRecovery();   // nothing left to replace
    stopReconnecting();
    endRecovery();
    state.lastDisconnect = { ...info, kind: 'ended', final: true, sessionState: 'lost', message: SESSION_LOST_WORDS };
    showDisconnected(SESSION_LOST_TITLE, SESSION_LOST_WORDS, true);
    return;
  }
  if (session.view === 'over' || session.view === 'gone') {
    const message = sessionOverMessage(session.view, session.endsAs, state.completionCode);
    survey.ended();
    takeRecovery();   // nothing left to replace
    stopReconnecting();
    endRecovery();
    state.lastDisconnect = { ...info, kind: 'ended', final: true, sessionState: session.state, message };
    showDisconnected('Session ended', message, true);
    return;
  }

  // A connection replaced after a picture failure: connect again, quietly, after the series' wait.
  const recovery = takeRecovery();
  if (recovery !== null) {
    const { delayMs, focus } = recovery;
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

  const { title, message, action } = disconnectPanel(info.kind, info.reason);
  state.lastDisconnect = { ...info, final: false, sessionState: session.state, message };
  showDisconnected(title, message, false, action);
}
