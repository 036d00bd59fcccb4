// SPDX-License-Identifier: GPL-2.0-or-later
// web/survey.js without a browser: which messages a SurveyReporter posts to a fake parent window, to which
// origins, in what order, and when it stays silent (not framed, before the status named the uid).
// Usage: node survey_reporter_test.mjs WEB_DIR     Exits 0 when every check passed, 1 otherwise.
import assert from 'node:assert/strict';
import path from 'node:path';
import { pathToFileURL } from 'node:url';

const webDir = process.argv[2];
if (!webDir) {
  console.error('usage: node survey_reporter_test.mjs WEB_DIR');
  process.exit(1);
}
const { SurveyReporter } = await import(pathToFileURL(path.join(webDir, 'survey.js')).href);

function fakeParent() {
  const posted = [];
  return { posted, postMessage(message, origin) { posted.push({ message, origin }); } };
}
const self = {};
const status = (extra = {}) => ({ state: 'running', uid: 'P1', outcome: null, code: null,
                                  survey_origins: ['https://survey.example', 'https://other.example'], ...extra });
let failures = 0;
function check(name, body) {
  try {
    body();
    console.log(`ok   ${name}`);
  } catch (err) {
    failures += 1;
    console.log(`FAIL ${name}\n     ${err.message}`);
  }
}

check('a page that is not framed (or is watched) posts nothing', () => {
  const reporter = new SurveyReporter(self, self);
  reporter.update(status({ outcome: 'completed', code: 'C1' }));
  reporter.started();
  reporter.ended();
  assert.equal(reporter.enabled, false);
  const watched = new SurveyReporter(null, self);
  watched.started();
  assert.equal(watched.enabled, false);
});

check('each event goes once to each configured origin, and only there', () => {
  const parent = fakeParent();
  const reporter = new SurveyReporter(parent, self);
  reporter.update(status());
  reporter.started();
  reporter.started();
  assert.deepEqual(parent.posted, [
    { message: { type: 'rfbsim', event: 'started', uid: 'P1', code: null, outcome: null },
      origin: 'https://survey.example' },
    { message: { type: 'rfbsim', event: 'started', uid: 'P1', code: null, outcome: null },
      origin: 'https://other.example' },
  ]);
  assert.ok(parent.posted.every(({ origin }) => origin !== '*'));
});

check('events wait for the status that names the uid and the origins', () => {
  const parent = fakeParent();
  const reporter = new SurveyReporter(parent, self);
  reporter.started();
  assert.equal(parent.posted.length, 0);
  reporter.update(status({ survey_origins: ['https://survey.example'] }));
  assert.deepEqual(parent.posted.map(({ message }) => message.event), ['started']);
});

check('the outcome carries its code, comes after started, and ended repeats the code', () => {
  const parent = fakeParent();
  const reporter = new SurveyReporter(parent, self);
  reporter.update(status({ outcome: 'timeout', code: 'LATE-2', survey_origins: ['https://survey.example'] }));
  reporter.started();
  reporter.update(status({ outcome: 'timeout', code: 'LATE-2', survey_origins: ['https://survey.example'] }));
  reporter.ended();
  assert.deepEqual(parent.posted.map(({ message }) => [message.event, message.code, message.outcome]),
                   [['started', null, null], ['timeout', 'LATE-2', 'timeout'], ['ended', 'LATE-2', 'timeout']]);
});

check('a watcher shown the recording to its end hears watched with the video condition code', () => {
  const parent = fakeParent();
  const reporter = new SurveyReporter(parent, self);
  reporter.update(status({ survey_origins: ['https://survey.example'], condition: 'video' }));
  reporter.started();
  reporter.update(status({ outcome: 'watched', code: 'VID-7', survey_origins: ['https://survey.example'],
                           condition: 'video' }));
  reporter.ended();
  assert.deepEqual(parent.posted.map(({ message }) => [message.event, message.code, message.outcome]),
                   [['started', null, null], ['watched', 'VID-7', 'watched'], ['ended', 'VID-7', 'watched']]);
});

check('a session that never showed a picture and had no outcome sends ended alone', () => {
  const parent = fakeParent();
  const reporter = new SurveyReporter(parent, self);
  reporter.update(status({ state: 'failed', survey_origins: ['https://survey.example'] }));
  reporter.ended();
  assert.deepEqual(parent.posted.map(({ message }) => message.event), ['ended']);
});

check('no configured origin means no message at all', () => {
  const parent = fakeParent();
  const reporter = new SurveyReporter(parent, self);
  reporter.update(status({ survey_origins: [] }));
  reporter.started();
  assert.equal(parent.posted.length, 0);
});

process.exit(failures === 0 ? 0 : 1);
