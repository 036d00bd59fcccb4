// SPDX-License-Identifier: GPL-2.0-or-later
// The whole study task's other ending, in Chromium (or Firefox ESR with --browser firefox): the same survey and
// warehouse session as e2e_task.mjs, with the task's time limit cut to TIME_LIMIT_S (sim_rfb --time-limit, passed
// by sim_manager), and a participant who does nothing. The task must time out exactly at the limit with nothing done, the survey must show the timeout
// code, and the session must have ended as a timeout in session.json, manager.json and the manager's index.
//
// Usage: node e2e_task_timeout.mjs [--browser chromium|firefox] SIM_MANAGER SIM_RFB WEB_ROOT ARTIFACTS_DIR [WEB_DIR]
//   (as e2e_task.mjs; writes task_timeout_*.png, task_timeout-data and its logs)
// Environment: RFBSIM_CHROMIUM (default /usr/bin/chromium), RFBSIM_E2E_TIMEOUT_S (default 120).
// Exits 0 when every check passed, 1 on the first failed check, 2 on the overall timeout.

import { check, log, parseManagerArgs, runTest, stopSimCleanly } from './e2e_support.mjs';
import { CODE_TIMEOUT, checkEnd, readEvents, startTaskSession, taskStory } from './e2e_task_support.mjs';

const UID = 'e2e-task-idle';
const TIME_LIMIT_S = 8;   // instead of the warehouse's 240 s
const END_GRACE_S = 3;    // instead of its 15 s: the session ends 3 s after the timeout
const env = parseManagerArgs('e2e_task_timeout.mjs');

async function main() {
  const run = await startTaskSession(env, {
    tag: 'task_timeout', uid: UID,
    sessionArgs: ['--time-limit', String(TIME_LIMIT_S), '--end-grace', String(END_GRACE_S)],
  });
  check(run.session.time_limit_s === TIME_LIMIT_S && run.session.end_grace_s === END_GRACE_S,
        `session.json: time_limit_s ${run.session.time_limit_s}, end_grace_s ${run.session.end_grace_s}, expected ` +
        `${TIME_LIMIT_S} and ${END_GRACE_S}`);
  await run.shot('start');
  log(`the participant does nothing; the task times out after ${TIME_LIMIT_S} s`);

  const ended = await checkEnd(run, UID, 'timeout', CODE_TIMEOUT);
  await run.shot('ended');

  const events = readEvents(run.folder);
  const story = taskStory(events);
  const expected = ['timer started', 'task started 0 find_robot', `outcome timeout ${CODE_TIMEOUT}`,
                    'session end timeout'];
  log(`task events: ${story.join('; ')}`);
  check(JSON.stringify(story) === JSON.stringify(expected),
        `events.jsonl tells ${JSON.stringify(story)}; expected ${JSON.stringify(expected)}`);
  const keys = events.filter((e) => e.type === 'key');
  check(keys.length === 0, `${keys.length} key events recorded for a participant who pressed nothing`);
  // The clock: the outcome comes at the limit to the tick, counted from the first viewer.
  const timer = events.find((e) => e.type === 'timer');
  const outcome = events.find((e) => e.type === 'outcome');
  const elapsed = (outcome.tick - timer.tick) / ended.tick_hz;
  check(Math.abs(elapsed - TIME_LIMIT_S) < 1e-9 && ended.tasks_done.length === 0,
        `the timeout came ${elapsed} s after the timer started (limit ${TIME_LIMIT_S} s); tasks_done ` +
        JSON.stringify(ended.tasks_done));
  log(`timed out ${elapsed} s after the timer started, nothing done`);

  check(run.pageLog.pageErrors.length === 0, `uncaught errors in the page: ${run.pageLog.pageErrors.join(' | ')}`);
  await stopSimCleanly(run.manager);
  await run.pageLog.close();
}

await runTest(`${env.browser === 'chromium' ? 'browser' : env.browser}_e2e_task_timeout`, 120, main);
