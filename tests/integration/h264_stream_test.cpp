// SPDX-License-Identifier: GPL-2.0-or-later
// H.264 (the open H.264 rectangle, encoding 50) end to end: the in-process server encodes, a client that
// decodes with libavcodec (tests/support's H264RfbClient) shows the served picture; clients that do not
// offer 50 get Tight JPEG from the same server.
#include <catch2/catch.hpp>

#include <chrono>
#include <cstdint>
#include <functional>
#include <thread>
#include <vector>

#include "eventually.hpp"
#include "h264_rfb_client.hpp"
#include "rfb_test_client.hpp"
#include "rfbsim/server.hpp"

using namespace std::chrono_literals;
using rfbsim::test::eventually;
using rfbsim::test::H264RfbClient;
using rfbsim::test::RfbTestClient;

namespace {

constexpr int kH264Width = 320;
constexpr int kH264Height = 240;

// A smooth picture that depends on `k`: a diagonal gradient and, over a quarter of it, a block whose colour
// swings between two far-apart colours from one k to the next, so that consecutive pictures differ by far
// more (a mean of about 45 per channel) than the encoder's error on a smooth picture (under 1).
std::vector<std::uint8_t> picture(int k) {
  std::vector<std::uint8_t> pixels(static_cast<std::size_t>(kH264Width) * kH264Height * 4U);
  const bool warm = k % 2 == 0;
  for (int y = 0; y < kH264Height; ++y) {
    for (int x = 0; x < kH264Width; ++x) {
      std::uint8_t* p = &pixels[(static_cast<std::size_t>(y) * kH264Width + static_cast<std::size_t>(x)) * 4U];
      const bool block = x >= 40 + k * 8 && x < 200 + k * 8 && y >= 60 && y < 180;
      p[0] = block ? (warm ? 250 : 20) : static_cast<std::uint8_t>(x * 255 / kH264Width);
      p[1] = block ? (warm ? 230 : 60) : static_cast<std::uint8_t>(y * 255 / kH264Height);
      p[2] = block ? (warm ? 30 : 230) : static_cast<std::uint8_t>(128 + (x + y) / 8);
      p[3] = 255;
    }
  }
  return pixels;
}

rfbsim::ServerOptions h264_server(rfbsim::Codec codec = rfbsim::Codec::kH264) {
  rfbsim::ServerOptions options;
  options.width = kH264Width;
  options.height = kH264Height;
  options.codec = codec;
  return options;
}

void submit(rfbsim::Server& server, const std::vector<std::uint8_t>& pixels) {
  server.submit(rfbsim::FrameView{pixels.data(), kH264Width, kH264Height, 0});
}

std::string encoding_of(const rfbsim::Server& server, int id) {
  for (const auto& stream : server.client_streams()) {
    if (stream.id == id) return stream.encoding;
  }
  return "";
}

}  // namespace

TEST_CASE("an H.264 client gets pictures that decode to the served frames", "[streaming][h264]") {
  rfbsim::Server server(h264_server());
  H264RfbClient client("127.0.0.1", server.port());
  // List what noVNC lists besides: cursor shapes (-239) and desktop size (-223, -308). libvncserver then
  // has cursor and size news pending that only its own updates would deliver.
  std::vector<std::uint8_t> encodings{2, 0, 0, 7};
  for (const std::int32_t e : {50, 0, -312, -313, -239, -223, -308}) {
    for (int shift = 24; shift >= 0; shift -= 8) encodings.push_back(static_cast<std::uint8_t>(e >> shift));
  }
  REQUIRE(client.send_raw(encodings));
  for (int k = 0; k < 8; ++k) {
    const auto pixels = picture(k);
    submit(server, pixels);
    const rfbsim::FrameView served{pixels.data(), kH264Width, kH264Height, 0};
    // Smooth content at CRF 23: the decoded picture is within a few levels of the source everywhere.
    INFO("frame " << k);
    CHECK(client.pump_until([&] { return rfbsim::test::mean_abs_difference(client.frame(), served) < 3.0; }, 10s));
  }
  // One picture per changed frame at most (plus the first, grey, picture), and none for a still one:
  // cursor or desktop-size news that only libvncserver's own updates deliver must not keep H.264 busy.
  const auto pictures = client.h264_pictures();
  CHECK(pictures <= 9);
  client.pump_until([] { return false; }, 1s);
  CHECK(client.h264_pictures() == pictures);
  CHECK(client.idr_pictures() >= 1);
  CHECK(client.decode_errors() == 0);
  CHECK(client.raw_rects() == 0);  // every picture came as H.264
  CHECK(client.continuous());
  CHECK(client.bad_fences() == 0);
  REQUIRE(eventually([&] { return encoding_of(server, 1) == "h264"; }, 5s));
}

TEST_CASE("a full update request restarts the H.264 stream with an IDR", "[streaming][h264]") {
  rfbsim::Server server(h264_server());
  H264RfbClient client("127.0.0.1", server.port());
  submit(server, picture(0));
  REQUIRE(client.wait_for_updates(1, 10s));
  const auto idrs = client.idr_pictures();
  submit(server, picture(1));
  REQUIRE(client.wait_for_updates(1, 10s));
  CHECK(client.idr_pictures() == idrs);  // a changed frame is a P picture
  // FramebufferUpdateRequest, non-incremental, whole screen.
  const std::vector<std::uint8_t> full_request{3, 0, 0, 0, 0, 0, 0x01, 0x40, 0x00, 0xF0};
  REQUIRE(client.send_raw(full_request));
  CHECK(client.pump_until([&] { return client.idr_pictures() > idrs; }, 10s));
  CHECK(client.decode_errors() == 0);
}

TEST_CASE("with codec h264, clients that do not offer it get Tight beside an H.264 client", "[streaming][h264]") {
  rfbsim::Server server(h264_server());
  H264RfbClient h264("127.0.0.1", server.port());
  RfbTestClient tight("127.0.0.1", server.port());
  for (int k = 0; k < 3; ++k) {
    const auto pixels = picture(k);
    submit(server, pixels);
    const rfbsim::FrameView served{pixels.data(), kH264Width, kH264Height, 0};
    CHECK(h264.pump_until([&] { return rfbsim::test::mean_abs_difference(h264.frame(), served) < 3.0; }, 10s));
    CHECK(tight.pump_until([&] { return rfbsim::test::mean_abs_difference(tight.frame(), served) < 3.0; }, 10s));
  }
  REQUIRE(eventually([&] { return encoding_of(server, 1) == "h264" && encoding_of(server, 2) == "tight"; }, 5s));
}

TEST_CASE("with codec jpeg, a client that offers H.264 still gets Tight", "[streaming][h264]") {
  rfbsim::Server server(h264_server(rfbsim::Codec::kJpeg));
  rfbsim::test::H264RfbClientOptions options;
  options.offer_tight = true;
  H264RfbClient client("127.0.0.1", server.port(), options);
  submit(server, picture(0));
  // This client cannot decode Tight: pump_until throws on the first Tight rectangle, as it should here.
  CHECK_THROWS_WITH(client.pump_until([] { return false; }, 5s), Catch::Contains("Tight"));
  CHECK(client.h264_pictures() == 0);
}
