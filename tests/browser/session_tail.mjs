// SPDX-License-Identifier: GPL-2.0-or-later
// Follows a running session's recorded data (docs/data.md) as sim_rfb writes it: the samples of
// trajectories.csv (every agent's pose at one tick) and the lines of events.jsonl, read on from where the last
// read stopped. sim_rfb writes and syncs both every 0.5 s and at every task event; a last line without its
// newline is not read until it is whole. This is how a scripted participant learns where it is, where the
// robot is, and what the task monitor counted.

import fs from 'node:fs';
import path from 'node:path';

// Reads the whole lines added to one file since the last call.
class LineTail {
  constructor(file) {
    this.file = file;
    this.offset = 0;
    this.partial = '';
  }

  // The new whole lines ([] while the file does not exist yet).
  read() {
    let fd;
    try {
      fd = fs.openSync(this.file, 'r');
    } catch (err) {
      if (err.code === 'ENOENT') {
        return [];
      }
      throw err;
    }
    try {
      const chunks = [];
      const buffer = Buffer.alloc(1 << 16);
      for (;;) {
        const n = fs.readSync(fd, buffer, 0, buffer.length, this.offset);
        if (n === 0) {
          break;
        }
        chunks.push(Buffer.from(buffer.subarray(0, n)));
        this.offset += n;
      }
      const text = this.partial + Buffer.concat(chunks).toString('utf8');
      const lines = text.split('\n');
      this.partial = lines.pop();
      return lines.filter((line) => line.length > 0);
    } finally {
      fs.closeSync(fd);
    }
  }
}

/// One session folder's data as it grows. `samples` holds every complete trajectory sample in order, each
/// { tick, time, avatar, robot, people } with poses { x, y, yaw }; `events` every event object in order.
export class SessionTail {
  constructor(folder) {
    this.folder = folder;
    this.trajectories = new LineTail(path.join(folder, 'trajectories.csv'));
    this.eventLines = new LineTail(path.join(folder, 'events.jsonl'));
    this.header = null;
    this.pending = null;   // the sample whose rows are still coming (a sample ends when the next tick begins)
    this.samples = [];
    this.events = [];
  }

  /// Reads what was added to both files since the last call.
  update() {
    for (const line of this.eventLines.read()) {
      try {
        this.events.push(JSON.parse(line));
      } catch (err) {
        throw new Error(`${this.folder}/events.jsonl: a line that is not JSON: ${line}`);
      }
    }
    for (const line of this.trajectories.read()) {
      if (this.header === null) {
        this.header = line.split(',');
        const want = 'tick,time,kind,id,x,y,yaw,vx,vy';
        if (line !== want) {
          throw new Error(`${this.folder}/trajectories.csv: header '${line}', expected '${want}'`);
        }
        continue;
      }
      const [tick, time, kind, id, x, y, yaw] = line.split(',');
      const row = { tick: Number(tick), time: Number(time), kind, id: Number(id), x: Number(x), y: Number(y),
                    yaw: Number(yaw) };
      if (this.pending && this.pending.tick !== row.tick) {
        this.samples.push(this.pending);
        this.pending = null;
      }
      this.pending ??= { tick: row.tick, time: row.time, avatar: null, robot: null, people: [] };
      const pose = { x: row.x, y: row.y, yaw: row.yaw };
      if (kind === 'avatar') {
        this.pending.avatar = pose;
      } else if (kind === 'robot') {
        this.pending.robot = pose;
      } else {
        this.pending.people.push({ id: row.id, ...pose });
      }
    }
    return this;
  }

  /// The newest sample with the avatar's row and, in a session with a robot, the robot's (rows come avatar,
  /// robot, people: the newest sample's people may still be coming); null before there is one.
  latest() {
    const last = this.samples.length > 0 ? this.samples[this.samples.length - 1] : null;
    const withRobot = last ? last.robot !== null : false;
    if (this.pending && this.pending.avatar && (this.pending.robot !== null || (last && !withRobot))) {
      return this.pending;
    }
    return last;
  }

  /// The events of `type` (and, when given, with event === `event`).
  eventsOf(type, event) {
    return this.events.filter((e) => e.type === type && (event === undefined || e.event === event));
  }
}
