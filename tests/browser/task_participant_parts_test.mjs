// SPDX-License-Identifier: GPL-2.0-or-later
// The scripted participant's pure parts without a browser or simulator: a scenario's layout (a tiny hand-made
// room: 3 x 3 m, a 0.2 x 1.6 m prop across its lower middle), paths around that prop, and reading a session's
// data while it is still being written.
// Usage: node task_participant_parts_test.mjs     Exits 0 when every check passed, 1 otherwise.
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';

import { headFor, planPath, segmentClear } from './grid_path.mjs';
import { loadScenarioLayout } from './scenario_layout.mjs';
import { SessionTail } from './session_tail.mjs';

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
const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'rfbsim-participant-test-'));
process.on('exit', () => fs.rmSync(dir, { recursive: true, force: true }));

// The room: a 60 x 60 pixel map at 0.05 m with a one-pixel wall all round; a prop 0.2 m across (x 1.4-1.6)
// from the floor to y 1.6.
const pixels = Buffer.alloc(60 * 60, 254);
for (let i = 0; i < 60; i += 1) {
  pixels[i] = pixels[59 * 60 + i] = pixels[i * 60] = pixels[i * 60 + 59] = 0;
}
fs.writeFileSync(path.join(dir, 'room.pgm'), Buffer.concat([Buffer.from('P5\n# room\n60 60\n255\n'), pixels]));
fs.writeFileSync(path.join(dir, 'room.yaml'), 'image: room.pgm\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\n' +
                 'negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n');
fs.writeFileSync(path.join(dir, 'scenario.yaml'), [
  'map: room.yaml',
  'props:',
  '  - kind: shelf',
  '    pose: [1.5, 0.8, 0.0]',
  '    size: [0.2, 1.6, 2.0]',
  'spawns:',
  '  west: [0.5, 0.5, 0.0]',
  '  east: [2.5, 0.5, 3.1416]',
  'landmarks:',
  '  - name: mark',
  '    position: east',
  'avatar:',
  '  start: west',
  '  goal: mark',
  'task:',
  '  steps:',
  '    - type: reach',
].join('\n'));
const layout = loadScenarioLayout(path.join(dir, 'scenario.yaml'));
const west = { x: 0.55, y: 0.55 };
const east = { x: 2.45, y: 0.55 };

check('layout: cells, clearance to the walls and the prop, named points', () => {
  assert.equal(layout.cols, 30);
  assert.equal(layout.rows, 30);
  // Cell (5, 10) lies 5 cells from the west wall's cells and 8 from the prop's (its cells reach 1.35 m).
  assert.ok(Math.abs(layout.clearanceAt(0.55, 1.05) - 0.5) < 1e-9, `${layout.clearanceAt(0.55, 1.05)}`);
  assert.equal(layout.clearanceAt(1.5, 1.0), 0);            // inside the prop
  assert.ok(layout.clearanceAt(1.5, 1.75) < 0.2);           // just above it
  assert.equal(layout.clearanceAt(-1, 1), 0);               // off the map
  assert.deepEqual(layout.point('mark'), { x: 2.5, y: 0.5 });
  assert.deepEqual(layout.reachTarget(0), { x: 2.5, y: 0.5, name: 'mark' });
  assert.throws(() => layout.point('nowhere'), /scenario\.yaml: point '"nowhere"' is not/);
});

check('layout: a scenario file that is not YAML is an error naming it', () => {
  const broken = path.join(dir, 'broken.yaml');
  fs.writeFileSync(broken, 'map: room.yaml\nprops: [1, 2\n');
  assert.throws(() => loadScenarioLayout(broken), (err) => err.message.startsWith(`${broken}: `));
});

check('paths: round the prop, with the clearance asked for, or none', () => {
  assert.equal(segmentClear(layout, west, east, 0.1), false);
  assert.equal(segmentClear(layout, west, { x: 0.55, y: 2.45 }, 0.3), true);
  const path_ = planPath(layout, west, east, 0.3);
  assert.ok(path_, 'no path round the prop');
  assert.ok(Math.hypot(path_[0].x - west.x, path_[0].y - west.y) < 0.1);
  assert.ok(Math.hypot(path_.at(-1).x - east.x, path_.at(-1).y - east.y) < 0.1);
  assert.ok(path_.every((p) => layout.clearanceAt(p.x, p.y) >= 0.3));
  assert.ok(Math.max(...path_.map((p) => p.y)) > 1.9, 'the path does not go over the prop');
  // Heading straight for the farthest point in sight: up past the prop on its west side, not into it.
  const aim = headFor(layout, west, path_, 10, 0.3);
  assert.ok(aim.x < 1.5 && aim.y > 1.9 && segmentClear(layout, west, aim, 0.3), JSON.stringify(aim));
  // No way with more clearance than the gap above the prop has, nor through a disc that fills the gap.
  assert.equal(planPath(layout, west, east, 0.7), null);
  assert.equal(planPath(layout, west, east, 0.3, [{ x: 1.5, y: 2.3, r: 0.8 }]), null);
});

check('session data: whole lines only, samples end when the next tick begins', () => {
  const folder = path.join(dir, 'session');
  fs.mkdirSync(folder);
  const csv = path.join(folder, 'trajectories.csv');
  const events = path.join(folder, 'events.jsonl');
  const tail = new SessionTail(folder);
  assert.equal(tail.update().latest(), null);   // nothing written yet
  fs.writeFileSync(csv, 'tick,time,kind,id,x,y,yaw,vx,vy\n0,0.000000,avatar,0,1,2,0.5,0,0\n0,0.0000');
  fs.writeFileSync(events, '{"tick":0,"time":0.0,"type":"session","event":"start"}\n{"tick":6,');
  tail.update();
  assert.equal(tail.latest(), null);            // the robot's row is not whole yet
  assert.equal(tail.events.length, 1);
  fs.appendFileSync(csv, '00,robot,0,3,4,-1,0,0\n0,0.000000,person,1,5,6,0,0,0\n6,0.100000,avatar,0,1.1,2,0.5,0,0\n');
  fs.appendFileSync(events, '"time":0.1,"type":"key","keysym":119,"down":true,"client":1}\n');
  tail.update();
  assert.equal(tail.samples.length, 1);
  assert.deepEqual(tail.samples[0], { tick: 0, time: 0, avatar: { x: 1, y: 2, yaw: 0.5 },
                                      robot: { x: 3, y: 4, yaw: -1 }, people: [{ id: 1, x: 5, y: 6, yaw: 0 }] });
  assert.equal(tail.latest().tick, 0);          // tick 6 has no robot row yet
  assert.deepEqual(tail.eventsOf('key').map((e) => e.keysym), [119]);
  fs.appendFileSync(csv, '6,0.100000,robot,0,3,3.9,-1,0,0\n');
  assert.equal(tail.update().latest().tick, 6);
  const bad = new SessionTail(dir);
  fs.writeFileSync(path.join(dir, 'trajectories.csv'), 'time,tick\n');
  assert.throws(() => bad.update(), /trajectories\.csv: header 'time,tick'/);
});

if (failures > 0) {
  console.log(`${failures} check(s) failed`);
  process.exit(1);
}
console.log('all checks passed');
