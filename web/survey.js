// SPDX-License-Identifier: GPL-2.0-or-later
// Tells a survey that embeds this page (in an iframe) how the session goes: postMessage to the parent window of
// {type: "rfbsim", event: "started" | "completed" | "timeout" | "watched" | "ended", uid, code, outcome}, each event
// once, and only to the survey origins sim_manager is configured with (its status says which). "watched": a
// video-condition participant was shown their recording to its end (`code` is the link's t1). `outcome` is the
// session's outcome so far (null before it has one); sim_manager's own page for a video link with no recording
// free sends event "unavailable" then "ended" with outcome "unavailable" (manager/http/pages.hpp). postMessage with a target origin
// is delivered only if the parent's origin is that one, so a page framed by anyone else hears nothing.

export const SURVEY_EVENTS = ['started', 'completed', 'timeout', 'watched', 'ended'];
const OUTCOMES = ['completed', 'timeout', 'watched'];

export class SurveyReporter {
  // `target`: the window told (the parent); `self`: this page's window. Not framed (target === self): silent.
  constructor(target, self) {
    this.target = target;
    this.enabled = target !== null && target !== undefined && target !== self;
    this.uid = null;
    this.origins = [];
    this.outcome = null;
    this.code = null;
    this.sent = new Set();
    this.pending = [];   // events waiting for the first status, which names the uid and the origins
    this.known = false;
  }

  // Takes one answer of sim_manager's status ({uid, outcome, code, survey_origins, ...}).
  update(status) {
    if (status === null || typeof status !== 'object') {
      return;
    }
    if (typeof status.uid === 'string') {
      this.uid = status.uid;
    }
    if (Array.isArray(status.survey_origins)) {
      this.origins = status.survey_origins.filter((origin) => typeof origin === 'string' && origin !== '');
    }
    this.known = this.uid !== null;
    if (OUTCOMES.includes(status.outcome)) {
      this.outcome = status.outcome;
      this.code = typeof status.code === 'string' ? status.code : null;
      this.post(status.outcome);
    }
    const waiting = this.pending;
    this.pending = [];
    waiting.forEach((event) => this.post(event));
  }

  // The first picture showed.
  started() {
    this.post('started');
  }

  // The session is over for good.
  ended() {
    this.post('ended');
  }

  post(event) {
    if (!this.enabled || this.sent.has(event)) {
      return;
    }
    // A survey hears 'started' before an outcome, whatever came first here: an outcome can be polled before
    // the first picture shows (a task done at once, or a hidden tab that draws nothing). A session that
    // never showed a picture and ended without an outcome (it failed to start) sends 'ended' alone.
    if (OUTCOMES.includes(event) && !this.sent.has('started')) {
      this.post('started');
    }
    if (!this.known) {
      if (!this.pending.includes(event)) {
        this.pending.push(event);
      }
      return;
    }
    this.sent.add(event);
    // 'ended' carries the outcome's code too, so that a survey listening only for it still gets the code.
    const code = event === 'started' ? null : this.code;
    const outcome = event === 'started' ? null : this.outcome;
    const message = { type: 'rfbsim', event, uid: this.uid, code, outcome };
    for (const origin of this.origins) {
      try {
        this.target.postMessage(message, origin);
      } catch (err) {
        // A malformed origin in the configuration: skip it, the others still hear.
      }
    }
  }
}
