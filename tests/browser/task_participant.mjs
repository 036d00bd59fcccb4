// SPDX-License-Identifier: GPL-2.0-or-later
// A scripted participant for the study task (find the robot, follow it, reach the marker): a closed-loop
// controller that presses W, A and D in the page like a person at the keyboard, and learns where it is,
// where the robot and the people are, and which step the task monitor is on from the session's own recorded
// data (session_tail.mjs), as the simulator writes it.
//
// It steers in pulses: hold a key for a computed time, release it, then wait until the data shows the
// simulator's state after that release (the release's tick is in events.jsonl), and decide again. Turn rate
// and walking speed are learnt from the pulses themselves, and the body radii come from session.json, so the
// controller depends on neither the avatar's parameters nor the robot's navigation.

import { CheckFailed, sleep } from './e2e_support.mjs';
import { headFor, pathLength, planPath, segmentClear } from './grid_path.mjs';

// ---------------------------------------------------------------------------------------------------------------
// Settings.
// ---------------------------------------------------------------------------------------------------------------
const MARGIN_M = 0.15;             // kept between the avatar's body and walls or props where the way allows
const PEOPLE_MARGIN_M = 0.15;      // kept between the avatar's body and a person's or the robot's
const PEOPLE_RANGE_M = 5;          // people farther than this are not planned around (they will have moved)
const LOOKAHEAD_M = 4;             // how far along the path the avatar heads in a straight line
const MAX_WALK_M = 2.5;            // the longest walk in one pulse: the data then says where it ended
const TURN_TOLERANCE_RAD = 0.3;    // a heading this close is good enough to walk on
const FINE_TOLERANCE_M = 0.08;     // on the last metre to a point: lateral miss allowed by the heading
const MIN_PULSE_S = 0.05;          // a shorter key press may fall between two ticks
const MAX_TURN_PULSE_S = 1.0;
const SETTLE_S = 0.3;              // after a release the avatar stops within this (it decelerates)
const DATA_TIMEOUT_MS = 8000;      // the data must show a release within this (synced every 0.5 s)
const IDLE_MS = 300;               // the wait when there is nothing to do but let the task monitor count
const STUCK_AFTER = 2;             // walk pulses in a row that got nowhere before backing off
// Before the first pulse: rough guesses only; each pulse corrects them.
const INITIAL_TURN_RATE = 1.5;     // rad/s
const INITIAL_WALK_SPEED = 1.0;    // m/s

const wrap = (angle) => Math.atan2(Math.sin(angle), Math.cos(angle));
const distance = (a, b) => Math.hypot(a.x - b.x, a.y - b.y);
const xy = (p) => `(${p.x.toFixed(2)}, ${p.y.toFixed(2)})`;

/// The participant. `page`: the playwright page whose focused frame has the simulator view (keys go to it);
/// `tail`: the session's SessionTail; `layout`: the scenario's layout (scenario_layout.mjs); `session`: the
/// session.json written at the start (tick_hz, agents' radii, tasks); `log`: progress lines.
export class ScriptedParticipant {
  constructor({ page, tail, layout, session, log }) {
    this.page = page;
    this.tail = tail;
    this.layout = layout;
    this.log = log;
    this.tickHz = session.tick_hz;
    const radiusOf = (kind) => (session.agents.find((a) => a.kind === kind) || {}).radius;
    this.avatarRadius = radiusOf('avatar');
    this.robotRadius = radiusOf('robot');
    this.personRadius = radiusOf('person') ?? 0.25;
    if (!(this.avatarRadius > 0) || !(this.robotRadius > 0)) {
      throw new CheckFailed(`session.json lists no avatar and robot with a radius: ${JSON.stringify(session.agents)}`);
    }
    this.steps = layout.scenario.task.steps;
    this.turnRate = INITIAL_TURN_RATE;
    this.walkSpeed = INITIAL_WALK_SPEED;
    this.releases = 0;        // key releases sent; the data must show as many
    this.stuck = 0;
    this.backOffSide = 1;
    this.trace = [];          // one entry per decision, for the artifacts
    this.pulses = { turn: 0, walk: 0, back: 0 };
  }

  // ---- What the data says. ----

  // The index of the step the task monitor is on, 'outcome' once there is one, or -1 before the timer.
  taskStep() {
    if (this.tail.eventsOf('outcome').length > 0) {
      return 'outcome';
    }
    const started = this.tail.eventsOf('task', 'started');
    return started.length > 0 ? started[started.length - 1].index : -1;
  }

