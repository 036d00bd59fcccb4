// SPDX-License-Identifier: GPL-2.0-or-later
// RfbTestClient over libvncclient, plus small loopback HTTP helpers for tests.
#include "rfb_test_client.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <rfb/rfbclient.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <mutex>
#include <stdexcept>

#include "rfb_client_messages.hpp"

namespace rfbsim::test {

namespace {

int g_tag = 0;  // address used as libvncclient's client-data tag

void quiet_log(const char* /*format*/, ...) {}

// libvncclient allocates the framebuffer through this hook; we keep it in a vector we own.
rfbBool resize_framebuffer(rfbClient* client) {
  auto* self = static_cast<std::vector<std::uint8_t>*>(rfbClientGetClientData(client, &g_tag + 1));
  self->assign(static_cast<std::size_t>(client->width) * static_cast<std::size_t>(client->height) * 4U, 0);
  client->frameBuffer = self->data();
  client->updateRect.x = client->updateRect.y = 0;
  client->updateRect.w = client->width;
  client->updateRect.h = client->height;
  SetFormatAndEncodings(client);
  return TRUE;
}

// libvncclient sends an incremental update request after each update unless the server's
// SupportedMessages say it may not: clearing that bit is how a ContinuousUpdates client goes quiet.
void allow_update_requests(rfbClient* client, bool allow) {
  std::uint8_t& bits = client->supportedMessages.client2server[rfbFramebufferUpdateRequest / 8];
  const auto bit = static_cast<std::uint8_t>(1U << (rfbFramebufferUpdateRequest % 8));
  bits = allow ? static_cast<std::uint8_t>(bits | bit) : static_cast<std::uint8_t>(bits & ~bit);
}

// The encodings the extension adds to SetEncodings: libvncclient's extension list is global, so the
// list is filled per client, under a lock, for the length of that client's handshake.
std::mutex g_offer_mutex;
int g_offered_encodings[3] = {0, 0, 0};

}  // namespace

// Fence and ContinuousUpdates for libvncclient, which has neither: server messages 150 and 248 reach
// handleMessage with only their type byte read.
struct StreamingExtension {
  static rfbBool handle(rfbClient* client, rfbServerToClientMsg* message) {
    auto* self = static_cast<RfbTestClient*>(rfbClientGetClientData(client, &g_tag));
    if (self == nullptr || self->mode_ != UpdateMode::kContinuous) return FALSE;
    if (message->type == 150) {
      // The first EndOfContinuousUpdates says the server does them: turn them on (as noVNC does). A later
      // one ends them: requests are needed again.
      ++self->end_of_continuous_;
      if (self->end_of_continuous_ == 1) {
        const auto enable = enable_continuous_message(true, client->width, client->height);
        WriteToRFBServer(client, reinterpret_cast<const char*>(enable.data()), static_cast<unsigned>(enable.size()));
        allow_update_requests(client, false);
        self->continuous_ = true;
      } else {
        self->continuous_ = false;
        allow_update_requests(client, true);
        SendIncrementalFramebufferUpdateRequest(client);
      }
      return TRUE;
    }
    if (message->type == 248) {
      std::uint8_t head[8];
      if (!ReadFromRFBServer(client, reinterpret_cast<char*>(head), sizeof head)) return FALSE;
      const std::uint32_t flags = (std::uint32_t{head[3]} << 24) | (std::uint32_t{head[4]} << 16) |
                                  (std::uint32_t{head[5]} << 8) | head[6];
      std::uint8_t payload[255];
      if (head[7] > 0 && !ReadFromRFBServer(client, reinterpret_cast<char*>(payload), head[7])) return FALSE;
      if ((flags & (1U << 31)) == 0 || head[7] > 64) {
        ++self->bad_fences_;
        return TRUE;
      }
      // Answer: Request cleared, BlockBefore/BlockAfter kept (handled in order anyway), payload echoed.
      std::vector<std::uint8_t> answer{248, 0, 0, 0, 0, 0, 0, static_cast<std::uint8_t>(flags & 3U), head[7]};
      answer.insert(answer.end(), payload, payload + head[7]);
      WriteToRFBServer(client, reinterpret_cast<const char*>(answer.data()), static_cast<unsigned>(answer.size()));
      ++self->fences_answered_;
      return TRUE;
    }
    return FALSE;
  }

