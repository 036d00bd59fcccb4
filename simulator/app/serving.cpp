// SPDX-License-Identifier: GPL-2.0-or-later
// Serving a session: the ready pipe's lines, the page's folder, the server's options.
#include "app/serving.hpp"

#include <poll.h>
#include <unistd.h>

#include <filesystem>
#include <stdexcept>

#include "app/parent_pipe.hpp"
#include "app/stream_status.hpp"
#include "record/digest.hpp"
#include "rfbsim/log.hpp"

namespace rfbsim::sim {

namespace {

// The page: --web-root if given, else the one built beside this binary, else the installed one.
std::string find_web_root(const std::string& requested) {
  if (!requested.empty()) return requested;
  for (const char* candidate : {RFBSIM_BUILD_WEB_ROOT, RFBSIM_INSTALLED_WEB_ROOT}) {
    std::error_code ec;
    if (std::filesystem::is_regular_file(std::filesystem::path(candidate) / "index.html", ec)) return candidate;
  }
  throw std::runtime_error(std::string("no participant page found (looked in ") + RFBSIM_BUILD_WEB_ROOT + " and " +
                           RFBSIM_INSTALLED_WEB_ROOT + "); run 'npm ci --prefix web' and rebuild, or pass --web-root");
}

}  // namespace

void report_ready(int fd, const rfbsim::Server& server) {
  const std::string& unix_socket = server.options().unix_socket_path;
  const std::string line =
      unix_socket.empty() ? contract::ready_port_line(server.port()) : contract::ready_unix_line(unix_socket);
  const std::string error = write_line(fd, line);
  if (!error.empty()) {
    ::close(fd);
    throw std::runtime_error("--ready-fd " + std::to_string(fd) + ": cannot write the ready line (" + error + ")");
  }
}

void report_outcome(int fd, contract::TaskEnd end) {
  const std::string error = write_line(fd, contract::outcome_line(end));
  if (!error.empty()) rfbsim::log::warn("sim_rfb", "cannot report the outcome to the parent: %s", error.c_str());
}

rfbsim::ServerOptions server_options_of(const SimOptions& options, Picture picture, const StatusBoard& status,
                                        ClientChanges& client_changes, const std::string& address_key) {
  rfbsim::ServerOptions server_options;
  server_options.port = options.port;
  server_options.bind_address = options.bind;
  server_options.width = picture.width;
  server_options.height = picture.height;
  server_options.jpeg_quality = options.jpeg_quality;
  server_options.codec = options.codec == "h264"   ? rfbsim::Codec::kH264
                         : options.codec == "jpeg" ? rfbsim::Codec::kJpeg
                                                   : rfbsim::Codec::kAuto;
  server_options.frame_rate = picture.fps;  // H.264 timing: the rate frames are submitted at while watched
  server_options.max_clients = options.max_clients;
  server_options.desktop_name = "rfbsim";
  server_options.proxy_protocol = options.proxy_protocol;
  server_options.allowed_origins = options.allowed_origins;
  server_options.unix_socket_path = options.unix_socket;
  // RFB only: no web root and no route, which librfbsim takes to mean no HTTP at all, so that a raw RFB
  // client is served sooner (at once after sim_manager's PROXY line) than after the wait for a browser's page
  // request.
  if (!options.rfb_only) {
    server_options.web_root = find_web_root(options.web_root);
    server_options.json_routes["/status.json"] = [&status] { return status.read(); };
  }
  // The log names the participant's address only hashed, as the session data does.
  server_options.on_connect = [&client_changes, &address_key](const rfbsim::ClientInfo& c) {
    rfbsim::log::limited(rfbsim::log::Level::kInfo, "client-connected", "sim_rfb",
                         "client %d connected, address %s (%s)", c.id,
                         hash_address(address_key, c.address).c_str(), c.websocket ? "websocket" : "rfb");
    client_changes.push(true, c);
  };
  server_options.on_disconnect = [&client_changes](const rfbsim::ClientInfo& c) {
    rfbsim::log::limited(rfbsim::log::Level::kInfo, "client-disconnected", "sim_rfb", "client %d disconnected", c.id);
    client_changes.push(false, c);
  };
  return server_options;
}

void StreamReporter::update(std::chrono::steady_clock::time_point now, int clients, const rfbsim::Server& server) {
  if (failed_) return;
  if (clients == 0) {
    if (reported_) write(stream_line({}));  // the parent stops showing the last report
    watched_ = reported_ = false;
    return;
  }
  // The first report a second after the first viewer came, once there is a frame rate to tell.
  if (!watched_) next_ = now + kInterval;
  watched_ = true;
  if (now < next_) return;
  const std::vector<rfbsim::ClientStreamStatus> streams = server.client_streams();
  if (streams.empty()) return;  // the network thread has not seen the viewer yet: try again next loop
  write(stream_line(streams));
  reported_ = true;
  next_ = now + kInterval;
}

void StreamReporter::write(const std::string& line) {
  pollfd pfd{fd_, POLLOUT, 0};
  if (::poll(&pfd, 1, 0) != 1 || (pfd.revents & POLLOUT) == 0) {
    if ((pfd.revents & (POLLERR | POLLHUP)) == 0) return;  // full: this one is skipped, the next may fit
  }
  // Under PIPE_BUF bytes: written whole or not at all.
  const std::string error = write_line(fd_, line);
  if (error.empty()) return;
  failed_ = true;
  rfbsim::log::warn("sim_rfb", "cannot report the stream to the parent: %s; no more stream lines", error.c_str());
}

rfbsim::OffscreenGLOptions gl_options_of(const SimOptions& options, Picture picture) {
  rfbsim::OffscreenGLOptions gl;
  gl.width = picture.width;
  gl.height = picture.height;
  gl.platform = options.egl_platform;
  return gl;
}

}  // namespace rfbsim::sim
