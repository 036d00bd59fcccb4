// SPDX-License-Identifier: GPL-2.0-or-later
// Session lives on the I/O thread: processes, readiness, timers, reaping, the index (its writes and the
// processes' starts are queued for threads of their own).
#include "sessions/supervisor.hpp"

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
#include <variant>

#include "contract/ready_line.hpp"
#include "sessions/launch_plan.hpp"
#include "sessions/process_launcher.hpp"
#include "record/digest.hpp"
#include "sessions/session_process.hpp"
#include "sessions/session_views.hpp"
#include "admission/tokens.hpp"
#include "x11_display.hpp"

namespace rfbsim::manager {

namespace {

using SteadyClock = std::chrono::steady_clock;
namespace asio = boost::asio;

// How often a kRfb session's port is tried until it takes a connection.
constexpr auto kPortPollInterval = std::chrono::milliseconds(20);

// The longest line the program's pipe may carry ("ready PORT", "outcome ...", "stream ..." lines are all far
// shorter): more without a newline is nonsense, and the pipe is not listened to any more.
constexpr std::size_t kMaxPipeLine = 256;

std::uint64_t cpu_limit_seconds(const ManagerConfig& config) {
  if (config.limits.cpu_time_factor <= 0) return 0;
  const double seconds = static_cast<double>(config.max_duration.count()) * config.limits.cpu_time_factor +
                         static_cast<double>(config.limits.cpu_slack.count()) +
                         static_cast<double>(config.stop_grace.count());
  return static_cast<std::uint64_t>(seconds);
}

// The key participants' addresses are hashed with: RFBSIM_ADDRESS_KEY, which main() sets when the study did
// not, so that the sessions (which inherit it) hash alike in events.jsonl.
const std::string& address_key() {
  static const std::string key = sim::address_hash_key();
  return key;
}

// A free loopback port for a program that must be told its port (kRfb). The port is free when we look;
// the program binds it a moment later, so a clash is possible but unlikely, and ends as a failed start.
int pick_free_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return 0;
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t length = sizeof address;
  int port = 0;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) == 0 &&
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length) == 0) {
    port = ntohs(address.sin_port);
  }
  ::close(fd);
  return port;
}

// A private folder for the sessions' unix sockets: mode 0700 from mkdtemp, so that only the manager's user can
// even reach the sockets (which sim_rfb also makes 0600). Short, under the temporary directory, because a
// socket path must fit in 108 bytes; "" (TCP ports instead) when that cannot be had.
std::string make_socket_dir() {
  std::error_code ec;
  std::string pattern = (std::filesystem::temp_directory_path(ec) / "rfbsim-manager-XXXXXX").string();
  if (ec || pattern.size() > 80) pattern = "/tmp/rfbsim-manager-XXXXXX";
  if (::mkdtemp(pattern.data()) == nullptr) {
    std::fprintf(stderr, "[manager] cannot make a folder for session sockets (%s); sessions use loopback ports\n",
                 std::strerror(errno));
    return "";
  }
  return pattern;
}

void log_session(const Session& session, const std::string& text) {
  std::fprintf(stderr, "[manager] session %lld (uid %s): %s\n", static_cast<long long>(session.id),
               session.uid.c_str(), text.c_str());
}

}  // namespace

// Per live session: its timers and its readiness channel.
struct Supervisor::Runtime {
  explicit Runtime(asio::io_context& io)
      : expiry(io), idle(io), stop(io), start_deadline(io), poll(io), ready_pipe(io), probe(io) {}
  asio::steady_timer expiry, idle, stop, start_deadline, poll;
  asio::posix::stream_descriptor ready_pipe;
  asio::ip::tcp::socket probe;  // kRfb: tries the port until it answers
  std::array<char, 256> buffer{};
  std::string ready_text;
  bool bad_stream_logged = false;  // a bad stream line is logged once per session, not every second
  int clients = 0;
  bool ever_connected = false;  // a participant's browser connected at least once
  int x11_display = -1;         // kX11: the display rfbsim_x11_session reported, cleaned after a SIGKILL
  SteadyClock::time_point started;
};

