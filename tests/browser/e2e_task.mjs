// SPDX-License-Identifier: GPL-2.0-or-later
// The whole study task, end to end, in Chromium (or Firefox ESR with --browser firefox): a survey page on its own
// origin frames a participant's link to sim_manager with the shipped warehouse scenario, and a scripted participant
// (task_participant.mjs) does the task with real key presses in the page: find the robot, follow it for the 30 s
// the task asks, walk to the marker. It learns where everything is from the session's own data as sim_rfb writes it. Then the task's
// events must be in order (found, following, followed 30 s, marker reached, completed), the data must agree
// with what the task monitor counted, the survey must show the success code, and the session must have ended
// as completed in session.json, manager.json and the manager's index.
//
// Usage: node e2e_task.mjs [--browser chromium|firefox] SIM_MANAGER SIM_RFB WEB_ROOT ARTIFACTS_DIR [WEB_DIR]
//   SIM_MANAGER    the sim_manager executable to start
//   SIM_RFB        the sim_rfb executable it starts for the session
//   WEB_ROOT       the assembled web root (build/web/root) sim_manager serves
//   ARTIFACTS_DIR  where screenshots (task_*.png), the participant's log (task.json), sim_manager's output,
//                  its data folder (task-data) and the browser console are written (created)
//   WEB_DIR        the source web/ folder whose node_modules holds playwright-core (default: ../../web from here)
// Environment: RFBSIM_CHROMIUM (default /usr/bin/chromium), RFBSIM_E2E_TIMEOUT_S (default 270).
// Exits 0 when every check passed, 1 on the first failed check, 2 on the overall timeout.

import fs from 'node:fs';
import path from 'node:path';

import { check, log, pageState, parseManagerArgs, runTest, sleep, stopSimCleanly } from './e2e_support.mjs';
import { CODE_SUCCESS, checkEnd, readEvents, startTaskSession, taskStory } from './e2e_task_support.mjs';
import { loadScenarioLayout } from './scenario_layout.mjs';
import { SessionTail } from './session_tail.mjs';
import { ScriptedParticipant } from './task_participant.mjs';

const UID = 'e2e-task';
const END_GRACE_S = 3;   // sim_rfb --end-grace: the session ends 3 s after the outcome, not the warehouse's 15
// The participant must be done within this of the first picture: the task's own limit is 240 s, and a
// participant that needs longer is broken (it takes 90-120 s here: ~25 s to find the robot, 30 s following,
// ~40 s to the marker).
const PARTICIPANT_DEADLINE_MS = 200_000;
const KEYSYMS = { w: 0x77, a: 0x61, d: 0x64, s: 0x73 };   // X11 keysyms of the keys pressed
const env = parseManagerArgs('e2e_task.mjs');

const distance = (a, b) => Math.hypot(a.x - b.x, a.y - b.y);

// Checks, from the trajectories alone, what the task monitor said at each step (an independent count).
function checkAgainstData(folder, session, events, layout) {
  const tail = new SessionTail(folder).update();
  const samples = tail.samples;
  const steps = layout.scenario.task.steps;
  const at = (tick) => samples.reduce((best, s) => (Math.abs(s.tick - tick) < Math.abs(best.tick - tick) ? s : best));
  const done = (index) => events.find((e) => e.type === 'task' && e.event === 'done' && e.index === index);
  const started = (index) => events.find((e) => e.type === 'task' && e.event === 'started' && e.index === index);
  // m: the most two bodies' distance changes between a tick and the nearest sample (1.5 m/s, faster than the
  // avatar walks and the robot drives together, over one sample interval).
  const slack = 1.5 / session.trajectory_hz;

  // Found: the robot within the step's range at the tick the monitor said so.
  const found = at(done(0).tick);
  check(distance(found.avatar, found.robot) <= steps[0].distance + slack,
        `find_robot was done at tick ${done(0).tick} with the robot ${distance(found.avatar, found.robot).toFixed(2)} m away`);
  // Followed: the samples between the follow step's start and its end within its range add up to its duration.
  const hz = session.trajectory_hz;
  const during = samples.filter((s) => s.tick > started(1).tick && s.tick <= done(1).tick);
  const inRange = during.map((s) => distance(s.avatar, s.robot) <= steps[1].distance);
  const near = inRange.filter(Boolean).length;
  // The monitor counts every tick in range; the samples see one tick in six, so each stretch in range may
  // show up to one sample interval short at its ends.
  const stretches = inRange.filter((isIn, i) => isIn && (i === 0 || !inRange[i - 1])).length;
  const followed = (done(1).tick - started(1).tick) / session.tick_hz;
  check(followed >= steps[1].duration - 1e-6,
        `follow_robot was done ${followed.toFixed(2)} s after it started; it asks ${steps[1].duration} s`);
  check(near / hz >= steps[1].duration - (stretches + 1) / hz,
        `the trajectories have the avatar within ${steps[1].distance} m of the robot for only ${(near / hz).toFixed(1)} s ` +
        `of the follow step (needs ${steps[1].duration} s)`);
  // Reached: the avatar at the marker.
  const target = layout.reachTarget(2);
  const reached = at(done(2).tick);
  check(distance(reached.avatar, target) <= steps[2].tolerance + slack,
        `reach was done at tick ${done(2).tick} with the avatar ${distance(reached.avatar, target).toFixed(2)} m ` +
        `from ${target.name}`);
  return { foundApart: distance(found.avatar, found.robot), followedS: followed, nearS: near / hz,
           followMaxApart: Math.max(...during.map((s) => distance(s.avatar, s.robot))),
           reachedFrom: distance(reached.avatar, target) };
}