  // Updates the data and returns its newest sample (waits for the first one).
  async sample() {
    for (const deadline = Date.now() + DATA_TIMEOUT_MS; Date.now() < deadline; await sleep(100)) {
      const s = this.tail.update().latest();
      if (s && s.avatar && s.robot) {
        return s;
      }
    }
    throw new CheckFailed(`no trajectory sample with the avatar and the robot in ${this.tail.folder}`);
  }

  // ---- Keys. ----

  // Holds `key` for `seconds`, then waits until the data shows the state after the release. Returns the
  // sample then and the hold as the simulator counted it (s, from the key events' ticks).
  async pulse(key, seconds) {
    await this.page.keyboard.down(key);
    await sleep(1000 * seconds);
    await this.page.keyboard.up(key);
    this.releases += 1;
    const releases = await this.waitFor(`the simulator to record key release ${this.releases} (${key})`, () => {
      const ups = this.tail.eventsOf('key').filter((e) => !e.down);
      return ups.length >= this.releases ? ups : null;
    });
    const up = releases[this.releases - 1];
    const keys = this.tail.eventsOf('key');
    const down = keys.slice(0, keys.indexOf(up)).reverse().find((e) => e.down && e.keysym === up.keysym);
    const settled = up.tick + Math.ceil(SETTLE_S * this.tickHz);
    const after = await this.waitFor(`a trajectory sample at tick ${settled} or later`, () => {
      const s = this.tail.latest();
      return s && s.tick >= settled && s.robot ? s : null;
    });
    return { after, held: down ? (up.tick - down.tick) / this.tickHz : seconds };
  }

  async waitFor(what, fn) {
    for (const deadline = Date.now() + DATA_TIMEOUT_MS; ; await sleep(50)) {
      this.tail.update();
      const value = fn();
      if (value) {
        return value;
      }
      if (Date.now() > deadline) {
        throw new CheckFailed(`timed out after ${DATA_TIMEOUT_MS} ms waiting for ${what} in ${this.tail.folder}`);
      }
    }
  }

  // Turns by `error` rad (positive: left, A) and learns the turn rate from what the data shows.
  async turn(before, error) {
    const seconds = Math.min(MAX_TURN_PULSE_S, Math.max(MIN_PULSE_S, Math.abs(error) / this.turnRate));
    const { after, held } = await this.pulse(error > 0 ? 'a' : 'd', seconds);
    this.pulses.turn += 1;
    const turned = Math.abs(wrap(after.avatar.yaw - before.avatar.yaw));
    if (held >= 0.1 && turned > 0.02) {
      this.turnRate = 0.5 * this.turnRate + 0.5 * (turned / held);
    }
    return after;
  }

  // Walks about `metres` forward and learns the walking speed; backs off after pulses that got nowhere
  // (a person or the robot in the way).
  async walk(before, metres) {
    const seconds = Math.max(MIN_PULSE_S, metres / this.walkSpeed);
    const { after, held } = await this.pulse('w', seconds);
    this.pulses.walk += 1;
    const moved = distance(after.avatar, before.avatar);
    if (held >= 0.4 && moved > 0.5 * this.walkSpeed * held) {
      this.walkSpeed = 0.5 * this.walkSpeed + 0.5 * (moved / held);
    }
    this.stuck = metres > 0.3 && moved < 0.25 * metres ? this.stuck + 1 : 0;
    if (this.stuck >= STUCK_AFTER) {
      this.log(`participant: stuck at ${xy(after.avatar)}; backing off`);
      this.stuck = 0;
      this.pulses.back += 1;
      await this.pulse('s', 0.6);
      this.backOffSide = -this.backOffSide;
      return this.turn(await this.sample(), 0.8 * this.backOffSide);
    }
    return after;
  }

  // ---- Going places. ----

  // One pulse toward `goal`, stopping `stopAt` m short of it (0: onto it). `obstacles`: discs to keep out of.
  // Returns true once within stopAt (nothing pressed then).
  async stepToward(s, goal, stopAt, obstacles) {
    const me = s.avatar;
    const straight = distance(me, goal);
    if (straight <= stopAt) {
      return true;
    }
    const clearance = this.avatarRadius + MARGIN_M;
    const path = planPath(this.layout, me, goal, clearance, obstacles) ??
                 planPath(this.layout, me, goal, clearance) ??
                 planPath(this.layout, me, goal, this.avatarRadius + 0.02);
    if (!path) {
      throw new CheckFailed(`no way from ${xy(me)} to ${xy(goal)} on the scenario's map`);
    }
    const precise = stopAt === 0 && straight < 1.5 && segmentClear(this.layout, me, goal, this.avatarRadius);
    const aim = precise ? goal : headFor(this.layout, me, path, LOOKAHEAD_M, this.avatarRadius + 0.05);
    const error = wrap(Math.atan2(aim.y - me.y, aim.x - me.x) - me.yaw);
    const tolerance = precise ? Math.max(0.05, Math.atan2(FINE_TOLERANCE_M, straight)) : TURN_TOLERANCE_RAD;
    const remaining = Math.max(0, (precise ? straight : pathLength(path)) - stopAt);
    this.note(s, goal, Math.abs(error) > tolerance ? 'turn' : 'walk');
    if (Math.abs(error) > tolerance) {
      await this.turn(s, error);
    } else {
      await this.walk(s, Math.min(remaining, distance(me, aim) + 0.3, MAX_WALK_M));
    }
    return false;
  }

