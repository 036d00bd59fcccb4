// SPDX-License-Identifier: GPL-2.0-or-later
// What the demo survey (web/survey-demo.html) heard, for the browser tests that drive it (e2e_survey.mjs,
// e2e_video_condition.mjs): every message its top window received, and the demo's own record.

// Records, in the top window only, every message event whatever its origin: window.__e2eMessages.
export function recordAllMessages() {
  if (window !== window.top) {
    return;
  }
  window.__e2eMessages = [];
  window.addEventListener('message', (event) => {
    const data = event.data && typeof event.data === 'object' ? event.data : { value: String(event.data) };
    window.__e2eMessages.push({ origin: event.origin, ...data });
  });
}

export const demoState = (page) => page.evaluate(() => JSON.parse(JSON.stringify(window.surveyDemo || null)));
export const rawMessages = (page) => page.evaluate(() => window.__e2eMessages || []);
export const describeMessages = (messages) => messages.map((m) => `${m.event}${m.code ? `(${m.code})` : ''}`).join(', ') || 'none';