async function main() {
  // The warehouse's task as shipped; only the 15 s the outcome stays on screen before the end are cut to 3.
  const run = await startTaskSession(env, {
    tag: 'task', uid: UID, sessionArgs: ['--end-grace', String(END_GRACE_S)],
  });
  const { driver, page, frame, folder, session } = run;
  // The Chromium test's files keep their names; a Firefox run's get a firefox_ prefix.
  const prefix = env.browser === 'chromium' ? '' : `${env.browser}_`;
  const artifact = (name) => path.join(env.artifacts, `${prefix}${name}`);
  const layout = loadScenarioLayout(session.scenario_file);
  const stepTypes = layout.scenario.task.steps.map((s) => s.type).join();
  check(stepTypes === 'find_robot,follow_robot,reach' &&
        JSON.stringify(session.tasks.map((t) => t.type)) === JSON.stringify(['find_robot', 'follow_robot', 'reach']),
        `the warehouse's task is ${stepTypes} (session.json: ${JSON.stringify(session.tasks)}); this test knows ` +
        'find_robot, follow_robot, reach');
  log(`warehouse task: ${JSON.stringify(layout.scenario.task)}; the marker is ${layout.reachTarget(2).name} at ` +
      `(${layout.reachTarget(2).x}, ${layout.reachTarget(2).y})`);

  // A click on the picture gives it the keyboard, as a participant is told to do.
  await driver.click(frame, '#screen canvas');
  check((await pageState(frame)).focused, 'the simulator view does not have the keyboard after a click');
  await run.shot('start');

  // The participant does the task.
  const tail = new SessionTail(folder);
  const participant = new ScriptedParticipant({ page, tail, layout, session, log });
  const startedAt = Date.now();
  const traceFile = artifact('task.json');
  let summary;
  try {
    summary = await participant.run(startedAt + PARTICIPANT_DEADLINE_MS);
  } finally {
    // What the participant saw and did, kept also when it failed (replaced by the full record on success).
    fs.writeFileSync(traceFile, JSON.stringify({ pulses: participant.pulses, trace: participant.trace }, null, 1));
  }
  log(`participant done in ${((Date.now() - startedAt) / 1000).toFixed(1)} s wall: ${summary.pulses.turn} turns, ` +
      `${summary.pulses.walk} walks, ${summary.pulses.back} back-offs; learnt turn rate ` +
      `${summary.turnRate.toFixed(2)} rad/s, walking speed ${summary.walkSpeed.toFixed(2)} m/s`);
  await sleep(1500);   // the code is drawn in the picture: keep it in the screenshot
  await run.shot('completed');

  // The end, everywhere it is recorded.
  const ended = await checkEnd(run, UID, 'completed', CODE_SUCCESS);
  await page.screenshot({ path: artifact('task_ended.png') });

  // The task's events, in order.
  const events = readEvents(folder);
  const story = taskStory(events);
  const expected = [
    'timer started',
    'task started 0 find_robot', 'task done 0 find_robot',
    'task started 1 follow_robot', 'task done 1 follow_robot',
    'task started 2 reach', 'task done 2 reach',
    `outcome completed ${CODE_SUCCESS}`,
    'session end completed',
  ];
  log(`task events: ${story.join('; ')}`);
  check(JSON.stringify(story) === JSON.stringify(expected),
        `events.jsonl tells ${JSON.stringify(story)}; expected ${JSON.stringify(expected)}`);
  check(JSON.stringify(ended.tasks_done.map((t) => t.type)) === JSON.stringify(['find_robot', 'follow_robot', 'reach']),
        `session.json tasks_done: ${JSON.stringify(ended.tasks_done)}`);

  // The keys came from the page, through a real client, and were the ones the participant pressed.
  const keys = events.filter((e) => e.type === 'key');
  const pressed = new Set(keys.filter((e) => e.down).map((e) => e.keysym));
  const releases = keys.filter((e) => !e.down).length;
  check(keys.every((e) => e.client !== 0) && pressed.has(KEYSYMS.w) && (pressed.has(KEYSYMS.a) || pressed.has(KEYSYMS.d)) &&
        [...pressed].every((k) => Object.values(KEYSYMS).includes(k)) && releases === participant.releases,
        `key events in events.jsonl: ${keys.length} (${releases} releases, the participant sent ` +
        `${participant.releases}), keysyms ${[...pressed].map((k) => k.toString(16)).join(' ')}`);

  // The data agrees with the monitor.
  const measured = checkAgainstData(folder, ended, events, layout);
  const taskTime = (events.find((e) => e.type === 'outcome').time - events.find((e) => e.type === 'timer').time);
  log(`from the data: robot ${measured.foundApart.toFixed(2)} m away when found; ${measured.nearS.toFixed(1)} s ` +
      `within range while following (at most ${measured.followMaxApart.toFixed(2)} m apart), step took ` +
      `${measured.followedS.toFixed(1)} s; ${measured.reachedFrom.toFixed(2)} m from the marker; task done in ` +
      `${taskTime.toFixed(1)} s simulated`);

  fs.writeFileSync(traceFile, JSON.stringify({
    story, measured, taskTimeS: taskTime, pulses: summary.pulses, turnRate: summary.turnRate,
    walkSpeed: summary.walkSpeed, trace: summary.trace,
  }, null, 1));
  check(run.pageLog.pageErrors.length === 0, `uncaught errors in the page: ${run.pageLog.pageErrors.join(' | ')}`);
  await stopSimCleanly(run.manager);
  await run.pageLog.close();
}

await runTest(`${env.browser === 'chromium' ? 'browser' : env.browser}_e2e_task`, 270, main);