struct Supervisor::ChildWatch {
  explicit ChildWatch(asio::io_context& io) : signals(io, SIGCHLD) {}
  asio::signal_set signals;
};

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
    socket_dir_ = make_socket_dir();
    // An x11 session's RFB socket and cookie have nowhere else to go that only the manager's user can reach.
    if (socket_dir_.empty() && config_.session_kind == SessionKind::kX11) {
      throw std::runtime_error("session_kind x11 needs a private folder for the sessions' sockets and cookies");
    }
  }
  next_id_ = index_.max_id() + 1;
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
  if (socket_dir_.empty()) return;
  std::error_code ignored;
  std::filesystem::remove_all(socket_dir_, ignored);
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
  unsaved_[session.id] = {sequence, session};
  auto done = [this, id = session.id, sequence, committed = std::move(committed)](const std::string& error) {
    asio::post(io_, [this, id, sequence, error, committed] {
      const auto it = unsaved_.find(id);
      if (it != unsaved_.end() && it->second.first == sequence) unsaved_.erase(it);
      if (!error.empty()) std::fprintf(stderr, "[manager] session %lld: %s\n", static_cast<long long>(id), error.c_str());
      if (committed) committed(error);
    });
  };
  if (insert) {
    writer_->insert(session, std::move(done));
  } else {
    writer_->update(session, std::move(done));
  }
}

std::optional<Session> Supervisor::latest_for_uid(const std::string& uid) {
  std::optional<Session> latest = index_.latest_for_uid(uid);
  for (const auto& [id, queued] : unsaved_) {
    if (queued.second.uid == uid && (!latest || id >= latest->id)) latest = queued.second;
  }
  return latest;
}

bool Supervisor::has_session_for_uid(const std::string& uid) {
  return table_.by_uid(uid) != nullptr || latest_for_uid(uid).has_value();
}

int Supervisor::recover_interrupted() {
  std::vector<Session> left;
  try {
    left = index_.live_sessions(config_.host_id);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "[manager] cannot read the index: %s\n", error.what());
    return 0;
  }
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
    save(session, copy_after_commit(session));
    ++ended_counts_[SessionState::kInterrupted];
  }
  return static_cast<int>(left.size());
}

