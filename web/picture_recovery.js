// SPDX-License-Identifier: GPL-2.0-or-later
// A picture the browser could not decode (H.264 only, see h264_guard.js): noVNC 1.7 would wait for it forever, so
// the connection is replaced without a word. A new connection gets a new decoder, and the server starts its stream
// with a whole picture (an IDR). Meanwhile the frozen picture stays on screen, and if no new one shows within
// RECOVERY_NOTICE_MS the progress line says that it is being restored. Failures that follow one another wait longer
// each time (RECOVERY_BACKOFF_MS), so that a browser that fails on every picture never reconnects in a tight loop;
// after H264_FAILURES_BEFORE_JPEG of them the page stops offering H.264 and the server streams JPEG instead.
//
// Importing this module installs the guard and the encodings filter; reconnect.js makes the new connection when
// the old one has closed (takeRecovery).

import { installH264Guard } from './h264_guard.js';
import RFB from './novnc/core/rfb.js';
import { page, state, ui } from './page_state.js';
import { RECOVERY_NOTICE_MS, showProgress } from './page_view.js';

// Wait before the 1st, 2nd and 3rd reconnect in a row; the 3rd is the last one H.264 gets (the page then asks for
// JPEG, which needs no decoder), the last wait stands for any later one.
const RECOVERY_BACKOFF_MS = [0, 1000, 3000];
const RECOVERY_CALM_MS = 60_000;     // a failure this long after the last one starts a new series
const H264_FAILURES_BEFORE_JPEG = 3; // failures in one series after which H.264 is no longer offered
const H264_ENCODING = 50;            // RFB encoding number of H.264 rectangles

let recovery = null;           // { delayMs, focus } from a failure until its connection has closed
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
  if (page.rfb === null || recovery !== null) {
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
  page.recoveringSince = now;
  clearTimeout(recoveryNoticeTimer);
  recoveryNoticeTimer = setTimeout(showProgress, RECOVERY_NOTICE_MS);
  holdPicture(page.canvas);
  page.rfb.disconnect();
}

/** The connection's decoders are gone with it: nothing they do from now on is a failure of the next one. */
export function retireDecoders() {
  h264Guard.retire();
}

/** The replacement a picture failure asked for ({ delayMs, focus }), once its connection has closed, or null;
 *  taking it clears it. */
export function takeRecovery() {
  const taken = recovery;
  recovery = null;
  return taken;
}

/** A picture failure whose new connection did not get through is a lost connection now: no more notice. */
export function recoveryBecameLoss() {
  state.recovering = false;
  clearTimeout(recoveryNoticeTimer);
}

/** A frozen picture is held behind the view (the new connection's view lets it show until it has its own). */
export function pictureHeld() {
  return heldPicture;
}

// Keeps a still copy of the frozen picture behind noVNC's (transparent, see connection.js) view until the new
// connection draws its first picture; 'contain' letterboxes it the way noVNC's scaleViewport does.
export function holdPicture(view) {
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
export function endRecovery() {
  state.recovering = false;
  clearTimeout(recoveryNoticeTimer);
  recoveryNoticeTimer = null;
  if (heldPicture) {
    ui.screen.style.background = '';
    heldPicture = false;
  }
  if (page.rfb !== null) {
    page.rfb.background = '#1e1e1e';
  }
}
