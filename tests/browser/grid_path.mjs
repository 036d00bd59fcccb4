// SPDX-License-Identifier: GPL-2.0-or-later
// Paths for a scripted participant on a scenario layout (scenario_layout.mjs): A* over the grid cells with at
// least a given clearance, keeping out of discs to avoid (people nearby), preferring the middle of an aisle;
// and where to head next along a path, as far ahead as the way is clear.

import { forEachNeighbour } from './scenario_layout.mjs';

// A binary min-heap of cell indices keyed by a score.
class MinHeap {
  constructor() {
    this.items = [];
  }

  get size() {
    return this.items.length;
  }

  push(index, score) {
    const items = this.items;
    items.push({ index, score });
    let i = items.length - 1;
    while (i > 0) {
      const parent = (i - 1) >> 1;
      if (items[parent].score <= items[i].score) {
        break;
      }
      [items[parent], items[i]] = [items[i], items[parent]];
      i = parent;
    }
  }

  pop() {
    const items = this.items;
    const top = items[0];
    const last = items.pop();
    if (items.length > 0) {
      items[0] = last;
      let i = 0;
      for (;;) {
        const l = 2 * i + 1;
        const r = l + 1;
        let m = i;
        if (l < items.length && items[l].score < items[m].score) {
          m = l;
        }
        if (r < items.length && items[r].score < items[m].score) {
          m = r;
        }
        if (m === i) {
          break;
        }
        [items[m], items[i]] = [items[i], items[m]];
        i = m;
      }
    }
    return top.index;
  }
}

const PREFERRED_EXTRA_M = 0.6;   // clearance beyond the minimum that a path seeks where the way allows
const NARROW_COST = 2;           // cost factor added in cells with no extra clearance (0 with PREFERRED_EXTRA_M)
const SNAP_RADIUS_M = 2;         // a start or goal in a blocked cell moves to the nearest free cell this close

// The centre of a cell, in metres.
const centreOf = (layout, k) => ({
  x: layout.originX + ((k % layout.cols) + 0.5) * layout.resolution,
  y: layout.originY + (Math.floor(k / layout.cols) + 0.5) * layout.resolution,
});

// A predicate: may the participant's centre be in cell k?
function freeCells(layout, clearance, avoid) {
  return (k) => {
    if (layout.clearance[k] < clearance) {
      return false;
    }
    const c = centreOf(layout, k);
    return !avoid.some((d) => Math.hypot(c.x - d.x, c.y - d.y) < d.r);
  };
}

// The free cell nearest (by grid steps) to (x, y), within SNAP_RADIUS_M; -1 when none.
function nearestFree(layout, x, y, isFree) {
  const { cx, cy } = layout.cellOf(x, y);
  const limit = Math.ceil(SNAP_RADIUS_M / layout.resolution);
  let best = -1;
  let bestDistance = Infinity;
  for (let dy = -limit; dy <= limit; dy += 1) {
    for (let dx = -limit; dx <= limit; dx += 1) {
      const nx = cx + dx;
      const ny = cy + dy;
      const d = Math.hypot(dx, dy);
      if (d < bestDistance && nx >= 0 && ny >= 0 && nx < layout.cols && ny < layout.rows &&
          isFree(ny * layout.cols + nx)) {
        best = ny * layout.cols + nx;
        bestDistance = d;
      }
    }
  }
  return best;
}

/// A path from `from` to `to` ({x, y}, m) as a list of points (cell centres, from first to last), over cells
/// with at least `clearance` m to walls and props and outside every disc in `avoid` ([{x, y, r}]); null when
/// there is none. A start or goal in a blocked cell is moved to the nearest free cell.
export function planPath(layout, from, to, clearance, avoid = []) {
  const isFree = freeCells(layout, clearance, avoid);
  const start = nearestFree(layout, from.x, from.y, isFree);
  const goal = nearestFree(layout, to.x, to.y, isFree);
  if (start < 0 || goal < 0) {
    return null;
  }
  const { cols, rows } = layout;
  const gx = goal % cols;
  const gy = Math.floor(goal / cols);
  const heuristic = (k) => {
    const dx = Math.abs((k % cols) - gx);
    const dy = Math.abs(Math.floor(k / cols) - gy);
    return Math.max(dx, dy) + (Math.SQRT2 - 1) * Math.min(dx, dy);
  };
  const cost = new Float64Array(cols * rows).fill(Infinity);
  const from_ = new Int32Array(cols * rows).fill(-1);
  const open = new MinHeap();
  cost[start] = 0;
  open.push(start, heuristic(start));
  while (open.size > 0) {
    const k = open.pop();
    if (k === goal) {
      break;
    }
    forEachNeighbour(k, cols, rows, (n, nx, ny, dx, dy) => {
      if (!isFree(n)) {
        return;
      }
      // Longer through narrow cells, so that the path keeps to the middle where there is room.
      const extra = Math.min(1, (layout.clearance[n] - clearance) / PREFERRED_EXTRA_M);
      const step = Math.hypot(dx, dy) * (1 + NARROW_COST * (1 - extra));
      if (cost[k] + step < cost[n]) {
        cost[n] = cost[k] + step;
        from_[n] = k;
        open.push(n, cost[n] + heuristic(n));
      }
    });
  }
  if (cost[goal] === Infinity) {
    return null;
  }
  const cells = [];
  for (let k = goal; k !== -1; k = from_[k]) {
    cells.push(k);
  }
  return cells.reverse().map((k) => centreOf(layout, k));
}

/// Whether a disc of radius `clearance` can go straight from a to b: every point on the way, looked at every
/// half cell, has that clearance.
export function segmentClear(layout, a, b, clearance) {
  const length = Math.hypot(b.x - a.x, b.y - a.y);
  const steps = Math.max(1, Math.ceil(length / (layout.resolution / 2)));
  for (let i = 0; i <= steps; i += 1) {
    const t = i / steps;
    if (layout.clearanceAt(a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)) < clearance) {
      return false;
    }
  }
  return true;
}

/// The point of `path` to head for from `position`: the farthest one, up to maxAheadM along the path, that
/// can be reached in a straight line with `clearance`; the path's second point when none can.
export function headFor(layout, position, path, maxAheadM, clearance) {
  let best = path[Math.min(1, path.length - 1)];
  let along = 0;
  for (let i = 1; i < path.length; i += 1) {
    along += Math.hypot(path[i].x - path[i - 1].x, path[i].y - path[i - 1].y);
    if (along > maxAheadM) {
      break;
    }
    if (segmentClear(layout, position, path[i], clearance)) {
      best = path[i];
    }
  }
  return best;
}

/// The length of a path, m.
export function pathLength(path) {
  let length = 0;
  for (let i = 1; i < path.length; i += 1) {
    length += Math.hypot(path[i].x - path[i - 1].x, path[i].y - path[i - 1].y);
  }
  return length;
}