void Supervisor::start(const StartRequest& request, const std::string& address, const std::string& participant,
                       StartReply reply) {
  StartOutcome outcome;
  Session* live = table_.by_uid(request.uid);
  if (live != nullptr && live->state == SessionState::kEnding) {
    outcome.kind = StartOutcome::Kind::kPreviousEnding;  // a few seconds from gone: the page retries here
    reply(outcome);
    return;
  }
  std::optional<SessionState> last;
  if (live == nullptr) {
    try {
      if (const auto latest = latest_for_uid(request.uid)) last = latest->state;
    } catch (const std::exception& error) {
      outcome.message = std::string("the session index cannot be read: ") + error.what();
      reply(outcome);
      return;
    }
  }
  switch (admit(live != nullptr, last, config_.allow_repeat, table_.full() || shutting_down_ || draining_)) {
    case Admission::kJoinLive:
      outcome.kind = StartOutcome::Kind::kJoined;
      outcome.token = live->token;
      reply(outcome);
      return;
    case Admission::kAlreadyCompleted:
      outcome.kind = StartOutcome::Kind::kCompleted;
      reply(outcome);
      return;
    case Admission::kBusy:
      outcome.kind = StartOutcome::Kind::kBusy;
      reply(outcome);
      return;
    case Admission::kStartNew:
      break;
  }
  // Made-up uids from one address would each hold a slot until the idle timeout; a participant has one
  // session at a time, so a few unseen ones from one address is already generous.
  const int unspent_cap = config_.abuse.unspent_sessions_per_address;
  if (unspent_cap > 0 && !address.empty()) {
    int unspent = 0;
    for (Session* other : table_.all()) {
      unspent += other->start_address == address && !other->spent_at && other->state != SessionState::kEnding ? 1 : 0;
    }
    if (unspent >= unspent_cap) {
      outcome.kind = StartOutcome::Kind::kTooManyUnspent;
      reply(outcome);
      return;
    }
  }

  Session session;
  session.uid = request.uid;
  session.token = new_session_token();
  session.scenario = request.scenario;
  session.seed = request.seed.value_or(new_seed());
  session.params_json = parameters_json(request, session.seed);
  session.code_success = request.code_success;
  session.code_timeout = request.code_timeout;
  session.host_id = config_.host_id;
  session.start_address = address;
  session.address_hash = participant.empty() ? std::string() : sim::hash_address(address_key(), participant);
  session.created = std::chrono::system_clock::now();
  // Ids are handed out here, so that the row can be written off this thread; the participant is redirected
  // only once it is committed (below), so a redirect always points at a recorded session.
  session.id = next_id_++;
  const SessionRos ros = session_ros(config_, request, session.id);
  session.ros_namespace = ros.ros_namespace;
  session.robot_control = ros.robot_control;

  LaunchContext context;
  context.seed = session.seed;
  context.session_id = session.id;
  context.data_dir = (std::filesystem::absolute(config_.data_dir) / "sessions" /
                      (std::to_string(session.id) + "-" + session.uid))
                         .string();
  session.data_path = context.data_dir;
  LaunchJob job;
  try {
    if (config_.session_kind == SessionKind::kRfb) {
      context.port = pick_free_port();
      if (context.port == 0) throw std::runtime_error("no free loopback port");
      session.port = context.port;
    } else if (!socket_dir_.empty()) {
      context.unix_socket = socket_dir_ + "/" + std::to_string(session.id) + ".sock";
      session.unix_socket = context.unix_socket;
      if (config_.session_kind == SessionKind::kX11) context.xauthority = x11_xauthority_path(session.id);
    }
    job.folder = context.data_dir;
    SpawnSpec& spec = job.spec;
    spec.program = program_;
    spec.args = session_arguments(config_, request, context);
    spec.working_dir = context.data_dir;
    spec.log_file = context.data_dir + "/session.log";
    spec.ready_pipe = config_.session_kind != SessionKind::kRfb;
    const ProcessLimits limits = session_limits(config_);
    spec.limits.address_space_bytes = limits.address_space_mb * 1024 * 1024;
    spec.limits.open_files = limits.open_files;
    spec.limits.cpu_seconds = cpu_limit_seconds(config_);
  } catch (const std::exception& error) {
    fail_start(std::move(session), error.what(), reply);
    return;
  }

  // The slot is taken from here on, while the process starts on the launcher's thread (pid -1 until then). The
  // row goes in now, so that every later change is an update of it; if the index cannot take it, the session
  // cannot be recorded and must not run.
  Session& kept = table_.add(std::move(session));
  auto& rt = *runtimes_.emplace(kept.id, std::make_unique<Runtime>(io_)).first->second;
  rt.started = SteadyClock::now();
  const std::int64_t id = kept.id;
  insert_row(kept, [this, id](const std::string& error) {
    Session* s = table_.by_id(id);
    if (!error.empty() && s != nullptr) begin_end(*s, SessionState::kFailed, error);
  });

  rt.expiry.expires_after(config_.max_duration);
  rt.expiry.async_wait([this, id](const boost::system::error_code& ec) {
    Session* s = table_.by_id(id);
    if (ec || s == nullptr) return;
    begin_end(*s, SessionState::kExpired, "reached the maximum duration of " +
                                              std::to_string(config_.max_duration.count()) + " s");
  });
  rt.start_deadline.expires_after(config_.start_timeout);
  rt.start_deadline.async_wait([this, id](const boost::system::error_code& ec) {
    Session* s = table_.by_id(id);
    if (ec || s == nullptr || s->state != SessionState::kStarting) return;
    begin_end(*s, SessionState::kFailed, "not ready after " + std::to_string(config_.start_timeout.count()) + " s");
  });
  arm_idle_timer(kept);
  ++launches_in_flight_;
  launcher_->launch(std::move(job), [this, id, reply = std::move(reply)](LaunchResult result) mutable {
    asio::post(io_, [this, id, result = std::move(result), reply = std::move(reply)]() mutable {
      launched(id, std::move(result), std::move(reply));
    });
  });
}

void Supervisor::fail_start(Session session, const std::string& error, const StartReply& reply) {
  session.state = SessionState::kFailed;
  session.detail = error;
  session.ended_at = std::chrono::system_clock::now();
  insert_row(session, nullptr);
  ++ended_counts_[SessionState::kFailed];
  log_session(session, "could not start: " + error);
  metrics_.count_rejection(Rejection::kStartFailed);
  StartOutcome outcome;
  outcome.message = error;
  reply(outcome);
}

