// SPDX-License-Identifier: GPL-2.0-or-later
// Session lives on the I/O thread: construction, the index's reads and queued writes, the program's
// readiness (its pipe, or its port), and lookups. Starting is in supervisor_start.cpp, ending in
// supervisor_ending.cpp.
#include "sessions/supervisor.hpp"

#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <charconv>
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
#include <variant>

#include "contract/ready_line.hpp"
#include "sessions/launch_plan.hpp"
#include "sessions/process_launcher.hpp"
#include "record/digest.hpp"
#include "rfbsim/log.hpp"
#include "sessions/session_process.hpp"
#include "sessions/session_views.hpp"
#include "admission/tokens.hpp"
#include "x11_display.hpp"
#include "rfbsim/log.hpp"
#include "sessions/socket_folder.hpp"
#include "sessions/supervisor_runtime.hpp"

namespace rfbsim::manager {

namespace {

using SteadyClock = std::chrono::steady_clock;
namespace asio = boost::asio;

// How often a kRfb session's port is tried until it takes a connection.
constexpr auto kPortPollInterval = std::chrono::milliseconds(20);

// The longest line the program's pipe may carry ("ready PORT", "outcome ...", "stream ..." lines are all far
// shorter): more without a newline is nonsense, and the pipe is not listened to any more.
constexpr std::size_t kMaxPipeLine = 256;

// The longest pause between tries of a write the index refused: space freed on a full disk is taken up soon.
constexpr std::chrono::seconds kMaxIndexRetry{30};

// The highest id a session folder under `sessions_dir` carries ("<id>-<uid>"), 0 when none: a session whose row
// never reached the index (a full disk) may still have left its folder, and its id must not name a second one.
std::int64_t highest_folder_id(const std::filesystem::path& sessions_dir) {
  std::int64_t highest = 0;
  std::error_code ec;
  for (std::filesystem::directory_iterator it(sessions_dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    const std::size_t dash = name.find('-');
    std::int64_t id = 0;
    const auto [ptr, error] = std::from_chars(name.data(), name.data() + (dash == std::string::npos ? 0 : dash), id);
    if (dash != std::string::npos && dash > 0 && error == std::errc() && ptr == name.data() + dash) {
      highest = std::max(highest, id);
    }
  }
  return highest;
}

}  // namespace

Supervisor::Supervisor(asio::io_context& io, const ManagerConfig& config, std::string program, SessionIndex& index,
                       Metrics& metrics)
    : io_(io),
      config_(config),
      program_(std::move(program)),
      index_(index),
      metrics_(metrics),
      table_(config.max_sessions),
      child_watch_(std::make_unique<ChildWatch>(io)),
      writer_(std::make_unique<IndexWriter>(index.path())),
      launcher_(std::make_unique<ProcessLauncher>()) {
  // x11 sessions always use it: their RFB socket and Xauthority must be the manager's user's alone.
  if ((config_.session_kind == SessionKind::kSimRfb && config_.session_socket == "unix") ||
      config_.session_kind == SessionKind::kX11) {
    // One per data directory, found again after a kill -9 (socket_folder.hpp).
    socket_folder_ = std::make_unique<SocketFolder>(config_.data_dir);
    socket_dir_ = socket_folder_->path();
    if (!socket_folder_->note().empty()) rfbsim::log::info("manager", "%s", socket_folder_->note().c_str());
    if (socket_dir_.empty()) rfbsim::log::warn("manager", "sessions use loopback ports instead of unix sockets");
    // An x11 session's RFB socket and cookie have nowhere else to go that only the manager's user can reach.
    if (socket_dir_.empty() && config_.session_kind == SessionKind::kX11) {
      throw std::runtime_error("session_kind x11 needs a private folder for the sessions' sockets and cookies");
    }
  }
  next_id_ = std::max(index_.max_id(), highest_folder_id(std::filesystem::absolute(config_.data_dir) / "sessions")) + 1;
  index_retry_ = std::make_unique<asio::steady_timer>(io_);
  for (const auto& [state, count] : index_.count_by_state()) {
    if (!is_live(state)) ended_counts_[state] = count;
  }
  wait_for_children();
  if (!config_.after_session_command.empty()) {
    CopierSettings copy;
    copy.command = config_.after_session_command;
    copy.retries = config_.after_session_retries;
    copy.timeout = config_.after_session_timeout;
    copy.kill_grace = config_.stop_grace;
    copy.index_path = index_.path();
    copy.log_dir = (std::filesystem::absolute(config_.data_dir) / "copy-logs").string();
    copier_ = std::make_unique<SessionCopier>(std::move(copy));
    // Copies the previous manager left unfinished (it stopped or died meanwhile) are tried again.
    for (const Session& session : index_.pending_copies(config_.host_id)) copier_->enqueue(copy_job_for(session));
  }
}

Supervisor::~Supervisor() {
  launcher_.reset();  // starts nothing more
  writer_.reset();    // writes what is queued
  if (const std::size_t behind = unrecorded(); behind > 0) {
    rfbsim::log::error("manager",
                       "the index could not take the last changes of %zu session(s) (a full disk?): it is behind; "
                       "the next start marks sessions it still shows as live interrupted",
                       behind);
  }
  socket_folder_.reset();  // removes the folder and what is left in it
}

void Supervisor::wait_for_children() {
  child_watch_->signals.async_wait([this](const boost::system::error_code& ec, int) {
    if (ec) return;
    reap_children();
    wait_for_children();
  });
}

Supervisor::Runtime& Supervisor::runtime(std::int64_t id) { return *runtimes_.at(id); }

void Supervisor::save(const Session& session, std::function<void(const std::string&)> committed) {
  queue_write(false, session, std::move(committed));
}

void Supervisor::insert_row(const Session& session, std::function<void(const std::string&)> committed) {
  queue_write(true, session, std::move(committed));
}

void Supervisor::queue_write(bool insert, const Session& session, std::function<void(const std::string&)> committed) {
  // The table (or the caller) has the newest version now; the index gets it in order, off this thread.
  const std::uint64_t sequence = ++write_sequence_;
  unsaved_[session.id] = {sequence, session, false};
  auto done = [this, id = session.id, sequence, committed = std::move(committed)](const std::string& error) {
    asio::post(io_, [this, id, sequence, error, committed] {
      const auto it = unsaved_.find(id);
      const bool newest = it != unsaved_.end() && it->second.sequence == sequence;
      if (error.empty()) {
        if (newest) unsaved_.erase(it);
      } else {
        // Kept, served as the truth meanwhile, and written again until the index takes it.
        metrics_.count_index_write_error();
        rfbsim::log::limited(rfbsim::log::Level::kError, "index-write", "manager",
                             "session %lld: %s (kept, and written again once the index takes it)",
                             static_cast<long long>(id), error.c_str());
        if (newest) it->second.refused = true;
        schedule_index_retry();
      }
      if (committed) committed(error);
    });
  };
  if (insert) {
    writer_->insert(session, std::move(done));
  } else {
    writer_->update(session, std::move(done));
  }
}

void Supervisor::schedule_index_retry() {
  if (index_retry_->expiry() > asio::steady_timer::clock_type::now()) return;  // a retry is already due
  index_retry_->expires_after(index_retry_delay_);
  index_retry_->async_wait([this](const boost::system::error_code& ec) {
    if (ec) return;
    std::vector<Session> again;
    for (const auto& [id, unsaved] : unsaved_) {
      if (unsaved.refused) again.push_back(unsaved.session);
    }
    if (again.empty()) {
      index_retry_delay_ = std::chrono::seconds(1);
      return;
    }
    index_retry_delay_ = std::min(index_retry_delay_ * 2, kMaxIndexRetry);
    // An update writes the whole row where the index has none yet, so a session whose insert failed is recorded.
    for (const Session& session : again) {
      save(session, [this, id = session.id](const std::string& error) {
        if (error.empty() && unsaved_.count(id) == 0) {
          index_retry_delay_ = std::chrono::seconds(1);
          rfbsim::log::limited(rfbsim::log::Level::kInfo, "index-caught-up", "manager",
                               "session %lld: the index took the change it had refused", static_cast<long long>(id));
        }
      });
    }
  });
}

std::size_t Supervisor::unrecorded() const {
  std::size_t count = 0;
  for (const auto& [id, unsaved] : unsaved_) count += unsaved.refused ? 1 : 0;
  return count;
}

std::optional<Session> Supervisor::latest_for_uid(const std::string& uid) {
  std::optional<Session> latest = index_.latest_for_uid(uid);
  for (const auto& [id, queued] : unsaved_) {
    if (queued.session.uid == uid && (!latest || id >= latest->id)) latest = queued.session;
  }
  return latest;
}

void Supervisor::lay_unsaved_over(std::vector<Session>& rows) const {
  for (const auto& [id, queued] : unsaved_) {
    const auto row = std::find_if(rows.begin(), rows.end(), [id = id](const Session& r) { return r.id == id; });
    if (row != rows.end()) {
      const int watchers = row->watchers;  // the index's count: the table never keeps one
      *row = queued.session;
      row->watchers = watchers;
    } else {
      rows.push_back(queued.session);
    }
  }
}

YokeChoice Supervisor::choose_source(const StartRequest& request) {
  std::vector<Session> rows = index_.yoking_rows(config_.host_id);
  lay_unsaved_over(rows);  // a watcher started a moment ago is only queued, and must count
  YokeRequest yoke;
  yoke.watcher_uid = request.uid;
  yoke.scenario = request.scenario;
  yoke.pinned_uid = request.yoke_uid;
  yoke.by_participant = config_.yoke_policy == "by_participant";
  yoke.max_viewers = config_.yoke_max_viewers;
  yoke.host_id = config_.host_id;
  // A folder moved or deleted by hand (or by an after-session command) cannot be shown.
  return choose_yoke_source(rows, yoke, [](const Session& source) {
    std::error_code ec;
    return std::filesystem::is_regular_file(std::filesystem::path(source.data_path) / "session.json", ec);
  });
}

bool Supervisor::has_session_for_uid(const std::string& uid) {
  return table_.by_uid(uid) != nullptr || latest_for_uid(uid).has_value();
}

Supervisor::Recovery Supervisor::recover_interrupted() {
  Recovery recovery;
  std::vector<Session> left;
  try {
    left = index_.live_sessions(config_.host_id);
  } catch (const std::exception& error) {
    recovery.error = std::string("cannot read the index: ") + error.what();
    return recovery;
  }
  recovery.found = static_cast<int>(left.size());
  for (Session& session : left) {
    // The group is ours if its leader is the very process we started (same start time), or if no process
    // has that id any more (then only members of our old group can carry it). A reused id is left alone.
    const auto start = process_start_ticks(session.pid);
    const bool ours = session.pid > 1 && (!start || *start == session.process_start);
    if (ours && process_group_alive(session.pid)) {
      signal_process_group(session.pid, SIGKILL);
      for (int i = 0; i < 100 && process_group_alive(session.pid); ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));  // start-up only: nothing else runs yet
      }
      log_session(session, "its process was still running after a manager restart; killed");
    }
    session.state = SessionState::kInterrupted;
    session.detail = "the manager stopped unexpectedly while the session ran";
    session.ended_at = std::chrono::system_clock::now();
    const auto copy = copy_after_commit(session);
    ++ended_counts_[SessionState::kInterrupted];
    // Written here and now, through the I/O thread's own connection (nothing else runs yet), so that what the
    // start-up says it marked is what the index holds. A refusal joins the other writes to try again.
    const std::string error = record_session(index_, session, false);
    if (error.empty()) {
      ++recovery.recorded;
      if (copy) copy("");
      continue;
    }
    recovery.error = error;
    metrics_.count_index_write_error();
    unsaved_[session.id] = {++write_sequence_, session, true};
    schedule_index_retry();
  }
  return recovery;
}

