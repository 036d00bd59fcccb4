// SPDX-License-Identifier: GPL-2.0-or-later
// ServedScene: an in-process rfbsim::Server whose frames the test drives, with one well-behaved
// libvncclient client connected, and the checks every robustness case ends with: the good client still
// gets fresh frames, a new client is still served, and the bad client is forgotten.
#pragma once

#include <catch2/catch.hpp>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <random>
#include <thread>
#include <vector>

#include "eventually.hpp"
#include "rfb_test_client.hpp"
#include "rfbsim/server.hpp"

namespace rfbsim::test {

using Clock = std::chrono::steady_clock;

// How long the checks wait for an effect to show; generous, never a timing assertion.
inline constexpr std::chrono::milliseconds kPatience{10000};

struct Rgb {
  std::uint8_t r, g, b;
};

// The k-th test colour; consecutive colours differ in every channel.
inline Rgb colour(int k) {
  return {static_cast<std::uint8_t>(k * 53), static_cast<std::uint8_t>(k * 97 + 80),
          static_cast<std::uint8_t>(k * 29 + 160)};
}

// A server of the given options with one good client connected and a frame source the test drives.
class ServedScene {
 public:
  explicit ServedScene(rfbsim::ServerOptions options)
      : server_(std::move(options)),
        width_(server_.options().width),
        height_(server_.options().height),
        pixels_(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_) * 4U) {
    fill(colour(next_colour_++));
    good_ = std::make_unique<RfbTestClient>("127.0.0.1", server_.port());
    REQUIRE(good_->wait_for_updates(1, kPatience));
  }

  rfbsim::Server& server() { return server_; }
  int port() const { return server_.port(); }
  RfbTestClient& good() { return *good_; }

  // Submits random noise (incompressible: every update is as large as the frame allows).
  void submit_noise(std::uint32_t seed) {
    std::mt19937 generator(seed);
    for (std::size_t i = 0; i < pixels_.size(); i += 4) {
      const auto v = generator();
      pixels_[i] = static_cast<std::uint8_t>(v);
      pixels_[i + 1] = static_cast<std::uint8_t>(v >> 8);
      pixels_[i + 2] = static_cast<std::uint8_t>(v >> 16);
      pixels_[i + 3] = 255;
    }
    server_.submit(rfbsim::FrameView{pixels_.data(), width_, height_, 0});
  }

  // Submits a frame of a colour the good client has not seen yet and pumps the good client until its
  // picture shows that colour: proof of a fresh update, not a stale one already on the wire.
  bool good_client_gets_fresh_frame(std::chrono::milliseconds timeout = kPatience) {
    const Rgb want = colour(next_colour_++);
    fill(want);
    const auto started = Clock::now();
    const bool ok = good_->pump_until([&] { return centre_is(want); }, timeout);
    const auto waited = std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - started);
    longest_wait_ = std::max(longest_wait_, waited);
    return ok;
  }

  // A client connecting now completes the handshake and gets the current picture; it then leaves.
  bool new_client_is_served() {
    bool served = false;
    try {
      RfbTestClient fresh("127.0.0.1", server_.port());
      served = fresh.width() == width_ && fresh.height() == height_ && fresh.wait_for_updates(1, kPatience);
    } catch (const std::exception& e) {
      UNSCOPED_INFO("new client failed: " << e.what());
    }
    return served && eventually([&] { return server_.client_count() == 1; }, kPatience);
  }

  // Only the good client is left.
  bool back_to_one_client() {
    return eventually([&] { return server_.client_count() == 1; }, kPatience);
  }

  // The three checks every case ends with.
  void check_still_serving() {
    CHECK(back_to_one_client());
    CHECK(good_client_gets_fresh_frame());
    CHECK(good_client_gets_fresh_frame());
    CHECK(good_->connected());
    CHECK(new_client_is_served());
  }

  // The longest a fresh frame took to reach the good client so far (reported, never asserted).
  std::chrono::milliseconds longest_wait() const { return longest_wait_; }

 private:
  void fill(Rgb c) {
    for (std::size_t i = 0; i < pixels_.size(); i += 4) {
      pixels_[i] = c.r;
      pixels_[i + 1] = c.g;
      pixels_[i + 2] = c.b;
      pixels_[i + 3] = 255;
    }
    server_.submit(rfbsim::FrameView{pixels_.data(), width_, height_, 0});
  }

  bool centre_is(Rgb c) const {
    const rfbsim::FrameView view = good_->frame();
    const std::uint8_t* p = view.row(view.height / 2) + static_cast<std::size_t>(view.width / 2) * 4U;
    const auto near = [](std::uint8_t a, std::uint8_t b) { return std::abs(int{a} - int{b}) <= 8; };
    return near(p[0], c.r) && near(p[1], c.g) && near(p[2], c.b);
  }

  rfbsim::Server server_;
  int width_;
  int height_;
  std::vector<std::uint8_t> pixels_;
  int next_colour_ = 1;
  std::unique_ptr<RfbTestClient> good_;
  std::chrono::milliseconds longest_wait_{0};
};

}  // namespace rfbsim::test
