// SPDX-License-Identifier: GPL-2.0-or-later
// A TCP relay for the browser tests: sits between Chromium and sim_manager on loopback, passes bytes through
// untouched, and on the test's word plays the network's part in a failure: cut every connection without a word
// (what a Wi-Fi switch or a NAT timeout looks like to both ends), refuse new ones for a while, or end one
// WebSocket with a close frame of the test's choosing, as if the server had sent it.
//
// To put that close frame between two of the server's frames, the relay follows the server's WebSocket framing
// after an HTTP 101 answer (RFC 6455 section 5.2: a 2-byte head, 0, 2 or 8 bytes of length, a mask key when the
// mask bit is set, then the payload). It reads nothing else.

import net from 'node:net';

const MAX_ANSWER_HEAD = 16_384;   // a server answer head longer than this is passed through unread

// Follows one direction of WebSocket frames and says where each ends, so that bytes can be cut between frames.
class FrameWalker {
  constructor() {
    this.head = [];   // bytes of the frame head being read
    this.left = 0;    // payload bytes of the current frame still to come
  }

  // True when the bytes seen so far end exactly at the end of a frame.
  get atBoundary() {
    return this.head.length === 0 && this.left === 0;
  }

  // Reads chunk and returns the offsets in it just after each frame that ends inside it.
  feed(chunk) {
    const ends = [];
    let i = 0;
    while (i < chunk.length) {
      if (this.left > 0) {
        const take = Math.min(this.left, chunk.length - i);
        this.left -= take;
        i += take;
        if (this.left === 0) {
          ends.push(i);
        }
        continue;
      }
      this.head.push(chunk[i]);
      i += 1;
      if (this.head.length < 2) {
        continue;
      }
      const short = this.head[1] & 0x7f;
      const lengthBytes = short === 126 ? 2 : short === 127 ? 8 : 0;
      const maskBytes = this.head[1] & 0x80 ? 4 : 0;
      if (this.head.length < 2 + lengthBytes + maskBytes) {
        continue;
      }
      let length = short;
      if (lengthBytes > 0) {
        length = 0;
        for (let b = 0; b < lengthBytes; b += 1) {
          length = length * 256 + this.head[2 + b];
        }
      }
      this.head = [];
      this.left = length;
      if (length === 0) {
        ends.push(i);
      }
    }
    return ends;
  }
}

// A WebSocket close frame from a server (unmasked): code and a reason of at most 123 bytes.
function closeFrame(code, reason) {
  const text = Buffer.from(reason, 'utf8');
  if (text.length > 123) {
    throw new Error(`close reason of ${text.length} bytes; at most 123 fit a control frame`);
  }
  const frame = Buffer.alloc(4 + text.length);
  frame[0] = 0x88;   // FIN + opcode 8 (close)
  frame[1] = 2 + text.length;
  frame.writeUInt16BE(code, 2);
  text.copy(frame, 4);
  return frame;
}

// One browser connection and its upstream twin.
class Pair {
  constructor(relay, browser, upstream) {
    this.relay = relay;
    this.browser = browser;
    this.upstream = upstream;
    this.mode = 'answer';     // 'answer': the server's HTTP answer is being read; 'frames': it was 101, WebSocket
                              // frames follow; 'plain': anything else, passed through untouched
    this.answerHead = '';     // the server's HTTP answer until its blank line
    this.walker = new FrameWalker();
    this.pendingClose = null; // a close frame to send at the next frame boundary, then hang up
    this.closed = false;

    browser.on('data', (chunk) => {
      if (!this.closed && this.pendingClose === null) {
        upstream.write(chunk);
      }
    });
    upstream.on('data', (chunk) => this.fromServer(chunk));
    for (const socket of [browser, upstream]) {
      socket.on('error', () => this.destroy());
      socket.on('close', () => this.destroy());
    }
  }

  // Server bytes to the browser, watched for the 101 answer and then for frame ends.
  fromServer(chunk) {
    if (this.closed) {
      return;
    }
    if (this.mode === 'plain') {
      this.browser.write(chunk);
      return;
    }
    let frames = chunk;
    if (this.mode === 'answer') {
      const before = this.answerHead.length;
      this.answerHead += chunk.toString('latin1');
      const end = this.answerHead.indexOf('\r\n\r\n');
      if (end < 0 || !this.answerHead.startsWith('HTTP/1.1 101 ')) {
        // Still in the head, or an answer that is no WebSocket (then everything passes untouched).
        if (end >= 0 || this.answerHead.length > MAX_ANSWER_HEAD) {
          this.mode = 'plain';
        }
        this.browser.write(chunk);
        return;
      }
      this.mode = 'frames';
      this.relay.upgrades += 1;
      const headBytes = end + 4 - before;
      this.browser.write(chunk.subarray(0, headBytes));
      frames = chunk.subarray(headBytes);
    }
    if (this.pendingClose !== null) {
      const ends = this.walker.feed(frames);
      if (ends.length === 0) {
        this.browser.write(frames);
        return;
      }
      this.browser.write(frames.subarray(0, ends[0]));
      this.sendClose();
      return;
    }
    this.walker.feed(frames);
    this.browser.write(frames);
  }

  // Ends this WebSocket with a close frame (code, reason) between two of the server's frames.
  injectClose(code, reason) {
    this.pendingClose = closeFrame(code, reason);
    if (this.walker.atBoundary) {
      this.sendClose();
    }
  }

  sendClose() {
    const frame = this.pendingClose;
    this.closed = true;
    this.upstream.destroy();
    this.browser.end(frame);
    this.relay.pairs.delete(this);
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

    /** The open WebSocket connections (pairs whose server answered 101). */
    websockets() {
      return [...this.pairs].filter((pair) => pair.mode === 'frames');
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
