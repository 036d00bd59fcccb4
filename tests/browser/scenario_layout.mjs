// SPDX-License-Identifier: GPL-2.0-or-later
// What a scripted participant knows of a scenario before it starts, read from the same files sim_rfb loads:
// the map image's walls and the scenario's props as an occupancy grid with each cell's clearance (metres to
// the nearest obstacle), its named points (spawns, landmarks) and where its reach steps lead. The formats are
// those of docs/scenarios.md (props: centre pose, size along the prop's own x and y, optional repeat) and the
// ROS map_server YAML the map uses (image, resolution, origin, negate, occupied_thresh).

import fs from 'node:fs';
import { createRequire } from 'node:module';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

// The yaml package (npm, a devDependency of web/ like playwright-core), from web/node_modules.
const YAML = createRequire(path.join(path.dirname(fileURLToPath(import.meta.url)), '..', '..', 'web',
                                     'package.json'))('yaml');

// Calls visit(n, nx, ny, dx, dy) for each of cell k's eight neighbours inside a cols x rows grid (cells are
// numbered row by row).
export function forEachNeighbour(k, cols, rows, visit) {
  const cx = k % cols;
  const cy = Math.floor(k / cols);
  for (let dy = -1; dy <= 1; dy += 1) {
    for (let dx = -1; dx <= 1; dx += 1) {
      const nx = cx + dx;
      const ny = cy + dy;
      if ((dx || dy) && nx >= 0 && ny >= 0 && nx < cols && ny < rows) {
        visit(ny * cols + nx, nx, ny, dx, dy);
      }
    }
  }
}

export const GRID_RESOLUTION_M = 0.1;   // the participant plans on cells this size (the map's are 0.05 m)

// A YAML file as plain data; a malformed one is an error naming the file (and the line, from the parser).
function readYaml(file) {
  try {
    return YAML.parse(fs.readFileSync(file, 'utf8'));
  } catch (err) {
    throw new Error(`${file}: ${err.message}`);
  }
}

// A binary PGM (P5, 8-bit) as { width, height, pixels } (row 0 is the top of the image).
function readPgm(file) {
  const data = fs.readFileSync(file);
  const fields = [];
  let i = 0;
  while (fields.length < 4) {
    while (i < data.length && /\s/.test(String.fromCharCode(data[i]))) {
      i += 1;
    }
    if (data[i] === 0x23) {   // a comment runs to the end of its line
      while (i < data.length && data[i] !== 0x0a) {
        i += 1;
      }
      continue;
    }
    const start = i;
    while (i < data.length && !/\s/.test(String.fromCharCode(data[i]))) {
      i += 1;
    }
    if (start === i) {
      throw new Error(`${file}: the PGM header ends early`);
    }
    fields.push(data.toString('latin1', start, i));
  }
  const [magic, width, height, maxval] = [fields[0], Number(fields[1]), Number(fields[2]), Number(fields[3])];
  if (magic !== 'P5' || !(width > 0) || !(height > 0) || maxval !== 255) {
    throw new Error(`${file}: not an 8-bit binary PGM (header ${fields.join(' ')})`);
  }
  const pixels = data.subarray(i + 1, i + 1 + width * height);
  if (pixels.length !== width * height) {
    throw new Error(`${file}: ${pixels.length} pixels, the header says ${width}x${height}`);
  }
  return { width, height, pixels };
}

// Whether a map pixel blocks: occupied, or unknown (between free_thresh and occupied_thresh), as map_server
// reads trinary maps; sim_rfb treats both as walls.
function pixelBlocks(value, spec) {
  const occupancy = spec.negate ? value / 255 : (255 - value) / 255;
  return occupancy > (spec.free_thresh ?? 0.196);
}

// Brushfire from every blocked cell: each cell's distance (m) to the nearest blocked cell's centre, by
// propagating nearest sites to neighbours (within a few mm of the exact Euclidean transform here).
function clearanceField(blocked, cols, rows, resolution) {
  const distance = new Float64Array(cols * rows).fill(Infinity);
  const siteX = new Int32Array(cols * rows);
  const siteY = new Int32Array(cols * rows);
  let queue = [];
  for (let k = 0; k < blocked.length; k += 1) {
    if (blocked[k]) {
      distance[k] = 0;
      siteX[k] = k % cols;
      siteY[k] = Math.floor(k / cols);
      queue.push(k);
    }
  }
  while (queue.length > 0) {
    const next = [];
    for (const k of queue) {
      forEachNeighbour(k, cols, rows, (n, nx, ny) => {
        const d = Math.hypot(nx - siteX[k], ny - siteY[k]);
        if (d < distance[n] - 1e-9) {
          distance[n] = d;
          siteX[n] = siteX[k];
          siteY[n] = siteY[k];
          next.push(n);
        }
      });
    }
    queue = next;
  }
  return distance.map((d) => d * resolution);
}

