// SPDX-License-Identifier: GPL-2.0-or-later
// Keeps one undecodable H.264 picture from freezing the participant page: watches the WebCodecs decoders that
// noVNC makes and tells the page when one of them has failed, so that the page can reconnect
// (picture_recovery.js).
//
// Why this is needed: noVNC 1.7 (core/decoders/h264.js) turns every H.264 rectangle into a "pending frame" that
// only the decoder's output callback resolves, and its display queue draws nothing else, and reads no further
// message, until that frame is resolved. When the decoder fails instead, noVNC's error callback throws (no one
// catches it), the decoder closes, and the pending frame is never resolved: the picture stands still for good
// while the connection looks healthy (the server, which hears no more fence answers, soon stops sending). The
// same freeze follows when decode() throws (noVNC logs it and keeps the pending frame), when noVNC's own output
// callback throws (a timestamp it did not expect), and when a chunk simply never comes out of the decoder.
//
// What the guard does: window.VideoDecoder becomes a subclass of the browser's own class. Each decoder counts the
// chunks that went in and the frames that came out, and calls noVNC's callbacks inside a try. Any of the failures
// above, or a chunk still without its frame STALL_MS after it went in, is reported once through onFailure. The
// subclass adds no delay: decode() and each output only update a queue of submit times; a single timer, every
// CHECK_MS, looks for stalls while pictures are coming (it stops at its first tick with none in flight, so a still
// page has none running). A decoder only ever has one or two chunks in flight, because noVNC waits for each frame
// before it reads the next update: a chunk that has waited STALL_MS has stopped the page, and no healthy decoder
// comes near that (one picture decodes in milliseconds).
//
// Install it before noVNC makes its first decoder (noVNC makes them when the first H.264 rectangle arrives, from the
// global VideoDecoder). noVNC's own support check runs when its modules load, before picture_recovery.js installs
// the guard, so it keeps the browser's class. Where VideoDecoder does not exist (an insecure context: http other
// than localhost, or an older browser) nothing is installed: noVNC does not offer H.264 there and the page stays on
// JPEG.

const STALL_MS = 2000;   // a chunk without its decoded frame for this long counts as a failure
const CHECK_MS = 500;    // how often decoders with chunks in flight are looked at

// Installs the guard. onFailure({ reason, detail }) is called, soon after and from a task of its own (at most once
// until the next retire()), when a decoder made since the last retire() has failed; reason is 'error',
// 'decode-threw', 'callback-threw' or 'stalled', detail a sentence for the console. stallMs and checkMs (ms) are
// for tests. Returns { installed, retire() }: retire() forgets the decoders made so far (their connection is being
// replaced: what they do from now on is no longer reported) and allows the next report.
export function installH264Guard({ onFailure, stallMs = STALL_MS, checkMs = CHECK_MS }) {
  const NativeVideoDecoder = globalThis.VideoDecoder;
  if (typeof NativeVideoDecoder !== 'function') {
    return { installed: false, retire() {} };
  }

  let generation = 0;      // bumped by retire(): decoders of an older generation are no longer watched
  let reported = false;    // a failure of this generation has been reported
  const inFlight = new Set();   // decoders of this generation with chunks not yet decoded
  let timer = null;        // the stall check's interval; stops itself when it finds inFlight empty

  const stopWatching = (decoder) => {
    inFlight.delete(decoder);
  };

  // Reports a failure of a decoder of the current generation, once per generation. The report comes in a task of
  // its own, never from inside the caller's stack: decode() is called while noVNC parses a message, and the page
  // answers by disconnecting.
  const report = (decoder, reason, detail) => {
    if (decoder.guardGeneration !== generation || reported) {
      return;
    }
    reported = true;
    stopWatching(decoder);
    setTimeout(() => {
      if (decoder.guardGeneration !== generation) {
        return;   // retired meanwhile: its connection is already gone
      }
      try {
        onFailure({ reason, detail });
      } catch (err) {
        console.error('rfbsim: H.264 guard: the failure handler threw:', err);
      }
    }, 0);
  };

  // The stall check: any decoder whose oldest chunk has waited longer than stallMs has failed.
  const checkStalls = () => {
    if (inFlight.size === 0) {
      // Stopped here rather than when the last frame comes out: frames come out dozens of times a second, each
      // leaving the set empty for a moment.
      clearInterval(timer);
      timer = null;
      return;
    }
    const now = performance.now();
    for (const decoder of inFlight) {
      const waited = now - decoder.guardSubmitted[0];
      if (waited > stallMs) {
        report(decoder, 'stalled',
               `a picture went into the decoder ${Math.round(waited)} ms ago and has not come out ` +
               `(${decoder.guardSubmitted.length} waiting, decoder ${decoder.state})`);
      }
    }
  };

  const watch = (decoder) => {
    inFlight.add(decoder);
    if (timer === null) {
      timer = setInterval(checkStalls, checkMs);
    }
  };

  class GuardedVideoDecoder extends NativeVideoDecoder {
    constructor(init) {
      if (!init || typeof init.output !== 'function' || typeof init.error !== 'function') {
        super(init);   // the browser's own TypeError
        return;
      }
      // The callbacks refer to the decoder, which only exists once super() has returned.
      let self = null;
      super({
        output: (frame) => {
          self.guardSubmitted.shift();
          if (self.guardSubmitted.length === 0) {
            stopWatching(self);
          }
          try {
            init.output(frame);
          } catch (err) {
            report(self, 'callback-threw', `the page's output callback threw: ${err && err.message}`);
          }
        },
        error: (err) => {
          // noVNC 1.7's error callback only throws (that throw is what the freeze starts with); it is still
          // called, so that a later noVNC that handles errors hears of them.
          try {
            init.error(err);
          } catch (ignored) {
            // reported below
          }
          report(self, 'error', `the decoder failed: ${err && err.name}: ${err && err.message}`);
        },
      });
      self = this;
      this.guardGeneration = generation;
      this.guardSubmitted = [];   // performance.now() of each chunk not yet decoded, oldest first
    }

    decode(chunk) {
      try {
        super.decode(chunk);
      } catch (err) {
        report(this, 'decode-threw', `decode() threw: ${err && err.name}: ${err && err.message}`);
        throw err;
      }
      if (this.guardGeneration === generation) {
        this.guardSubmitted.push(performance.now());
        if (this.guardSubmitted.length === 1) {
          watch(this);
        }
      }
    }

    // After reset() or close() the chunks in the decoder never come out: they are no longer waited for.
    reset() {
      this.guardForget();
      super.reset();
    }

    close() {
      this.guardForget();
      super.close();
    }

    guardForget() {
      this.guardSubmitted.length = 0;
      stopWatching(this);
    }
  }

  globalThis.VideoDecoder = GuardedVideoDecoder;

  return {
    installed: true,
    retire() {
      generation += 1;
      reported = false;
      inFlight.clear();
      if (timer !== null) {
        clearInterval(timer);
        timer = null;
      }
    },
  };
}
