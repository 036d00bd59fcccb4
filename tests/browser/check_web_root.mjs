// SPDX-License-Identifier: GPL-2.0-or-later
// Checks an assembled web root: every file index.html loads and every ES module import it reaches exists.
//
// Usage: node check_web_root.mjs WEB_ROOT
// Follows <script src>, <link href> and static/dynamic `import ... from '...'` with relative paths, the way the
// browser would, so a noVNC module missing from the copy list fails here rather than in a participant's browser.

import fs from 'node:fs';
import path from 'node:path';

const root = process.argv[2];
if (!root) {
  console.error('usage: node check_web_root.mjs WEB_ROOT');
  process.exit(1);
}

const missing = [];
const seen = new Set();
const queue = [];

// Queues a reference made from file `from` (absolute path) to `ref` (as written in the file).
function reference(from, ref) {
  if (ref.startsWith('data:')) {
    return;   // inline, nothing to fetch
  }
  if (/^[a-z][a-z0-9+.-]*:/i.test(ref) || ref.startsWith('//') || ref.startsWith('#')) {
    missing.push(`${path.relative(root, from)} refers outside the web root: ${ref}`);
    return;
  }
  const clean = ref.split(/[?#]/)[0];
  const target = clean.startsWith('/') ? path.join(root, clean) : path.resolve(path.dirname(from), clean);
  if (!target.startsWith(path.resolve(root) + path.sep)) {
    missing.push(`${path.relative(root, from)} refers above the web root: ${ref}`);
  } else if (!fs.existsSync(target)) {
    missing.push(`${path.relative(root, from)} -> ${ref} (no ${path.relative(root, target)})`);
  } else if (!seen.has(target)) {
    seen.add(target);
    queue.push(target);
  }
}

const index = path.resolve(root, 'index.html');
if (!fs.existsSync(index)) {
  console.error(`FAIL: ${index} does not exist (was target rfbsim_web built?)`);
  process.exit(1);
}
seen.add(index);
queue.push(index);

while (queue.length > 0) {
  const file = queue.shift();
  const text = fs.readFileSync(file, 'utf8');
  if (file.endsWith('.html')) {
    // Comments are dropped first so that commented-out markup does not count.
    const markup = text.replace(/<!--[\s\S]*?-->/g, '');
    for (const m of markup.matchAll(/<(?:script|link)\b[^>]*?\b(?:src|href)\s*=\s*"([^"]+)"/gi)) {
      reference(file, m[1]);
    }
  } else if (file.endsWith('.js')) {
    const code = text.replace(/\/\*[\s\S]*?\*\//g, '').replace(/^\s*\/\/.*$/gm, '');
    const patterns = [
      /\b(?:import|export)\s[^;'"]*?\bfrom\s*(['"])([^'"]+)\1/g,   // import x from '...'; export ... from '...'
      /\bimport\s*(['"])([^'"]+)\1/g,                              // import '...'
      /\bimport\(\s*(['"])([^'"]+)\1\s*\)/g,                       // import('...')
    ];
    for (const pattern of patterns) {
      for (const m of code.matchAll(pattern)) {
        reference(file, m[2]);
      }
    }
  }
}

if (missing.length > 0) {
  console.error(`FAIL: ${missing.length} missing reference(s) in ${root}:`);
  for (const line of missing) {
    console.error(`  ${line}`);
  }
  process.exit(1);
}
console.log(`web root ${root}: index.html reaches ${seen.size} files, all present`);
