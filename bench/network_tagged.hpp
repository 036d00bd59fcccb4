// SPDX-License-Identifier: GPL-2.0-or-later
// bench_network's live codec quality: what the viewer of a real stream sees, against the frames rendered.
//
// The lockstep comparison (network_codec.hpp) gives each codec all the time it wants; a live stream is paced by
// the congestion control, which picks JPEG's quality and H.264's bit rate from the link. Here the warehouse walk
// is rendered in process in real time (30 fps, its own thread, llvmpipe) into an in-process rfbsim::Server
// with sim_rfb's picture options (JPEG q80 4:2:0 with adaptive quality, or H.264), a LinkEmulator in front, and
// the viewer (libvncclient CU + Fence for JPEG, H264RfbClient for H.264) behind it. Each frame carries its
// number in a tag (two rows of twelve 32 px blocks in the bottom-left corner, the second the inverse of the
// first, so a block pair reads as a bit only when clearly apart), and the last 64 frames are kept; each picture
// the viewer completes is read for its tag and compared (luma SSIM, rows above the tag) with that frame.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "network_paths.hpp"
#include "rfbsim/frame.hpp"

namespace rfbsim::bench {

/// One live run: a codec through one link.
struct TaggedRun {
  std::string codec;      ///< "h264" or "jpeg"
  int rtt_ms = 0;
  double cap_mbit = 0;    ///< 0 = none
  double seconds = 0;     ///< measured window
  std::uint64_t updates = 0;
  std::uint64_t bytes_down = 0;     ///< emulator bytes to the viewer in the window
  double encode_ms_per_update = 0;  ///< the server's encode + write time per update in the window
  std::vector<double> ssim;         ///< per picture whose tag was read and whose frame was still kept
  int unread = 0;                   ///< pictures whose tag did not read (or whose frame was gone)
  double rendered_fps = 0;          ///< frames the render thread produced per second
  std::string error;
};

/// Runs h264 and jpeg through each of the links (RTT ms, cap Mbit/s), `warm_up` then `measure` seconds each.
/// `source_dir` holds scenarios/.
std::vector<TaggedRun> run_tagged(const SimSettings& settings, const std::string& source_dir,
                                  const std::vector<std::pair<int, double>>& links, int warm_up_s, int measure_s);

/// Prints the live table and, per link, H.264 against JPEG (bytes/s, fps, SSIM).
void print_tagged(const std::vector<TaggedRun>& runs);

/// Writes frame number `index` (mod 4096) as the tag into an RGBA picture of at least 384 x 64 pixels.
void stamp_tag(std::uint8_t* rgba, int width, int height, std::uint32_t index);
/// Reads the tag of a picture; -1 when any block pair is not clearly one bit.
int read_tag(const FrameView& frame);

}  // namespace rfbsim::bench
