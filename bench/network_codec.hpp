// SPDX-License-Identifier: GPL-2.0-or-later
// bench_network's codec comparison: H.264 against Tight JPEG q80 on the very same rendered frames, in process.
//
// The warehouse is stepped and rendered here (the scene without the HUD, llvmpipe as sim_rfb), with the walk of
// the cells (W held, D for 300 ms every second, 2 ticks of 1/60 s per frame). Each frame goes to two in-process
// rfbsim::Servers, one with Codec::kH264 watched by an H264RfbClient (CU + Fence, libavcodec decoder) and one
// with Codec::kJpeg at quality 80 4:2:0 watched by a libvncclient client, one frame at a time (submit, wait for
// both updates): so each client's picture is exactly its codec's version of that frame, and
//   SSIM       luma SSIM (8x8 windows every 4 px) of the client's picture against the rendered frame;
//   bytes      RFB bytes the server wrote for the update (stats().bytes_sent);
//   encode     the server's time encoding and writing it (stats().encode_ms): x264 or libjpeg-turbo per
//              720p frame, colour conversion included.
// Unthrottled (loopback, no cap): H.264 runs at its own rate control (CRF 23 up to the level's maximum), JPEG at
// q80, which is the comparison the target names (bytes <= 1/3 of JPEG q80 at equal or better SSIM).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "network_paths.hpp"
#include "rfbsim/frame.hpp"

namespace rfbsim::bench {

/// The cells' walk, rendered in process: `settings`' scenario, seed and avatar start (scenarios/ under
/// `source_dir`), W held, D for 300 ms of every second, two 1/60 s ticks per frame; the scene without the HUD at
/// 1280x720 with the EGL platform sim_rfb picks (llvmpipe here). Owns a GL context current on the thread that
/// made it: create it and call next() on one thread. Throws std::runtime_error (or the scenario's error).
class WalkScene {
 public:
  WalkScene(const SimSettings& settings, const std::string& source_dir);
  ~WalkScene();
  WalkScene(const WalkScene&) = delete;
  WalkScene& operator=(const WalkScene&) = delete;
  /// Steps the walk by one frame and renders it; the picture stays valid until the next call.
  FrameView next();
  /// The GL renderer's name.
  [[nodiscard]] std::string renderer() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Per-frame samples of one codec.
struct CodecSamples {
  std::string name;
  std::vector<double> ssim;
  std::vector<double> kbytes;     ///< kB (1000 bytes) per update
  std::vector<double> encode_ms;  ///< server time per update
};

/// The comparison's result.
struct CodecComparison {
  std::vector<CodecSamples> codecs;  ///< H.264 first, then JPEG
  int frames = 0;                    ///< frames submitted (after the warm-up)
  int skipped = 0;                   ///< frames that changed no tile (no update)
  std::string renderer;
  std::string error;                 ///< why it failed ("" when it ran)
};

/// Renders `frames` frames (after 30 unmeasured) of `settings`' scenario, seed and avatar start at 1280x720
/// and compares the codecs on them. `source_dir` holds scenarios/.
CodecComparison compare_codecs(const SimSettings& settings, const std::string& source_dir, int frames);

/// Prints the comparison table.
void print_codec_comparison(const CodecComparison& comparison);

}  // namespace rfbsim::bench
