// SPDX-License-Identifier: GPL-2.0-or-later
// A session's end: timers, stopping its process, reaping, the log tail, the X11 display's clean-up, the
// after-session copy; and the participant's presence, which the idle timer follows.
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <thread>

#include "admission/tokens.hpp"
#include "record/digest.hpp"
#include "rfbsim/log.hpp"
#include "sessions/launch_plan.hpp"
#include "sessions/process_launcher.hpp"
#include "sessions/session_process.hpp"
#include "sessions/session_views.hpp"
#include "sessions/supervisor.hpp"
#include "sessions/supervisor_runtime.hpp"
#include "x11_display.hpp"

namespace rfbsim::manager {

namespace {

using SteadyClock = std::chrono::steady_clock;
namespace asio = boost::asio;

}  // namespace

void Supervisor::begin_end(Session& session, SessionState end_as, const std::string& detail) {
  if (!begin_ending(session, end_as, detail)) return;
  save(session);
  log_session(session, std::string("ending (") + state_name(end_as) + "): " + detail);
  if (listener_ != nullptr) listener_->session_closing(session);
  Runtime& rt = runtime(session.id);
  rt.start_deadline.cancel();
  rt.expiry.cancel();
  rt.idle.cancel();
  // A session whose process is still being started gets stopped once its pid is known (launched()).
  if (session.pid > 1) stop_process(session);
}

void Supervisor::stop_process(Session& session) {
  if (config_.stop_grace.count() == 0) {
    signal_process_group(session.pid, SIGKILL);
    return;
  }
  signal_process_group(session.pid, SIGTERM);
  const std::int64_t id = session.id;
  Runtime& rt = runtime(id);
  rt.stop.expires_after(config_.stop_grace);
  rt.stop.async_wait([this, id](const boost::system::error_code& ec) {
    Session* s = table_.by_id(id);
    if (ec || s == nullptr) return;
    log_session(*s, "still running after the grace period; SIGKILL");
    signal_process_group(s->pid, SIGKILL);
  });
}

void Supervisor::reap_children() {
  // While a start is in flight, a child may exit before its pid reaches the table: reaping it then would lose
  // its exit. So only the sessions' own pids are reaped until no start is in flight; then any child at all.
  std::vector<pid_t> known;
  for (Session* session : table_.all()) {
    if (session->pid > 1) known.push_back(session->pid);
  }
  for (const pid_t pid : known) reap_if_exited(pid);
  if (launches_in_flight_ > 0) return;
  for (;;) {
    siginfo_t info{};
    if (::waitid(P_ALL, 0, &info, WEXITED | WNOHANG | WNOWAIT) != 0 || info.si_pid == 0) return;
    // The after-session copier's command is its own to reap (it waits for that pid alone).
    if (copier_ && copier_->may_own(info.si_pid)) return;
    if (!reap_if_exited(info.si_pid)) return;
  }
}

bool Supervisor::reap_if_exited(pid_t pid) {
  // Look before reaping: while the exited leader is a zombie its id cannot be reused, so the SIGKILL to its
  // group reaches only what the session's program left behind, never a stranger.
  siginfo_t info{};
  if (::waitid(P_PID, static_cast<id_t>(pid), &info, WEXITED | WNOHANG | WNOWAIT) != 0 || info.si_pid != pid) {
    return false;
  }
  signal_process_group(pid, SIGKILL);
  int status = 0;
  if (::waitpid(pid, &status, 0) != pid) return false;
  if (Session* session = table_.by_pid(pid)) process_gone(*session, status);
  return true;
}

std::function<void(const std::string&)> Supervisor::copy_after_commit(Session& session) {
  std::error_code ec;
  if (!copier_ || session.data_path.empty() || !std::filesystem::is_directory(session.data_path, ec)) return nullptr;
  session.copy_state = "pending";
  // Queued even when the index refused the row: the copy of the data matters more than its record.
  return [this, job = copy_job_for(session)](const std::string&) { copier_->enqueue(job); };
}

std::string Supervisor::session_log_tail(const Session& session) const {
  std::ifstream log(session.data_path + "/session.log", std::ios::binary | std::ios::ate);
  if (!log) return "";
  const std::streamoff size = log.tellg();
  const std::streamoff from = size > 400 ? size - 400 : 0;
  log.seekg(from);
  std::string tail((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
  while (!tail.empty() && (tail.back() == '\n' || tail.back() == '\r')) tail.pop_back();
  const std::size_t newline = tail.rfind('\n');
  return newline == std::string::npos ? tail : tail.substr(newline + 1);
}

void Supervisor::process_gone(Session& session, int wait_status) {
  const SessionState final_state = state_after_exit(session, wait_status);
  session.exit_status = describe_wait_status(wait_status);
  if (session.state != SessionState::kEnding) {
    const std::string last_line = session_log_tail(session);
    session.detail =
        "the program stopped by itself (" + session.exit_status + ")" + (last_line.empty() ? "" : ": " + last_line);
  }
  session.state = final_state;
  session.ended_at = std::chrono::system_clock::now();
  ++ended_counts_[final_state];
  // A killed sim_rfb leaves its socket file behind; a killed rfbsim_x11_session its Xauthority, and its Xvnc
  // (killed with the group) the display's lock file and X socket.
  if (!session.unix_socket.empty()) {
    std::error_code ignored;
    std::filesystem::remove(session.unix_socket, ignored);
  }
  if (config_.session_kind == SessionKind::kX11) {
    std::error_code ignored;
    std::filesystem::remove(x11_xauthority_path(session.id), ignored);
    // Killed, the launcher could not stop its Xvnc in order; exited, it did, and the display's number may already
    // be another session's.
    if (WIFSIGNALED(wait_status)) clean_x11_display(runtime(session.id).x11_display, 0);
  }
  save(session, copy_after_commit(session));
  log_session(session, std::string(state_name(final_state)) + " (" + session.exit_status + ")");
  if (listener_ != nullptr) listener_->session_closing(session);
  const std::int64_t id = session.id;
  runtimes_.erase(id);
  table_.remove(id);  // the slot is free from here on
  notify_if_all_gone();
}

std::string Supervisor::x11_xauthority_path(std::int64_t id) const {
  return socket_dir_ + "/" + std::to_string(id) + ".xauth";
}

void Supervisor::clean_x11_display(int display, int attempt) {
  if (display < 0 || x11::remove_stale_display(display)) return;
  // Its Xvnc was killed with the group a moment ago and may not be gone yet: look again, for a few seconds.
  if (attempt >= 20) {
    rfbsim::log::info("manager", "display :%d: its X server is still running; its lock file is left", display);
    return;
  }
  auto timer = std::make_shared<asio::steady_timer>(io_, std::chrono::milliseconds(250));
  timer->async_wait([this, timer, display, attempt](const boost::system::error_code& ec) {
    if (!ec) clean_x11_display(display, attempt + 1);
  });
}

void Supervisor::arm_idle_timer(Session& session) {
  const std::int64_t id = session.id;
  Runtime& rt = runtime(id);
  // Until a browser first comes, the shorter wait: a link preview never opens the socket, and each such
  // session would hold a slot for the whole idle timeout.
  const bool first = !rt.ever_connected && config_.first_connect_timeout < config_.idle_timeout;
  const auto wait = first ? config_.first_connect_timeout : config_.idle_timeout;
  rt.idle.expires_after(wait);
  rt.idle.async_wait([this, id, first, wait](const boost::system::error_code& ec) {
    Session* s = table_.by_id(id);
    if (ec || s == nullptr || runtime(id).clients > 0) return;
    begin_end(*s, SessionState::kIdle,
              first ? "no browser connected within " + std::to_string(wait.count()) + " s of the start"
                    : "no browser connected for " + std::to_string(wait.count()) + " s");
  });
}

void Supervisor::client_connected(std::int64_t id) {
  Session* session = table_.by_id(id);
  if (session == nullptr) return;
  Runtime& rt = runtime(id);
  ++rt.clients;
  rt.ever_connected = true;
  rt.idle.cancel();
}

void Supervisor::client_disconnected(std::int64_t id) {
  Session* session = table_.by_id(id);
  if (session == nullptr) return;
  Runtime& rt = runtime(id);
  if (rt.clients > 0) --rt.clients;
  if (rt.clients == 0 && is_live(session->state) && session->state != SessionState::kEnding) {
    arm_idle_timer(*session);
  }
}

void Supervisor::picture_delivered(std::int64_t id) {
  Session* session = table_.by_id(id);
  if (session == nullptr || session->spent_at || !is_live(session->state)) return;
  session->spent_at = std::chrono::system_clock::now();
  save(*session);
  log_session(*session, "link spent: the first picture reached the participant's browser");
}

bool Supervisor::end_by_admin(std::int64_t id) {
  Session* session = table_.by_id(id);
  if (session == nullptr || session->state == SessionState::kEnding) return false;
  begin_end(*session, SessionState::kEnded, "ended by an administrator");
  return true;
}

void Supervisor::shutdown(std::function<void()> done) {
  shutting_down_ = true;
  on_all_gone_ = std::move(done);
  for (Session* session : table_.all()) begin_end(*session, SessionState::kShutdown, "the manager stopped");
  notify_if_all_gone();
}

}  // namespace rfbsim::manager
