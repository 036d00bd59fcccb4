// SPDX-License-Identifier: GPL-2.0-or-later
// bench_network's live codec quality with tagged frames (see network_tagged.hpp).
#include "network_tagged.hpp"

#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "network_clients.hpp"
#include "network_codec.hpp"
#include "network_report.hpp"
#include "rfbsim/server.hpp"

namespace rfbsim::bench {

namespace {

using std::chrono::milliseconds;

constexpr int kTagBits = 12;
constexpr int kTagBlock = 32;                  // pixels per side of one block
constexpr int kTagHeight = 2 * kTagBlock;      // the tag's rows, left out of the SSIM
constexpr int kTagClearlyApart = 64;           // luma levels between a block and its inverse for a bit to read
constexpr std::size_t kKept = 64;              // frames kept for comparison (2 s at 30 fps)
constexpr auto kFramePeriod = std::chrono::microseconds(33333);
constexpr auto kSsimEvery = milliseconds(100);  // at most ten comparisons a second (each a few ms of CPU)

// The last kKept rendered frames, each with its number, one lock each.
struct Kept {
  std::mutex mutex;
  std::uint32_t index = 0xffffffff;
  std::vector<std::uint8_t> pixels;
};

// Mean luma (0..255) of the inner half of a tag block whose top-left corner is (x, y).
double block_luma(const FrameView& frame, int x, int y) {
  double sum = 0;
  const int q = kTagBlock / 4;
  for (int row = y + q; row < y + kTagBlock - q; ++row) {
    const std::uint8_t* p = frame.row(row) + static_cast<std::size_t>(x + q) * 4;
    for (int col = 0; col < kTagBlock / 2; ++col, p += 4) sum += 0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2];
  }
  return sum / (kTagBlock / 2 * kTagBlock / 2);
}

// The rows above the tag.
FrameView above_tag(const FrameView& frame) {
  return FrameView{frame.pixels, frame.width, frame.height - kTagHeight, frame.stride};
}

// Renders the walk at 30 fps into `server`, keeping each frame in `kept`, until `stop`.
void render_loop(const SimSettings& settings, const std::string& source_dir, rfbsim::Server& server,
                 std::array<Kept, kKept>& kept, std::atomic<bool>& stop, std::atomic<std::uint64_t>& rendered,
                 std::string& error) {
  try {
    WalkScene scene(settings, source_dir);
    auto next = Clock::now();
    for (std::uint32_t i = 0; !stop.load(); ++i) {
      const FrameView frame = scene.next();
      Kept& slot = kept[i % kKept];
      {
        const std::lock_guard lock(slot.mutex);
        PictureCopy copy;
        copy.assign(frame);
        const FrameView packed = copy.view();
        slot.pixels.assign(packed.pixels, packed.pixels + static_cast<std::size_t>(packed.width) * 4U *
                                                              static_cast<std::size_t>(packed.height));
        stamp_tag(slot.pixels.data(), frame.width, frame.height, i);
        slot.index = i;
        server.submit(FrameView{slot.pixels.data(), frame.width, frame.height, 0});
      }
      rendered.fetch_add(1);
      // Real time: one frame per period; behind by more than a few frames, start counting again from now.
      next += kFramePeriod;
      const auto now = Clock::now();
      if (next > now) {
        std::this_thread::sleep_until(next);
      } else if (now - next > 3 * kFramePeriod) {
        next = now;
      }
    }
  } catch (const std::exception& e) {
    error = e.what();
    stop.store(true);
  }
}

TaggedRun run_one(const SimSettings& settings, const std::string& source_dir, const std::string& codec, int rtt,
                  double cap, int warm_up_s, int measure_s) {
  TaggedRun run;
  run.codec = codec;
  run.rtt_ms = rtt;
  run.cap_mbit = cap;
  rfbsim::ServerOptions options;  // sim_rfb's picture options
  options.jpeg_quality = 80;
  options.codec = codec == "h264" ? rfbsim::Codec::kH264 : rfbsim::Codec::kJpeg;
  options.frame_rate = 30;
  auto kept = std::make_unique<std::array<Kept, kKept>>();
  std::unique_ptr<NetClient> client;  // declared before the server, so that the server goes first and closes it
  rfbsim::Server server(options);
  test::LinkEmulator link("127.0.0.1", server.port(), test::link_profile(milliseconds(rtt), cap));
  std::atomic<bool> stop{false};
  std::atomic<std::uint64_t> rendered{0};
  std::string render_error;
  std::thread renderer([&] { render_loop(settings, source_dir, server, *kept, stop, rendered, render_error); });
  try {
    client = connect_client(codec == "h264" ? ClientKind::kH264 : ClientKind::kCu, link.port(), milliseconds(30000));
    const auto from = Clock::now() + std::chrono::seconds(warm_up_s);
    const auto until = from + std::chrono::seconds(measure_s);
    bool started = false;
    test::LinkStats link_from;
    rfbsim::ServerStats server_from;
    std::uint64_t rendered_from = 0;
    std::uint64_t seen = client->updates();
    Clock::time_point last_ssim{};
    while (Clock::now() < until && !stop.load()) {
      if (!started && Clock::now() >= from) {
        started = true;
        link_from = link.stats();
        server_from = server.stats();
        rendered_from = rendered.load();
      }
      client->pump_until([&] { return client->updates() != seen; }, milliseconds(5));
      if (!client->connected()) throw std::runtime_error("the viewer lost its connection");
      if (client->updates() == seen) continue;
      seen = client->updates();
      if (!started) continue;
      ++run.updates;
      const auto now = Clock::now();
      if (now - last_ssim < kSsimEvery) continue;
      last_ssim = now;
      const int tag = read_tag(client->frame());
      if (tag < 0) {
        ++run.unread;
        continue;
      }
      Kept& slot = (*kept)[static_cast<std::size_t>(tag) % kKept];
      const std::lock_guard lock(slot.mutex);
      if ((slot.index & 0xfff) != static_cast<std::uint32_t>(tag) || slot.pixels.empty()) {
        ++run.unread;
        continue;
      }
      const FrameView original{slot.pixels.data(), client->frame().width, client->frame().height, 0};
      run.ssim.push_back(luma_ssim(above_tag(client->frame()), above_tag(original)));
    }
    const test::LinkStats link_to = link.stats();
    const rfbsim::ServerStats server_to = server.stats();
    run.seconds = static_cast<double>(measure_s);
    run.bytes_down = link_to.down.bytes_delivered - link_from.down.bytes_delivered;
    const auto updates_sent = server_to.updates_sent - server_from.updates_sent;
    run.encode_ms_per_update =
        updates_sent > 0 ? (server_to.encode_ms - server_from.encode_ms) / static_cast<double>(updates_sent) : 0.0;
    run.rendered_fps = static_cast<double>(rendered.load() - rendered_from) / run.seconds;
  } catch (const std::exception& e) {
    run.error = e.what();
  }
  stop.store(true);
  renderer.join();
  if (!render_error.empty()) run.error = "rendering: " + render_error;
  return run;
}

}  // namespace

