// SPDX-License-Identifier: GPL-2.0-or-later
// A client's own quality request (client_quality.hpp) as the cap on the server's, and a ClientStreamer that
// takes it: the top of its ladder, the quality it imposes, and what its status shows.
#include "client_quality.hpp"

#include <rfb/rfbproto.h>

#include <catch2/catch.hpp>

#include "client_streamer.hpp"

namespace {

using rfbsim::detail::capped_by_client;
using rfbsim::detail::ClientQualityRequest;
using rfbsim::detail::ClientStreamer;
using rfbsim::detail::QualityLevel;
using rfbsim::detail::StreamerConfig;
using rfbsim::detail::subsampling_coarseness;

// libvncserver's subsampling indices.
constexpr int k444 = 0;
constexpr int k420 = 1;
constexpr int k422 = 2;
constexpr int kGrey = 3;

// What libvncserver 0.9.14 makes of a Tight quality level (its table, TigerVNC's server's): level, JPEG quality,
// subsampling. noVNC sends level 6 unless the page says otherwise.
ClientQualityRequest level(int tight_level, int jpeg_quality, int subsampling, int compress_level = 6) {
  return {tight_level, jpeg_quality, subsampling, compress_level};
}

// sim_rfb's defaults: quality 80 at 4:2:0, adaptive.
StreamerConfig server_config(int jpeg_quality = 80) {
  StreamerConfig config;
  config.width = 64;
  config.height = 48;
  config.jpeg_quality = jpeg_quality;
  config.subsampling = k420;
  return config;
}

}  // namespace

TEST_CASE("subsampling indices rank by the colour detail they drop") {
  CHECK(subsampling_coarseness(k444) == 0);
  CHECK(subsampling_coarseness(k422) == 1);
  CHECK(subsampling_coarseness(k420) == 2);
  CHECK(subsampling_coarseness(kGrey) == 3);
  CHECK(subsampling_coarseness(7) == 2);  // unknown: as the server's default, never coarser
}

TEST_CASE("a client's request lowers the server's quality and never raises it") {
  const QualityLevel server{80, k420};
  // No request at all (what libvncserver leaves after a SetEncodings without quality): the server's.
  CHECK(capped_by_client(server, ClientQualityRequest{}) == QualityLevel{80, k420});
  // noVNC's default level 6 is quality 79 at 4:4:4: 79, and the server's 4:2:0 stays (4:4:4 would be more).
  CHECK(capped_by_client(server, level(6, 79, k444)) == QualityLevel{79, k420});
  // TigerVNC's -QualityLevel=3: quality 42 at 4:2:2; 4:2:0 already drops more colour than 4:2:2.
  CHECK(capped_by_client(server, level(3, 42, k422)) == QualityLevel{42, k420});
  // Level 0 is quality 15 at 4:2:0.
  CHECK(capped_by_client(server, level(0, 15, k420)) == QualityLevel{15, k420});
  // Level 9 (quality 100, 4:4:4) and TurboVNC's fine quality 95 ask for more than the cap: the cap holds.
  CHECK(capped_by_client(server, level(9, 100, k444)) == QualityLevel{80, k420});
  CHECK(capped_by_client(server, level(-1, 95, k444)) == QualityLevel{80, k420});
  // TurboVNC's grey subsampling is coarser than anything: taken. Its fine quality 50 alone: taken.
  CHECK(capped_by_client(server, level(-1, -1, kGrey)) == QualityLevel{80, kGrey});
  CHECK(capped_by_client(server, level(-1, 50, k444)) == QualityLevel{50, k420});
  // A server configured for 4:4:4 takes the client's 4:2:2.
  CHECK(capped_by_client({90, k444}, level(3, 42, k422)) == QualityLevel{42, k422});
  // Values libvncserver would never hand over change nothing.
  CHECK(capped_by_client(server, level(-1, 0, 9)) == QualityLevel{80, k420});
  CHECK(capped_by_client(server, level(-1, 101, -2)) == QualityLevel{80, k420});
}

TEST_CASE("a streamer's top quality is the client's request under the server's cap") {
  ClientStreamer streamer(server_config());
  const auto now = ClientStreamer::Clock::now();
  // Before the client's first update, the server's quality; its status names no request.
  CHECK(streamer.tight_quality() == QualityLevel{80, k420});
  auto status = streamer.status(1, now, rfbEncodingTight);
  CHECK(status.quality == 80);
  CHECK(status.requested_quality == 0);
  CHECK(status.requested_quality_level == -1);
  CHECK(status.compress_level == 6);

  SECTION("TigerVNC's -QualityLevel=3 -CompressLevel=1") {
    streamer.client_requested(level(3, 42, k422, 1));
    CHECK(streamer.tight_quality() == QualityLevel{42, k420});
    status = streamer.status(1, now, rfbEncodingTight);
    CHECK(status.quality == 42);
    CHECK(status.quality_level == 0);  // the top of this client's ladder
    CHECK(status.requested_quality == 42);
    CHECK(status.requested_quality_level == 3);
    CHECK(status.compress_level == 1);
  }
  SECTION("noVNC's default level 6: quality 79, one below the cap, at the server's 4:2:0") {
    streamer.client_requested(level(6, 79, k444));
    CHECK(streamer.tight_quality() == QualityLevel{79, k420});
    CHECK(streamer.status(1, now, rfbEncodingTight).requested_quality == 79);
  }
  SECTION("a request above the cap is shown, and the cap is what is used") {
    streamer.client_requested(level(9, 100, k444, 9));
    CHECK(streamer.tight_quality() == QualityLevel{80, k420});
    status = streamer.status(1, now, rfbEncodingTight);
    CHECK(status.quality == 80);
    CHECK(status.requested_quality == 100);
    CHECK(status.requested_quality_level == 9);
    CHECK(status.compress_level == 9);
  }
  SECTION("a later SetEncodings without a level gives the server's quality back") {
    streamer.client_requested(level(1, 29, k420));
    CHECK(streamer.tight_quality() == QualityLevel{29, k420});
    streamer.client_requested(ClientQualityRequest{});
    CHECK(streamer.tight_quality() == QualityLevel{80, k420});
    CHECK(streamer.status(1, now, rfbEncodingTight).requested_quality == 0);
  }
  SECTION("a lossless encoding shows the request but no quality in use") {
    streamer.client_requested(level(3, 42, k422, 1));
    status = streamer.status(1, now, rfbEncodingZRLE);
    CHECK(status.quality == 0);
    CHECK(status.requested_quality == 42);
  }
}

TEST_CASE("a server that respects the client's level imposes nothing, and still reports the request") {
  ClientStreamer streamer(server_config(0));
  streamer.client_requested(level(3, 42, k422, 1));
  CHECK(streamer.tight_quality() == std::nullopt);
  const auto status = streamer.status(1, ClientStreamer::Clock::now(), rfbEncodingTight);
  CHECK(status.requested_quality == 42);
  CHECK(status.compress_level == 1);
}
