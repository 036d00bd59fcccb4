// SPDX-License-Identifier: GPL-2.0-or-later
// Serves web/survey-demo.html on its own origin (loopback only), standing in for the researcher's survey
// site, so that the demo survey embeds sim_manager's sessions across origins as a real survey does.
//   node scripts/serve-survey-demo.mjs [PORT]   (default 8000)
import fs from 'node:fs';
import http from 'node:http';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const page = path.join(path.dirname(fileURLToPath(import.meta.url)), '..', 'web', 'survey-demo.html');
const port = Number(process.argv[2] || 8000);
if (!Number.isInteger(port) || port < 1 || port > 65535) {
  console.error(`serve-survey-demo: bad port '${process.argv[2]}'`);
  process.exit(2);
}

// One page and nothing else: no directory listing, no other file of the checkout.
const server = http.createServer((request, response) => {
  const url = new URL(request.url, 'http://localhost');
  if (request.method !== 'GET' || (url.pathname !== '/' && url.pathname !== '/survey-demo.html')) {
    response.writeHead(404, { 'Content-Type': 'text/plain' });
    response.end('not found\n');
    return;
  }
  fs.readFile(page, (err, body) => {
    if (err) {
      response.writeHead(500, { 'Content-Type': 'text/plain' });
      response.end(`cannot read ${page}\n`);
      return;
    }
    response.writeHead(200, { 'Content-Type': 'text/html; charset=utf-8', 'Cache-Control': 'no-store' });
    response.end(body);
  });
});
server.listen(port, '127.0.0.1', () => {
  console.log(`survey demo: http://127.0.0.1:${port}/survey-demo.html`);
});
