// SPDX-License-Identifier: GPL-2.0-or-later
// A minimal RFB 3.8 viewer for the ROS tests and bench_ros.mjs. It makes sim_rfb render and send frames, as a
// participant's page does: the bag's CPU is set against a watched session's, and a session whose rosbridge port
// is under attack is seen to keep streaming. It asks for Raw pixels only (the one encoding that needs no decoder
// to skip over), reads every FramebufferUpdate to its end and asks for the next at once, and counts the updates.
// Raw costs sim_rfb less than Tight JPEG does, so the session's CPU it shows is a lower bound and the bag's
// share an upper one.

import net from 'node:net';

const ENCODING_RAW = 0;

/// Connects to host:port and watches until stop(); resolves with { stop(), updates() } once the handshake is
/// done. Rejects naming the step that failed.
export function watch(host, port) {
  return new Promise((resolve, reject) => {
    const socket = net.connect(port, host);
    let buffer = Buffer.alloc(0);
    let step = 'version';
    let bytesPerPixel = 4;
    let width = 0;
    let height = 0;
    let updates = 0;
    let rectsLeft = -1;  // in the current FramebufferUpdate; -1 between messages
    let skip = 0;        // pixel bytes of the current rectangle still to come (dropped as they arrive)

    const requestUpdate = (incremental) => {
      const request = Buffer.alloc(10);
      request.writeUInt8(3, 0);
      request.writeUInt8(incremental ? 1 : 0, 1);
      request.writeUInt16BE(width, 6);
      request.writeUInt16BE(height, 8);
      socket.write(request);
    };
    const take = (n) => {
      if (buffer.length < n) return null;
      const head = buffer.subarray(0, n);
      buffer = buffer.subarray(n);
      return head;
    };

    // One step of the conversation per call while there are bytes for it; false when it needs more.
    const advance = () => {
      if (step === 'version') {
        if (!take(12)) return false;
        socket.write('RFB 003.008\n');
        step = 'security';
      } else if (step === 'security') {
        if (buffer.length < 1 || buffer.length < 1 + buffer[0]) return false;
        const types = take(1 + buffer[0]).subarray(1);
        if (!types.includes(1)) throw new Error(`security types ${[...types]} offer no None`);
        socket.write(Buffer.from([1]));
        step = 'result';
      } else if (step === 'result') {
        const result = take(4);
        if (!result) return false;
        if (result.readUInt32BE(0) !== 0) throw new Error('security handshake refused');
        socket.write(Buffer.from([1]));  // ClientInit: shared
        step = 'init';
      } else if (step === 'init') {
        if (buffer.length < 24 || buffer.length < 24 + buffer.readUInt32BE(20)) return false;
        const init = take(24 + buffer.readUInt32BE(20));
        width = init.readUInt16BE(0);
        height = init.readUInt16BE(2);
        bytesPerPixel = init[4] / 8;
        const encodings = Buffer.alloc(8);
        encodings.writeUInt8(2, 0);
        encodings.writeUInt16BE(1, 2);
        encodings.writeInt32BE(ENCODING_RAW, 4);
        socket.write(encodings);
        requestUpdate(false);
        step = 'serving';
        resolve({ stop: () => socket.destroy(), updates: () => updates });
      } else if (rectsLeft < 0) {
        if (buffer.length < 1) return false;
        const type = buffer[0];
        if (type === 0) {
          const header = take(4);
          if (!header) return false;
          rectsLeft = header.readUInt16BE(2);
        } else if (type === 2) {
          take(1);  // Bell
        } else if (type === 3) {
          if (buffer.length < 8 || buffer.length < 8 + buffer.readUInt32BE(4)) return false;
          take(8 + buffer.readUInt32BE(4));  // ServerCutText
        } else {
          throw new Error(`server message type ${type}, which a Raw-only viewer does not expect`);
        }
      } else if (rectsLeft > 0) {
        if (buffer.length < 12) return false;
        const encoding = buffer.readInt32BE(8);
        if (encoding !== ENCODING_RAW) throw new Error(`a rectangle in encoding ${encoding}, asked for Raw only`);
        const header = take(12);
        skip = header.readUInt16BE(4) * header.readUInt16BE(6) * bytesPerPixel;
        const now = Math.min(skip, buffer.length);
        take(now);
        skip -= now;
        rectsLeft -= 1;
        if (skip > 0) return false;  // the rest comes in later chunks
      }
      if (rectsLeft === 0) {
        rectsLeft = -1;
        updates += 1;
        requestUpdate(true);
      }
      return true;
    };

    socket.on('data', (data) => {
      let chunk = data;
      if (skip > 0) {
        const now = Math.min(skip, chunk.length);
        chunk = chunk.subarray(now);
        skip -= now;
      }
      buffer = buffer.length === 0 ? chunk : Buffer.concat([buffer, chunk]);
      try {
        while (advance());
      } catch (err) {
        socket.destroy();
        reject(new Error(`RFB viewer at ${step}: ${err.message}`));
      }
    });
    socket.on('error', (err) => reject(new Error(`RFB viewer at ${step}: ${err.message}`)));
  });
}
