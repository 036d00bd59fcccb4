// SPDX-License-Identifier: GPL-2.0-or-later
// The first picture. noVNC draws into its canvas only when a whole framebuffer update is in, and until then the
// canvas is transparent (it is cleared whenever noVNC sizes it): the first opaque pixel is the first picture.
// Looked for once per animation frame in an 8x8 copy, so noVNC's own canvas is never read back (a canvas read
// from often is moved off the GPU). Hidden pages get no animation frames: a picture counts once it can be seen.

import { page } from './page_state.js';

const PROBE_SIZE = 8;

// Watches `view`, the canvas of noVNC client `client`, and calls onPicture() once it shows a picture; stops
// without a call once `client` is no longer the page's current one (that attempt is over).
export function watchForFirstPicture(client, view, onPicture) {
  const probe = document.createElement('canvas');
  probe.width = PROBE_SIZE;
  probe.height = PROBE_SIZE;
  const probeContext = probe.getContext('2d', { willReadFrequently: true });
  const look = () => {
    if (page.rfb !== client) {
      return;   // that attempt is over
    }
    if (view.width > 0 && view.height > 0) {
      probeContext.clearRect(0, 0, PROBE_SIZE, PROBE_SIZE);
      probeContext.drawImage(view, 0, 0, PROBE_SIZE, PROBE_SIZE);
      const pixels = probeContext.getImageData(0, 0, PROBE_SIZE, PROBE_SIZE).data;
      for (let i = 3; i < pixels.length; i += 4) {
        if (pixels[i] !== 0) {
          onPicture();
          return;
        }
      }
    }
    window.requestAnimationFrame(look);
  };
  window.requestAnimationFrame(look);
}
