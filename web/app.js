// SPDX-License-Identifier: GPL-2.0-or-later
// rfbsim participant page: connects noVNC to this session's simulator and keeps hints and messages in step.
// The entry point (esbuild bundles it and everything it imports into app.bundle.js, which index.html loads): it
// wires the page's buttons and events and makes the first connection. The work is in the modules it imports:
//   page_state.js       elements, window.rfbsimState, query options, watching, the survey reporter
//   page_view.js        the progress line, the keyboard hint, the reconnecting notice, the disconnect panel
//   session_status.js   the manager's status of this session, polled
//   connection.js       one connection attempt (a WebSocket and a noVNC client) and its first picture
//   first_picture.js    spotting that first picture without reading noVNC's canvas back
//   picture_recovery.js replacing a connection whose picture could not be decoded (H.264), JPEG after repeats
//   reconnect.js        what follows an attempt: trying again by itself, or saying why not
//   disconnect_words.js what the disconnect panel says

// page_state.js comes first: importing it sets window.rfbsimState up before anything else runs.
import { page, state, ui } from './page_state.js';
import { updateFocus } from './page_view.js';
import { connect, retryWithoutWaiting } from './reconnect.js';

// The panel's button: one attempt at the person's word (after the tries ran out, a refusal, or a takeover), and a
// new series of tries should it fail.
ui.reconnect.addEventListener('click', () => {
  ui.reconnect.disabled = true;
  state.retries = 0;
  connect({ focusWhenConnected: true });
});

// The notice's button: the next try now rather than after its wait.
ui.reconnectNow.addEventListener('click', () => {
  retryWithoutWaiting({ focus: true });
});

// The browser saw the network come back: no reason to sit out the rest of a wait.
window.addEventListener('online', () => {
  retryWithoutWaiting();
});

// A click on the letterbox around the picture also gives the view the keyboard (noVNC only listens on the
// canvas). preventDefault keeps the browser from moving focus to the page body afterwards.
ui.screen.addEventListener('mousedown', (event) => {
  if (page.rfb !== null && event.target !== page.canvas) {
    event.preventDefault();
    page.rfb.focus({ preventScroll: true });
  }
});

window.addEventListener('focus', updateFocus);
window.addEventListener('blur', updateFocus);

connect();