/// Reads scenarioFile (and its map) and returns the layout: { cols, rows, resolution, originX, originY,
/// blocked (Uint8Array, row 0 at the map's lowest y), clearance (Float64Array, m), clearanceAt(x, y),
/// point(ref), reachTarget(stepIndex), scenario (the parsed file) }. Throws with the file's name on
/// anything it cannot read.
export function loadScenarioLayout(scenarioFile) {
  const scenario = readYaml(scenarioFile);
  if (!scenario || typeof scenario.map !== 'string') {
    throw new Error(`${scenarioFile}: no 'map'`);
  }
  const mapFile = path.resolve(path.dirname(scenarioFile), scenario.map);
  const mapSpec = readYaml(mapFile);
  const image = readPgm(path.resolve(path.dirname(mapFile), String(mapSpec.image)));
  const mapRes = Number(mapSpec.resolution);
  const [originX, originY] = mapSpec.origin || [0, 0];
  if (!(mapRes > 0)) {
    throw new Error(`${mapFile}: resolution must be a positive number`);
  }

  // The map's pixels, pooled onto the coarser grid: a cell blocks if any pixel in it does.
  const resolution = GRID_RESOLUTION_M;
  const cols = Math.ceil((image.width * mapRes) / resolution);
  const rows = Math.ceil((image.height * mapRes) / resolution);
  const blocked = new Uint8Array(cols * rows);
  for (let py = 0; py < image.height; py += 1) {
    for (let px = 0; px < image.width; px += 1) {
      if (pixelBlocks(image.pixels[py * image.width + px], mapSpec)) {
        const cx = Math.floor(((px + 0.5) * mapRes) / resolution);
        const cy = Math.floor(((image.height - py - 0.5) * mapRes) / resolution);   // image rows run down
        blocked[cy * cols + cx] = 1;
      }
    }
  }

  const spawns = scenario.spawns || {};
  const landmarks = Object.fromEntries((scenario.landmarks || []).map((l) => [l.name, l.position]));
  // A point given as [x, y(, yaw)], a spawn's name or a landmark's name, as the scenario allows.
  const point = (ref, what = 'point') => {
    const value = typeof ref === 'string' ? (landmarks[ref] ?? spawns[ref]) : ref;
    if (typeof value === 'string' && value !== ref) {
      return point(value, what);
    }
    if (!Array.isArray(value) || !Number.isFinite(value[0]) || !Number.isFinite(value[1])) {
      throw new Error(`${scenarioFile}: ${what} '${JSON.stringify(ref)}' is not [x, y], a spawn or a landmark`);
    }
    return { x: value[0], y: value[1] };
  };

  // Props: each an oriented box, repeated `count` times `step` apart; cells whose centre lies within half a
  // cell of the box block.
  for (const [index, prop] of (scenario.props || []).entries()) {
    const [x0, y0, yaw = 0] = prop.pose || [];
    const [sx, sy] = prop.size || [];
    if (![x0, y0, yaw, sx, sy].every(Number.isFinite)) {
      throw new Error(`${scenarioFile}: props[${index}] needs pose [x, y, yaw] and size [x, y, height]`);
    }
    const count = prop.repeat ? prop.repeat.count : 1;
    const [stepX, stepY] = prop.repeat ? prop.repeat.step : [0, 0];
    const hx = sx / 2 + resolution / 2;
    const hy = sy / 2 + resolution / 2;
    const reach = Math.hypot(hx, hy);
    for (let n = 0; n < count; n += 1) {
      const px = x0 + n * stepX;
      const py = y0 + n * stepY;
      for (let cy = Math.max(0, Math.floor((py - reach - originY) / resolution));
        cy <= Math.min(rows - 1, Math.ceil((py + reach - originY) / resolution)); cy += 1) {
        for (let cx = Math.max(0, Math.floor((px - reach - originX) / resolution));
          cx <= Math.min(cols - 1, Math.ceil((px + reach - originX) / resolution)); cx += 1) {
          const dx = originX + (cx + 0.5) * resolution - px;
          const dy = originY + (cy + 0.5) * resolution - py;
          const along = dx * Math.cos(yaw) + dy * Math.sin(yaw);
          const across = -dx * Math.sin(yaw) + dy * Math.cos(yaw);
          if (Math.abs(along) <= hx && Math.abs(across) <= hy) {
            blocked[cy * cols + cx] = 1;
          }
        }
      }
    }
  }

  const clearance = clearanceField(blocked, cols, rows, resolution);
  const cellOf = (x, y) => ({
    cx: Math.floor((x - originX) / resolution),
    cy: Math.floor((y - originY) / resolution),
  });
  // Outside the map counts as a wall.
  const clearanceAt = (x, y) => {
    const { cx, cy } = cellOf(x, y);
    return cx >= 0 && cy >= 0 && cx < cols && cy < rows ? clearance[cy * cols + cx] : 0;
  };

  // Where reach step `stepIndex` of the task leads: its landmark, else the avatar's goal (docs/scenarios.md).
  const reachTarget = (stepIndex) => {
    const step = scenario.task && scenario.task.steps && scenario.task.steps[stepIndex];
    if (!step || step.type !== 'reach') {
      throw new Error(`${scenarioFile}: task step ${stepIndex} is not a reach step`);
    }
    const ref = step.landmark ?? (scenario.avatar && scenario.avatar.goal);
    return { ...point(ref, `task step ${stepIndex}'s target`), name: String(ref) };
  };

  return { scenarioFile, scenario, cols, rows, resolution, originX, originY, blocked, clearance, cellOf,
           clearanceAt, point, reachTarget };
}