void Supervisor::launched(std::int64_t id, LaunchResult result, StartReply reply) {
  --launches_in_flight_;
  Session* session = table_.by_id(id);
  if (session == nullptr) {  // cannot happen: a session leaves the table only once it has a result
    if (result.process.pid > 0) signal_process_group(result.process.pid, SIGKILL);
    StartOutcome lost;
    lost.message = "the session ended as it started";
    reply(lost);
    return;
  }
  if (!result.error.empty()) {
    // Failed, also when an administrator or shutdown had begun ending it meanwhile: that it never ran is the
    // truer record.
    session->state = SessionState::kFailed;
    session->detail = result.error;
    session->ended_at = std::chrono::system_clock::now();
    save(*session);
    ++ended_counts_[SessionState::kFailed];
    log_session(*session, "could not start: " + result.error);
    metrics_.count_rejection(Rejection::kStartFailed);
    if (listener_ != nullptr) listener_->session_closing(*session);
    runtimes_.erase(id);
    table_.remove(id);
    StartOutcome failed;
    failed.message = result.error;
    reply(failed);
    reap_children();  // children that exited while this start was in flight were left for now
    notify_if_all_gone();
    return;
  }
  session->pid = result.process.pid;
  session->process_start = result.process.start_ticks;
  metrics_.count_start();
  const char* what = config_.session_kind == SessionKind::kSimRfb ? "sim_rfb"
                     : config_.session_kind == SessionKind::kX11  ? "rfbsim_x11_session"
                                                                  : "program";
  log_session(*session, std::string("started ") + what + " as pid " + std::to_string(session->pid) + " in " + session->data_path);
  Runtime& rt = runtime(id);
  if (result.process.ready_fd >= 0) rt.ready_pipe.assign(result.process.ready_fd);
  if (session->state == SessionState::kEnding) {
    // Ended while it started (shutdown, an administrator, the start deadline, the index): now there is a
    // process to stop, with the whole grace period from now.
    stop_process(*session);
  } else if (result.process.ready_fd >= 0) {
    watch_ready_pipe(*session);
  } else {
    poll_rfb_port(id);
  }
  // The redirect once the row with the process in it is committed (after the first row, the writer keeps order).
  save(*session, [this, id, token = session->token, reply = std::move(reply)](const std::string& error) {
    StartOutcome outcome;
    const Session* s = table_.by_id(id);
    if (error.empty() && s != nullptr && is_live(s->state) && s->state != SessionState::kEnding) {
      outcome.kind = StartOutcome::Kind::kStarted;
      outcome.token = token;
    } else {
      outcome.message = error.empty() ? "the session ended as it started" : error;
      if (Session* live = table_.by_id(id); live != nullptr && !error.empty()) {
        begin_end(*live, SessionState::kFailed, error);
      }
    }
    reply(outcome);
  });
  reap_children();  // it may have exited already, its SIGCHLD handled before its pid was known here
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
    session.detail = "the program stopped by itself (" + session.exit_status + ")" +
                     (last_line.empty() ? "" : ": " + last_line);
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
    std::fprintf(stderr, "[manager] display :%d: its X server is still running; its lock file is left\n", display);
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

std::optional<Session> Supervisor::find(const std::string& token) {
  if (Session* live = table_.by_token(token)) return *live;
  for (const auto& [id, queued] : unsaved_) {
    if (queued.second.token == token) return queued.second;
  }
  try {
    return index_.find_by_token(token);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "[manager] cannot read the index: %s\n", error.what());
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
  // Rows still queued for the writer: their newest version replaces the index's, or joins the list.
  for (const auto& [id, queued] : unsaved_) {
    const auto row = std::find_if(rows.begin(), rows.end(), [id = id](const Session& r) { return r.id == id; });
    if (row != rows.end()) {
      *row = queued.second;
    } else {
      rows.push_back(queued.second);
    }
  }
  std::sort(rows.begin(), rows.end(), [](const Session& a, const Session& b) { return a.id > b.id; });
  if (rows.size() > static_cast<std::size_t>(std::max(limit, 0))) rows.resize(static_cast<std::size_t>(std::max(limit, 0)));
  return rows;
}

}  // namespace rfbsim::manager
