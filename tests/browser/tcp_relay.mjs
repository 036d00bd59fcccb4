// SPDX-License-Identifier: GPL-2.0-or-later
// A TCP relay for the browser tests: sits between Chromium and sim_manager on loopback, passes bytes through
// untouched, and on the test's word plays the network's part in a failure: cut every connection without a word
// (what a Wi-Fi switch or a NAT timeout looks like to both ends), or refuse new ones for a while. It reads the
// server's HTTP answer only to count the WebSocket upgrades that went through.

import net from 'node:net';

const MAX_ANSWER_HEAD = 16_384;   // a server answer head longer than this is passed through unread

// One browser connection and its upstream twin.
class Pair {
  constructor(relay, browser, upstream) {
    this.relay = relay;
    this.browser = browser;
    this.upstream = upstream;
    this.mode = 'answer';     // 'answer': the server's HTTP answer head is being read; then 'through'
    this.answerHead = '';     // the server's HTTP answer until its blank line
    this.closed = false;

    browser.on('data', (chunk) => {
      if (!this.closed) {
        upstream.write(chunk);
      }
    });
    upstream.on('data', (chunk) => this.fromServer(chunk));
    for (const socket of [browser, upstream]) {
      socket.on('error', () => this.destroy());
      socket.on('close', () => this.destroy());
    }
  }

  // Server bytes to the browser, untouched; the answer head is read once to count a 101.
  fromServer(chunk) {
    if (this.closed) {
      return;
    }
    if (this.mode === 'answer') {
      this.answerHead += chunk.toString('latin1');
      const end = this.answerHead.indexOf('\r\n\r\n');
      if (end >= 0 || this.answerHead.length > MAX_ANSWER_HEAD) {
        if (end >= 0 && this.answerHead.startsWith('HTTP/1.1 101 ')) {
          this.relay.upgrades += 1;
        }
        this.mode = 'through';
        this.answerHead = '';
      }
    }
    this.browser.write(chunk);
  }

  destroy() {
    this.closed = true;
    this.browser.destroy();
    this.upstream.destroy();
    this.relay.pairs.delete(this);
  }
}

/** Starts a relay on a free loopback port to target { host, port }; resolves with the relay once it listens. */
export async function startTcpRelay(target) {
  const relay = {
    pairs: new Set(),   // open browser connections with their upstream twins
    upgrades: 0,        // WebSocket upgrades the server accepted through the relay
    refusing: false,    // new connections are closed at once (the network is down)
    port: 0,
    server: null,

    /** Closes every open connection at once, both ways, without a WebSocket close frame. */
    cutAll() {
      for (const pair of [...this.pairs]) {
        pair.destroy();
      }
    },

    /** While true, every new connection is closed as soon as it is accepted. */
    setRefusing(refusing) {
      this.refusing = refusing;
    },

    /** Stops listening and closes every connection; resolves once the server is closed. */
    close() {
      this.cutAll();
      return new Promise((resolve) => this.server.close(() => resolve()));
    },
  };

  relay.server = net.createServer((browser) => {
    if (relay.refusing) {
      browser.destroy();
      return;
    }
    browser.pause();
    const upstream = net.connect(target.port, target.host);
    upstream.once('connect', () => {
      const pair = new Pair(relay, browser, upstream);
      relay.pairs.add(pair);
      browser.resume();
    });
    upstream.once('error', () => browser.destroy());
    browser.once('error', () => upstream.destroy());
  });
  await new Promise((resolve, reject) => {
    relay.server.once('error', reject);
    relay.server.listen(0, '127.0.0.1', resolve);
  });
  relay.port = relay.server.address().port;
  return relay;
}
