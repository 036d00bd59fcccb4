// SPDX-License-Identifier: GPL-2.0-or-later
// What the participant page shows around the picture: the progress line, the keyboard hint, the notice while it
// reconnects by itself and the panel after a disconnect. These only draw what page_state.js holds; the modules that
// change it call them.

import { page, state, ui, watching } from './page_state.js';

/** Without a picture for this long (ms) after one could not be decoded, the progress line says that it is being
 *  restored (picture_recovery.js sets its timer by it). */
export const RECOVERY_NOTICE_MS = 2000;

// The progress line; `counter` (e.g. "3 s") is shown but not announced, and text is only set when it changes,
// so that screen readers hear each phase once.
export function showStatus(text, counter = '') {
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
export function showProgress() {
  if (state.reconnecting) {
    showStatus('');
    showReconnecting();
    return;
  }
  if (state.recovering) {
    const waited = performance.now() - page.recoveringSince;
    showStatus(waited >= RECOVERY_NOTICE_MS ? 'Restoring the picture\u2026' : '');
    return;
  }
  if (state.connected) {
    showStatus(page.pictureShown ? '' : 'Loading the picture\u2026');
  } else if (state.connecting) {
    if (state.sessionState === 'starting' && page.startingSince !== null) {
      const seconds = page.startingSince.elapsedS + (performance.now() - page.startingSince.at) / 1000;
      showStatus('Starting your simulation\u2026', `${Math.floor(seconds)} s`);
    } else {
      const again = state.attempts > 1;
      showStatus(again ? 'Reconnecting to the simulator\u2026' : 'Connecting to the simulator\u2026');
    }
  }
}

// The hint shows while a session is up and keys would not reach it (focus elsewhere, or the window/iframe
// itself not focused).
export function updateFocus() {
  state.focused = page.canvas !== null && document.hasFocus() && document.activeElement === page.canvas;
  // After the outcome the hint would cover the completion code drawn in the picture; a video-condition
  // participant only watches, and an offer of the keyboard would mislead them.
  ui.hint.hidden = watching || state.watcher || !state.connected || state.focused || state.outcome !== null;
}

// The notice while the page reconnects by itself: it leaves the (held) picture visible and asks for nothing, and
// its button tries at once instead of waiting; the text is only set when it changes (one announcement per try).
function showReconnecting() {
  const text = `Connection lost, reconnecting\u2026 (attempt ${state.retries})`;
  if (ui.noticeText.textContent !== text) {
    ui.noticeText.textContent = text;
  }
  ui.reconnectNow.disabled = page.retryTimer === null;
  ui.notice.hidden = false;
}

// The panel after a disconnect. `final`: the session is over for good, so there is nothing to reconnect to;
// `action`: the button's words where there is something to do.
export function showDisconnected(title, message, final, action = 'Reconnect') {
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