  static void register_once() {
    static std::once_flag once;
    std::call_once(once, [] {
      static rfbClientProtocolExtension extension{};
      extension.encodings = g_offered_encodings;
      extension.handleMessage = handle;
      rfbClientRegisterExtension(&extension);
    });
  }
};

RfbTestClient::RfbTestClient(const std::string& host, int port, int quality, UpdateMode mode) : mode_(mode) {
  if (std::getenv("RFBSIM_VNC_LOG") == nullptr) {
    rfbClientLog = quiet_log;
    rfbClientErr = quiet_log;
  }
  client_ = rfbGetClient(8, 3, 4);  // RGBX bytes: red in the lowest byte, as rfbsim serves
  free(client_->serverHost);  // rfbGetClient's placeholder
  client_->serverHost = strdup(host.c_str());
  client_->serverPort = port;
  client_->appData.encodingsString = "tight copyrect";
  client_->appData.compressLevel = 1;
  client_->appData.qualityLevel = quality;
  client_->appData.enableJPEG = TRUE;
  client_->appData.useRemoteCursor = FALSE;
  client_->canHandleNewFBSize = FALSE;
  client_->MallocFrameBuffer = resize_framebuffer;
  client_->FinishedFrameBufferUpdate = on_update_finished;
  rfbClientSetClientData(client_, &g_tag, this);
  rfbClientSetClientData(client_, &g_tag + 1, &pixels_);
  StreamingExtension::register_once();
  const std::lock_guard offer_lock(g_offer_mutex);
  g_offered_encodings[0] = mode == UpdateMode::kContinuous ? -312 : 0;  // Fence
  g_offered_encodings[1] = mode == UpdateMode::kContinuous ? -313 : 0;  // ContinuousUpdates
  // On failure rfbInitClient frees the client itself.
  if (!rfbInitClient(client_, nullptr, nullptr)) {
    client_ = nullptr;
    throw std::runtime_error("RFB connection to " + host + ":" + std::to_string(port) + " failed");
  }
  connected_ = true;
}

RfbTestClient::~RfbTestClient() {
  if (client_ != nullptr) {
    client_->frameBuffer = nullptr;  // ours, not libvncclient's
    rfbClientCleanup(client_);
  }
}

void RfbTestClient::on_update_finished(rfbClient* client) {
  auto* self = static_cast<RfbTestClient*>(rfbClientGetClientData(client, &g_tag));
  ++self->updates_;
}

bool RfbTestClient::pump_until(const std::function<bool()>& done, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!done()) {
    if (!connected_ || std::chrono::steady_clock::now() >= deadline) return done();
    // libvncclient reads ahead into its own buffer: messages already there (a fence right behind an
    // update) are handled before waiting on the socket, which would not show them.
    const int ready = client_->buffered > 0 ? 1 : WaitForMessage(client_, 20000);  // microseconds
    if (ready < 0) {
      connected_ = false;
    } else if (ready > 0 && !HandleRFBServerMessage(client_)) {
      connected_ = false;
    }
  }
  return true;
}

bool RfbTestClient::wait_for_updates(std::uint64_t count, std::chrono::milliseconds timeout) {
  const std::uint64_t target = updates_ + count;
  return pump_until([&] { return updates_ >= target; }, timeout);
}

int RfbTestClient::width() const { return client_->width; }
int RfbTestClient::height() const { return client_->height; }

FrameView RfbTestClient::frame() const { return FrameView{pixels_.data(), client_->width, client_->height, 0}; }

std::string RfbTestClient::desktop_name() const { return client_->desktopName ? client_->desktopName : ""; }

void RfbTestClient::send_key(std::uint32_t keysym, bool down) { SendKeyEvent(client_, keysym, down ? TRUE : FALSE); }

void RfbTestClient::send_pointer(int x, int y, int buttons) { SendPointerEvent(client_, x, y, buttons); }

bool RfbTestClient::send_raw(const std::vector<std::uint8_t>& bytes) {
  return WriteToRFBServer(client_, reinterpret_cast<const char*>(bytes.data()), static_cast<unsigned>(bytes.size())) !=
         FALSE;
}

void RfbTestClient::disable_continuous() {
  send_raw(enable_continuous_message(false, client_->width, client_->height));
}

double mean_abs_difference(const FrameView& a, const FrameView& b) {
  if (a.width != b.width || a.height != b.height) return std::numeric_limits<double>::infinity();
  double sum = 0.0;
  for (int y = 0; y < a.height; ++y) {
    const std::uint8_t* ra = a.row(y);
    const std::uint8_t* rb = b.row(y);
    for (int x = 0; x < a.width; ++x) {
      for (int c = 0; c < 3; ++c) sum += std::abs(int{ra[x * 4 + c]} - int{rb[x * 4 + c]});
    }
  }
  return sum / (3.0 * a.width * a.height);
}

std::string http_get(int port, const std::string& path, std::chrono::milliseconds timeout) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
    ::close(fd);
    return {};
  }
  const std::string request = "GET " + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n";
  ::send(fd, request.data(), request.size(), MSG_NOSIGNAL);
  std::string response;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    pollfd pfd{fd, POLLIN, 0};
    if (left.count() <= 0 || ::poll(&pfd, 1, static_cast<int>(left.count())) <= 0) break;
    char buffer[4096];
    const auto n = ::recv(fd, buffer, sizeof buffer, 0);
    if (n <= 0) break;
    response.append(buffer, static_cast<std::size_t>(n));
  }
  ::close(fd);
  return response;
}

std::string http_body(const std::string& response) {
  const auto blank = response.find("\r\n\r\n");
  return blank == std::string::npos ? std::string() : response.substr(blank + 4);
}

double json_number(const std::string& json, const std::string& key) {
  const std::string needle = "\"" + key + "\":";
  const auto at = json.find(needle);
  if (at == std::string::npos) return std::numeric_limits<double>::quiet_NaN();
  return std::strtod(json.c_str() + at + needle.size(), nullptr);
}

}  // namespace rfbsim::test
