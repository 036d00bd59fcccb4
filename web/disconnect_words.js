// SPDX-License-Identifier: GPL-2.0-or-later
// What the disconnect panel says, in the participant's words: why a session is over for good, and what became of
// a connection the page does not try again by itself. Pure (no DOM) so that the texts sit in one place apart from
// the logic that picks them (reconnect.js).

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
export const SESSION_LOST_TITLE = 'Session lost';
export const SESSION_LOST_WORDS = 'The server running your session stopped. Please go back to the survey and tell ' +
                                  'the researcher.';

// Sessions that did not run their course: the study link starts a new one.
const RESTARTABLE_STATES = new Set(['shutdown', 'crashed', 'failed', 'interrupted', 'abandoned']);

/** The panel's message for a session that is over: `view` is the status's 'over' or 'gone', `endsAs` the state it
 *  ended in, `completionCode` the link's code for the task's outcome (or null). */
export function sessionOverMessage(view, endsAs, completionCode) {
  let message;
  if (view === 'gone') {
    message = 'This session is no longer available on the server.';
  } else {
    message = SESSION_OVER_WORDS[endsAs] || `The session is over (${endsAs}).`;
    if (RESTARTABLE_STATES.has(endsAs)) {
      message += ' Opening your study link again starts a new session.';
    }
  }
  if (completionCode !== null) {
    message += ` Your completion code: ${completionCode}`;
  }
  return message;
}

/** The panel for a connection that is not tried again by itself, by reconnect_policy.js's kind of close ('taken-over',
 *  'ended', 'refused', 'lost', or any other for one that never connected): { title, message, action }, action
 *  being the button's words. `reason`: the server's words, if any. */
export function disconnectPanel(kind, reason) {
  let title;
  let message;
  let action = 'Reconnect';
  switch (kind) {
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
  if (kind === 'taken-over') {
    message += ' Press \u201cUse it here\u201d to continue in this window (the other one then stops).';
  } else {
    if (reason) {
      message += ` (${reason})`;
    }
    message += ' Press Reconnect to try again.';
  }
  return { title, message, action };
}
