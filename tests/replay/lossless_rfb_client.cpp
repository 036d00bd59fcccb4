// SPDX-License-Identifier: GPL-2.0-or-later
// LosslessRfbClient over libvncclient: Raw only, a framebuffer we own, updates counted.
#include "lossless_rfb_client.hpp"

#include <rfb/rfbclient.h>

#include <cstdlib>
#include <cstring>
#include <stdexcept>

namespace rfbsim::test {

namespace {

int g_tag = 0;  // address used as libvncclient's client-data tag

void quiet_log(const char* /*format*/, ...) {}

// libvncclient allocates the framebuffer through this hook; the picture lives in a vector we own.
rfbBool resize_framebuffer(rfbClient* client) {
  auto* pixels = static_cast<std::vector<std::uint8_t>*>(rfbClientGetClientData(client, &g_tag + 1));
  pixels->assign(static_cast<std::size_t>(client->width) * static_cast<std::size_t>(client->height) * 4U, 0);
  client->frameBuffer = pixels->data();
  SetFormatAndEncodings(client);
  return TRUE;
}

}  // namespace

LosslessRfbClient::LosslessRfbClient(const std::string& host, int port) {
  if (std::getenv("RFBSIM_VNC_LOG") == nullptr) {
    rfbClientLog = quiet_log;
    rfbClientErr = quiet_log;
  }
  client_ = rfbGetClient(8, 3, 4);  // RGBX bytes: red in the lowest byte, as rfbsim serves
  free(client_->serverHost);        // rfbGetClient's placeholder
  client_->serverHost = strdup(host.c_str());
  client_->serverPort = port;
  // Raw alone: every pixel arrives as the server holds it (no JPEG, no palette reduction).
  client_->appData.encodingsString = "raw";
  client_->appData.useRemoteCursor = FALSE;
  client_->canHandleNewFBSize = FALSE;
  client_->MallocFrameBuffer = resize_framebuffer;
  client_->FinishedFrameBufferUpdate = on_update_finished;
  rfbClientSetClientData(client_, &g_tag, this);
  rfbClientSetClientData(client_, &g_tag + 1, &pixels_);
  // On failure rfbInitClient frees the client itself.
  if (!rfbInitClient(client_, nullptr, nullptr)) {
    client_ = nullptr;
    throw std::runtime_error("RFB connection to " + host + ":" + std::to_string(port) + " failed");
  }
  connected_ = true;
}

LosslessRfbClient::~LosslessRfbClient() {
  if (client_ == nullptr) return;
  client_->frameBuffer = nullptr;  // ours, not libvncclient's
  rfbClientCleanup(client_);
}

void LosslessRfbClient::on_update_finished(rfbClient* client) {
  ++static_cast<LosslessRfbClient*>(rfbClientGetClientData(client, &g_tag))->updates_;
}

bool LosslessRfbClient::handle_one(int wait_us) {
  if (!connected_) return false;
  // libvncclient reads ahead into its own buffer: what is already there is handled without waiting.
  const int ready = client_->buffered > 0 ? 1 : WaitForMessage(client_, static_cast<unsigned>(wait_us));
  if (ready < 0 || (ready > 0 && !HandleRFBServerMessage(client_))) connected_ = false;
  return connected_;
}

bool LosslessRfbClient::pump(std::chrono::milliseconds duration) {
  const auto deadline = std::chrono::steady_clock::now() + duration;
  while (std::chrono::steady_clock::now() < deadline) {
    if (!handle_one(10000)) return false;
  }
  return connected_;
}

bool LosslessRfbClient::refresh(std::chrono::milliseconds timeout) {
  if (!connected_) return false;
  // Meant for a still picture: with nothing changing no other update is on its way, so the next one to
  // finish is the whole picture asked for.
  const std::uint64_t before = updates_;
  if (!SendFramebufferUpdateRequest(client_, 0, 0, client_->width, client_->height, FALSE)) return false;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (updates_ < before + 1) {
    if (std::chrono::steady_clock::now() >= deadline || !handle_one(10000)) return false;
  }
  return true;
}

std::vector<std::uint8_t> LosslessRfbClient::rgb() const {
  std::vector<std::uint8_t> out;
  out.reserve(pixels_.size() / 4 * 3);
  for (std::size_t i = 0; i + 3 < pixels_.size(); i += 4) out.insert(out.end(), &pixels_[i], &pixels_[i] + 3);
  return out;
}

int LosslessRfbClient::width() const { return client_->width; }
int LosslessRfbClient::height() const { return client_->height; }

void LosslessRfbClient::send_key(std::uint32_t keysym, bool down) {
  SendKeyEvent(client_, keysym, down ? TRUE : FALSE);
}

}  // namespace rfbsim::test