void stamp_tag(std::uint8_t* rgba, int width, int height, std::uint32_t index) {
  if (width < kTagBits * kTagBlock || height < kTagHeight) throw std::invalid_argument("picture too small for a tag");
  const std::size_t stride = static_cast<std::size_t>(width) * 4U;
  for (int bit = 0; bit < kTagBits; ++bit) {
    const bool set = ((index >> bit) & 1U) != 0;
    for (int row = 0; row < 2; ++row) {
      const std::uint8_t level = (set == (row == 0)) ? 255 : 0;
      for (int y = height - kTagHeight + row * kTagBlock; y < height - kTagHeight + (row + 1) * kTagBlock; ++y) {
        std::uint8_t* p = rgba + static_cast<std::size_t>(y) * stride + static_cast<std::size_t>(bit * kTagBlock) * 4U;
        for (int x = 0; x < kTagBlock; ++x, p += 4) p[0] = p[1] = p[2] = level;
      }
    }
  }
}

int read_tag(const FrameView& frame) {
  if (frame.width < kTagBits * kTagBlock || frame.height < kTagHeight) return -1;
  int index = 0;
  for (int bit = 0; bit < kTagBits; ++bit) {
    const double a = block_luma(frame, bit * kTagBlock, frame.height - kTagHeight);
    const double b = block_luma(frame, bit * kTagBlock, frame.height - kTagBlock);
    if (std::abs(a - b) < kTagClearlyApart) return -1;
    if (a > b) index |= 1 << bit;
  }
  return index;
}

std::vector<TaggedRun> run_tagged(const SimSettings& settings, const std::string& source_dir,
                                  const std::vector<std::pair<int, double>>& links, int warm_up_s, int measure_s) {
  std::vector<TaggedRun> runs;
  for (const auto& [rtt, cap] : links) {
    for (const std::string codec : {"jpeg", "h264"}) {
      std::fprintf(stderr, "bench_network: live %s, RTT %d ms cap %s ...\n", codec.c_str(), rtt, cap_text(cap).c_str());
      runs.push_back(run_one(settings, source_dir, codec, rtt, cap, warm_up_s, measure_s));
    }
  }
  return runs;
}

void print_tagged(const std::vector<TaggedRun>& runs) {
  Table table({"codec", "RTT ms", "cap Mbit/s", "rendered fps", "fps", "Mbit/s", "kB/update", "encode ms/update",
               "SSIM n", "SSIM mean", "SSIM p10", "tag unread"},
              1);
  for (const TaggedRun& r : runs) {
    std::vector<std::string> row{r.codec, std::to_string(r.rtt_ms), cap_text(r.cap_mbit)};
    if (!r.error.empty()) {
      row.push_back("failed: " + r.error);
      table.add_row(std::move(row));
      continue;
    }
    const double fps = static_cast<double>(r.updates) / r.seconds;
    const double mbit = static_cast<double>(r.bytes_down) * 8e-6 / r.seconds;
    const Summary s = summarize(r.ssim);
    row.insert(row.end(), {fixed(r.rendered_fps, 1), fixed(fps, 1), fixed(mbit, 2),
                           r.updates > 0 ? fixed(static_cast<double>(r.bytes_down) / 1000.0 /
                                                     static_cast<double>(r.updates), 1)
                                         : "-",
                           fixed(r.encode_ms_per_update, 2), std::to_string(s.n), fixed(s.mean, 4),
                           fixed(quantile(r.ssim, 0.1), 4), std::to_string(r.unread)});
    table.add_row(std::move(row));
  }
  table.print();
  // Per link: H.264 against JPEG.
  for (std::size_t i = 0; i + 1 < runs.size(); i += 2) {
    const TaggedRun& j = runs[i];
    const TaggedRun& h = runs[i + 1];
    if (!j.error.empty() || !h.error.empty() || j.bytes_down == 0 || j.updates == 0) continue;
    std::printf("RTT %d ms, cap %s: H.264 / JPEG bytes per second %.3f (target <= 0.333), fps %.2f (target >= 0.9), "
                "SSIM %+.4f (target >= 0)\n",
                j.rtt_ms, cap_text(j.cap_mbit).c_str(),
                static_cast<double>(h.bytes_down) / static_cast<double>(j.bytes_down),
                static_cast<double>(h.updates) / static_cast<double>(j.updates),
                summarize(h.ssim).mean - summarize(j.ssim).mean);
  }
}

}  // namespace rfbsim::bench