void Supervisor::notify_if_all_gone() {
  if (shutting_down_ && table_.size() == 0 && on_all_gone_) {
    auto done = std::move(on_all_gone_);
    on_all_gone_ = nullptr;
    asio::post(io_, done);
  }
}

void Supervisor::watch_ready_pipe(Session& session) {
  const std::int64_t id = session.id;
  Runtime& rt = runtime(id);
  rt.ready_pipe.async_read_some(asio::buffer(rt.buffer), [this, id](const boost::system::error_code& ec,
                                                                    std::size_t bytes) {
    Session* s = table_.by_id(id);
    if (s == nullptr || ec) return;  // closed: the exit (or the start timeout) tells the rest
    Runtime& r = runtime(id);
    r.ready_text.append(r.buffer.data(), bytes);
    // Whole lines: the first says ready, later ones report the task's outcome.
    for (std::size_t newline = r.ready_text.find('\n'); newline != std::string::npos;
         newline = r.ready_text.find('\n')) {
      const std::string line = r.ready_text.substr(0, newline);
      r.ready_text.erase(0, newline + 1);
      if (!take_pipe_line(*s, line)) return;
    }
    if (r.ready_text.size() > kMaxPipeLine) {
      if (s->state == SessionState::kStarting) {
        begin_end(*s, SessionState::kFailed, "the program's ready line is not 'ready PORT'");
      }
      return;  // a running program that writes nonsense is not listened to any more
    }
    watch_ready_pipe(*s);
  });
}

