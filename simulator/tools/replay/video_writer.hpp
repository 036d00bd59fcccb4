// SPDX-License-Identifier: GPL-2.0-or-later
// VideoWriter: RGBA frames in, an H.264 MP4 out (FFmpeg: libswscale converts to YUV 4:2:0, libavcodec
// encodes, libavformat muxes). The file is written under a temporary name beside the target and renamed
// over it by finish(), so that a failed or abandoned video never leaves a broken file behind (nor destroys an
// older one). No FFmpeg type in this header.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>

#include "rfbsim/frame.hpp"

namespace rfbsim::replay {

/// The video cannot be made; the message names the file or the missing piece ("no H.264 encoder ...",
/// "out.mp4: cannot open for writing (Permission denied)").
class VideoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// How the video is encoded.
struct VideoSettings {
  int width = 1280;   ///< frame width, px; an odd width loses its last column (4:2:0 needs even sizes)
  int height = 720;   ///< frame height, px; likewise
  int fps = 30;       ///< frames per second: the time base is 1/fps, one frame per tick of it
  int crf = 23;       ///< libx264's constant rate factor (lower: better and larger)
  std::string preset = "veryfast";  ///< libx264's speed preset
  double keyframe_seconds = 2.0;     ///< distance between keyframes (GOP), s
};

class VideoWriter {
 public:
  /// Opens `file` for writing and sets up the encoder: libx264 if this FFmpeg has it, else the first other
  /// H.264 encoder that opens. Throws VideoError when the file cannot be written or no encoder works.
  VideoWriter(const std::filesystem::path& file, const VideoSettings& settings);
  /// Without finish(): stops, and removes the unfinished file.
  ~VideoWriter();
  VideoWriter(const VideoWriter&) = delete;
  VideoWriter& operator=(const VideoWriter&) = delete;

  /// Appends one frame (RGBA, top row first, at least the settings' size) as the next 1/fps of video.
  /// Throws VideoError when encoding or writing fails.
  void write(const FrameView& frame);
  /// Drains the encoder, writes the MP4 index (at the front: playable while it downloads) and puts the file
  /// in place. Throws VideoError when that fails.
  void finish();
  /// Stops without keeping the file (as the destructor does when finish() was not called).
  void discard();

  /// The encoder in use, e.g. "libx264".
  [[nodiscard]] std::string encoder() const;
  /// Frames written so far.
  [[nodiscard]] std::int64_t frames() const;
  /// The encoded size so far (the file's size after finish()), bytes.
  [[nodiscard]] std::int64_t bytes() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rfbsim::replay