  // The people nearby, and the robot unless it is where we go, as discs the avatar's centre keeps out of.
  obstaclesOf(s, withRobot) {
    const discs = s.people
      .filter((p) => distance(p, s.avatar) < PEOPLE_RANGE_M)
      .map((p) => ({ x: p.x, y: p.y, r: this.personRadius + this.avatarRadius + PEOPLE_MARGIN_M }));
    if (withRobot) {
      discs.push({ x: s.robot.x, y: s.robot.y, r: this.robotRadius + this.avatarRadius + PEOPLE_MARGIN_M });
    }
    return discs;
  }

  note(s, goal, action) {
    this.trace.push({ tick: s.tick, step: this.taskStep(), avatar: s.avatar, robot: s.robot,
                      goal: { x: goal.x, y: goal.y }, action });
  }

  // ---- The task. ----

  /// Does the task until the monitor reports an outcome, or until `deadline` (Date.now() ms). Resolves with
  /// a summary: { outcome, pulses, turnRate, walkSpeed, trace }.
  async run(deadline) {
    let lastStep = null;
    for (;;) {
      const s = await this.sample();
      const step = this.taskStep();
      if (step !== lastStep) {
        this.log(`participant: task step ${step} (${this.steps[step]?.type ?? step}); avatar at ` +
                 `${xy(s.avatar)}, robot at ${xy(s.robot)}, ${distance(s.avatar, s.robot).toFixed(2)} m apart`);
        lastStep = step;
      }
      if (step === 'outcome') {
        break;
      }
      if (Date.now() > deadline) {
        throw new CheckFailed(`the participant ran out of time on task step ${step} (avatar at ${xy(s.avatar)}, ` +
                              `robot at ${xy(s.robot)})`);
      }
      const type = step >= 0 ? this.steps[step].type : null;
      const range = step >= 0 ? this.steps[step].distance : 0;
      const apart = distance(s.avatar, s.robot);
      if (type === 'find_robot') {
        // Close in until the robot is well inside the range with nothing between, then look at it.
        const near = 0.7 * range;
        const inSight = apart <= near && segmentClear(this.layout, s.avatar, s.robot, 0.05);
        if (!inSight) {
          // Near but with a shelf between: go on round it, closer.
          const stopAt = apart > near ? near - 0.5 : 0.3 * range;
          if (await this.stepToward(s, s.robot, stopAt, this.obstaclesOf(s, false))) {
            await sleep(IDLE_MS);
          }
        } else {
          const error = wrap(Math.atan2(s.robot.y - s.avatar.y, s.robot.x - s.avatar.x) - s.avatar.yaw);
          this.note(s, s.robot, Math.abs(error) > TURN_TOLERANCE_RAD ? 'face' : 'wait');
          if (Math.abs(error) > TURN_TOLERANCE_RAD) {
            await this.turn(s, error);
          } else {
            await sleep(IDLE_MS);
          }
        }
      } else if (type === 'follow_robot') {
        // Stay well within the range: close in when the robot draws away, else stand and let the time count.
        if (apart > 0.6 * range) {
          if (await this.stepToward(s, s.robot, 0.45 * range, this.obstaclesOf(s, false))) {
            await sleep(IDLE_MS);
          }
        } else {
          this.note(s, s.robot, 'wait');
          await sleep(IDLE_MS);
        }
      } else if (type === 'reach') {
        const target = this.layout.reachTarget(step);
        if (await this.stepToward(s, target, 0, this.obstaclesOf(s, true))) {
          await sleep(IDLE_MS);
        }
      } else {
        // Before the timer (no viewer counted yet), or a step this participant does not know.
        if (type !== null) {
          throw new CheckFailed(`the scripted participant cannot do task step ${step} (${type})`);
        }
        await sleep(IDLE_MS);
      }
    }
    return { outcome: this.tail.eventsOf('outcome')[0], pulses: this.pulses, turnRate: this.turnRate,
             walkSpeed: this.walkSpeed, trace: this.trace };
  }
}