bool Supervisor::take_pipe_line(Session& session, const std::string& line) {
  // The contract's parser (contract/ready_line.hpp): the same grammar sim_rfb and rfbsim_x11_session write with.
  const contract::ReadyLineParse parsed = contract::parse_ready_line(line);
  const contract::ReadyLine* value = parsed.line ? &*parsed.line : nullptr;
  if (session.state == SessionState::kStarting) {
    // On a unix socket: "ready unix PATH", and only the path it was given.
    if (!session.unix_socket.empty()) {
      const auto* ready = value != nullptr ? std::get_if<contract::ReadyUnix>(value) : nullptr;
      if (ready == nullptr || ready->path != session.unix_socket) {
        begin_end(session, SessionState::kFailed, "the program's ready line is not 'ready unix " + session.unix_socket + "'");
        return false;
      }
      mark_ready(session, 0);
      return true;
    }
    const auto* ready = value != nullptr ? std::get_if<contract::ReadyPort>(value) : nullptr;
    if (ready == nullptr) {
      begin_end(session, SessionState::kFailed, "the program's ready line is not 'ready PORT'");
      return false;
    }
    mark_ready(session, ready->port);
    return true;
  }
  // The participant's stream, about once a second while someone watches: the latest is kept for the admin page,
  // the API and the metrics (not the index: it is a reading, not the session's record).
  if (contract::is_stream_line(line)) {
    if (const auto* stream = value != nullptr ? std::get_if<StreamReport>(value) : nullptr) {
      session.stream = stream->clients > 0 ? std::optional<StreamReport>(*stream) : std::nullopt;
    } else if (!runtime(session.id).bad_stream_logged) {
      runtime(session.id).bad_stream_logged = true;
      log_session(session, "ignored a stream line (" + parsed.error + "), and will not log another: '" +
                               line.substr(0, 96) + "'");
    }
    return true;
  }
  // rfbsim_x11_session names the display it got, so that one whose X server was SIGKILLed is cleaned after it.
  const auto* display = value != nullptr ? std::get_if<contract::X11Display>(value) : nullptr;
  if (display != nullptr && config_.session_kind == SessionKind::kX11 && runtime(session.id).x11_display < 0) {
    runtime(session.id).x11_display = display->display;
    log_session(session, "its program runs on display :" + std::to_string(display->display));
    return true;
  }
  const auto* outcome = value != nullptr ? std::get_if<contract::TaskOutcomeLine>(value) : nullptr;
  if (outcome != nullptr && session.outcome.empty()) {
    session.outcome = contract::task_end_name(outcome->end);
    save(session);
    log_session(session, "task outcome: " + session.outcome);
    return true;
  }
  // The program can no longer write the session's data (a full disk): recorded, and by the config's policy
  // the participant carries on or the session ends.
  const auto* incomplete = value != nullptr ? std::get_if<contract::DataIncomplete>(value) : nullptr;
  if (incomplete != nullptr && session.data_incomplete.empty()) {
    session.data_incomplete = incomplete->reason;
    save(session);
    log_session(session, "its data is incomplete: " + session.data_incomplete);
    if (config_.on_data_incomplete == DataFailurePolicy::kEnd) {
      begin_end(session, SessionState::kEnded, "the session's data could not be written: " + session.data_incomplete);
      return false;
    }
    return true;
  }
  log_session(session, "ignored a line from the program: '" + line.substr(0, 64) + "'");
  return true;
}

