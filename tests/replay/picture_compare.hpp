// SPDX-License-Identifier: GPL-2.0-or-later
// Pictures of the same moment compared within the replay check's limits (docs/replay.md, "Compared with what
// was served"): a served picture against sim_replay's video frame, decoded by ffmpeg. Shared by the frame test
// (what a live sim_rfb served) and the watched-replay test (what sim_rfb --replay served).
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "rfbsim/frame.hpp"

namespace rfbsim::test {

using Pixels = std::vector<std::uint8_t>;  // RGB, 3 bytes per pixel, top row first

/// The tolerances, per pair of RGB pictures of the same moment. The video is H.264 (libx264 CRF 23, 4:2:0),
/// which softens edges and halves the colour resolution, the HUD's text and the desks' outlines most. Measured
/// at 320x240 in the lab (with the tutorial's HUD text then): the video's frame against the Raw capture MAD
/// 1.9-2.9, PSNR 33-36 dB; the worst case is a frame coded alone (a keyframe, every 2 s): the capture itself
/// through libx264 with the replay's settings loses MAD 2.7-3.6, PSNR 31-33 dB. The browser's Tight JPEG (the
/// server's quality 80, 4:2:0) adds its own loss: MAD 2.5-3.9, PSNR 32-35 dB against the video. Two different
/// moments differ by MAD 23-36, PSNR 13-16 dB. The limits sit between, with room for the keyframe case on
/// either side.
struct Tolerance {
  double max_mad;   ///< mean absolute difference per channel, 0..255
  double min_psnr;  ///< dB
};
constexpr Tolerance kLossless{5.0, 28.0};  // Raw capture vs the video: H.264's loss alone
constexpr Tolerance kJpeg{6.0, 27.0};      // JPEG capture vs the video: both losses

/// Mean absolute difference per channel, 0..255 (the pictures must be the same size).
double mean_abs_difference(const Pixels& a, const Pixels& b);
/// Peak signal-to-noise ratio over all channels, dB (infinite for equal pictures).
double psnr(const Pixels& a, const Pixels& b);
/// Whether two pictures show the same moment within `tolerance`.
bool matches(const Pixels& a, const Pixels& b, Tolerance tolerance);

/// An RGBA picture as RGB.
Pixels rgb_of(const FrameView& frame);

/// The frames `indices` (ascending) of `video` (`width` x `height`) decoded by ffmpeg (RFBSIM_FFMPEG) into
/// RGB, through the scratch file `raw`. BT.709 limited range as sim_replay tags them, with accurate rounding:
/// swscale's fast path darkens every channel by about 1 (measured), a bias that is the decoder's, not the
/// replay's.
std::vector<Pixels> decoded_frames(const std::filesystem::path& video, const std::vector<std::uint64_t>& indices,
                                   int width, int height, const std::filesystem::path& raw);

}  // namespace rfbsim::test
