// SPDX-License-Identifier: GPL-2.0-or-later
// When the participant page connects again by itself: what a closed connection means, what to do about it given
// what the manager says of the session, and how long to wait before the next try. Pure (no DOM, no timers, the
// random source passed in) so that node:test runs it as it is (tests/browser/reconnect_policy_test.mjs);
// connection.js and reconnect.js do the connecting, page_view.js the showing.
//
// The rule: a connection that was lost (the network, a relay, a proxy dropped it) is tried again, with growing
// waits and jitter, for as long as the manager says the session is alive, or cannot be asked (the network is the
// likely cause then). A close the server chose (the session ended, it was opened elsewhere, the page sent
// something it refused) is never tried again by itself: the page says why and leaves the choice to the person.

/** WebSocket close code sim_manager sends to a browser whose session was taken over by another window or tab. */
export const CLOSE_TAKEN_OVER = 4001;

/** Waits between automatic tries (ms): the first, the growth factor, the longest, and +/- this share of jitter. */
export const RETRY_BACKOFF = { firstMs: 500, factor: 2, maxMs: 10_000, jitter: 0.2 };

/** Without a manager to ask (sim_rfb serving the page itself) a lost connection gets this many tries, then the
 *  page offers Reconnect: nothing can say whether the simulator is coming back. */
export const STANDALONE_MAX_RETRIES = 6;

/** A connection that showed a picture and stayed up this long (ms) ends a series of tries: the next loss starts
 *  again from the shortest wait. Shorter ones keep the series going, so a link that drops at once never loops
 *  fast. */
export const SERIES_CALM_MS = 10_000;

// Codes with which a server turns down what this page sent (RFC 6455, section 7.4.1): trying the same again
// would meet the same answer.
const REFUSAL_CODES = new Set([1002, 1003, 1007, 1008, 1009, 1010]);

/**
 * Classes a closed connection from what the page saw of it:
 *  - connected: noVNC had reported the RFB session up on it;
 *  - clean: noVNC's own word (false when it failed the connection itself);
 *  - code: the WebSocket close code, or null where the socket never opened;
 *  - refused: the simulator turned the page down during the RFB handshake (a password, a security failure);
 *  - gaveUp: the page itself abandoned an attempt that took too long.
 * Returns 'taken-over' (4001: the session is open in another window), 'ended' (a close the server chose: 1000,
 * 1001, any other 4xxx, or a clean close without a code), 'refused', 'lost' (a working connection broke) or
 * 'failed' (an attempt that never got through).
 */
export function classifyClose({ connected = false, clean = false, code = null, refused = false, gaveUp = false }) {
  if (refused) {
    return 'refused';
  }
  if (gaveUp) {
    return 'failed';
  }
  if (code === CLOSE_TAKEN_OVER) {
    return 'taken-over';
  }
  if ((code >= 4000 && code <= 4999) || code === 1000 || code === 1001) {
    return 'ended';
  }
  if (code === 1005 && clean && connected) {
    return 'ended';   // a close frame without a code: deliberate, though the server did not say why
  }
  if (REFUSAL_CODES.has(code)) {
    return 'refused';
  }
  return connected ? 'lost' : 'failed';
}

/**
 * What the manager's `status` answer says about reconnecting: pass the HTTP status (null where the request itself
 * failed), whether the body was JSON, its `state` (or null), and whether a manager has answered this page before.
 * Returns 'live' (starting or running), 'over' (any other state), 'gone' (the manager no longer knows the
 * session: 404 or 410), 'none' (no manager: sim_rfb's plain 404 to a page that never heard from one) or
 * 'unknown' (no usable answer now: the network, a server error, a timeout).
 */
export function sessionView({ httpStatus = null, json = false, state = null, managed = false }) {
  if (httpStatus === null) {
    return 'unknown';
  }
  if (httpStatus >= 200 && httpStatus < 300 && json && typeof state === 'string') {
    return state === 'starting' || state === 'running' ? 'live' : 'over';
  }
  if (httpStatus === 404 || httpStatus === 410) {
    return json || managed ? 'gone' : 'none';
  }
  if (httpStatus >= 500) {
    return 'unknown';
  }
  // Anything else (a 2xx without a state, a 403 from a proxy): there is no manager this page can use.
  return managed ? 'unknown' : 'none';
}

/**
 * The next step after a connection closed: `kind` from classifyClose, `session` from sessionView, `retries` the
 * automatic tries already made in this series. Returns { action, retry?, delayMs? } where action is
 *  - 'end': the session is over or gone; nothing to reconnect to;
 *  - 'taken-over': offer to take the session back, once, at the person's word;
 *  - 'retry': try again by itself after delayMs (retry: the number of this try in the series, from 1);
 *  - 'offer': show what happened with a Reconnect button.
 * random() gives the jitter (0 <= x < 1; Math.random by default).
 */
export function nextStep({ kind, session, retries = 0 }, random = Math.random) {
  if (session === 'over' || session === 'gone') {
    return { action: 'end' };
  }
  if (kind === 'taken-over') {
    return { action: 'taken-over' };
  }
  if (kind !== 'lost' && kind !== 'failed') {
    return { action: 'offer' };
  }
  if (session === 'none' && retries >= STANDALONE_MAX_RETRIES) {
    return { action: 'offer' };
  }
  const retry = retries + 1;
  return { action: 'retry', retry, delayMs: retryDelayMs(retry, random) };
}

/**
 * The wait (ms, whole) before automatic try number `retry` (from 1): firstMs, doubling each time up to maxMs,
 * then spread by +/- jitter so that pages cut off together (a relay restart) do not all come back at once.
 */
export function retryDelayMs(retry, random = Math.random) {
  const { firstMs, factor, maxMs, jitter } = RETRY_BACKOFF;
  const steps = Math.max(0, Math.min(retry - 1, 30));   // 30: far past maxMs, and no overflow
  const nominal = Math.min(maxMs, firstMs * factor ** steps);
  const spread = 1 - jitter + 2 * jitter * Math.min(Math.max(random(), 0), 1);
  return Math.round(nominal * spread);
}