void Supervisor::poll_rfb_port(std::int64_t id) {
  Session* session = table_.by_id(id);
  if (session == nullptr || session->state != SessionState::kStarting) return;
  Runtime& rt = runtime(id);
  const asio::ip::tcp::endpoint endpoint(asio::ip::address_v4::loopback(), static_cast<unsigned short>(session->port));
  rt.probe = asio::ip::tcp::socket(io_);
  rt.probe.async_connect(endpoint, [this, id](const boost::system::error_code& ec) {
    Session* s = table_.by_id(id);
    if (s == nullptr || s->state != SessionState::kStarting) return;
    Runtime& r = runtime(id);
    boost::system::error_code ignored;
    r.probe.close(ignored);
    if (!ec) {
      mark_ready(*s, s->port);
      return;
    }
    r.poll.expires_after(kPortPollInterval);
    r.poll.async_wait([this, id](const boost::system::error_code& wait_ec) {
      if (!wait_ec) poll_rfb_port(id);
    });
  });
}

void Supervisor::mark_ready(Session& session, int port) {
  Runtime& rt = runtime(session.id);
  rt.start_deadline.cancel();
  session.state = SessionState::kRunning;
  session.port = port;
  session.ready_at = std::chrono::system_clock::now();
  save(session);
  const double seconds = std::chrono::duration<double>(SteadyClock::now() - rt.started).count();
  metrics_.observe_startup(seconds);
  char text[96];
  std::snprintf(text, sizeof text, "ready after %.3f s on ", seconds);
  log_session(session, text + (session.unix_socket.empty() ? "port " + std::to_string(port) : session.unix_socket));
  if (listener_ != nullptr) listener_->session_ready(session);
}

std::optional<Session> Supervisor::find(const std::string& token) {
  if (Session* live = table_.by_token(token)) return *live;
  for (const auto& [id, queued] : unsaved_) {
    if (queued.session.token == token) return queued.session;
  }
  try {
    return index_.find_by_token(token);
  } catch (const std::exception& error) {
    rfbsim::log::error("manager", "cannot read the index: %s", error.what());
    return std::nullopt;
  }
}

std::map<SessionState, std::int64_t> Supervisor::counts_by_state() {
  std::map<SessionState, std::int64_t> counts = ended_counts_;
  for (Session* session : table_.all()) ++counts[session->state];
  return counts;
}

std::vector<Session> Supervisor::recent(int limit) {
  std::vector<Session> rows = index_.recent(limit);
  lay_unsaved_over(rows);
  std::sort(rows.begin(), rows.end(), [](const Session& a, const Session& b) { return a.id > b.id; });
  if (rows.size() > static_cast<std::size_t>(std::max(limit, 0))) rows.resize(static_cast<std::size_t>(std::max(limit, 0)));
  return rows;
}

}  // namespace rfbsim::manager
