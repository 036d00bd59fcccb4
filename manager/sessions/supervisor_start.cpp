// SPDX-License-Identifier: GPL-2.0-or-later
// Starting a session: the admission rule, its row, the launch plan, the process on the launcher's thread,
// and what the launch came to.
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

#include "rfbsim/log.hpp"
#include "sessions/launch_plan.hpp"
#include "sessions/process_launcher.hpp"
#include "record/digest.hpp"
#include "sessions/session_process.hpp"
#include "sessions/session_views.hpp"
#include "admission/tokens.hpp"
#include "x11_display.hpp"
#include "sessions/supervisor_runtime.hpp"

namespace rfbsim::manager {

namespace {

using SteadyClock = std::chrono::steady_clock;
namespace asio = boost::asio;

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

}  // namespace

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

  // A watcher's source is chosen now, on this thread, and their session enters the table and the write queue
  // below before the next /start is looked at: two watchers at once never take one place.
  std::optional<Session> source;
  if (request.condition == "video") {
    try {
      YokeChoice choice = choose_source(request);
      if (!choice.source) {
        // Rate-limited: a participant can ask again and again.
        rfbsim::log::limited(rfbsim::log::Level::kInfo, "no-recording", "manager", "uid %s: no recording to show (%s)",
                             request.uid.c_str(), choice.why_none.c_str());
        outcome.kind = StartOutcome::Kind::kNoRecording;
        outcome.message = choice.why_none;
        outcome.uid = request.uid;
        reply(outcome);
        return;
      }
      source = std::move(choice.source);
    } catch (const std::exception& error) {
      outcome.message = std::string("the session index cannot be read: ") + error.what();
      reply(outcome);
      return;
    }
  }

  Session session;
  session.uid = request.uid;
  session.token = new_session_token();
  session.scenario = request.scenario;
  // A watcher's session is the recording's world: its seed is the source's (for the record; sim_rfb reads it
  // from the recording).
  session.seed = source ? source->seed : request.seed.value_or(new_seed());
  if (source) {
    session.condition = "video";
    session.yoked_to = source->id;
    session.yoked_to_uid_hash = sim::hash_uid(address_key(), source->uid);
  }
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
  if (!source) {  // a replayed robot is driven by nobody
    const SessionRos ros = session_ros(config_, request, session.id);
    session.ros_namespace = ros.ros_namespace;
    session.robot_control = ros.robot_control;
  }

  LaunchContext context;
  context.seed = session.seed;
  if (source) {
    context.replay_source = source->data_path;
    context.yoked_to = source->id;
  }
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

  // The slot is taken from here on, while the row is written and then the process starts on the launcher's
  // thread (pid -1 until then). The row goes in first, so that every later change is an update of it; a session
  // the index cannot take cannot be recorded and never runs (launch_recorded).
  Session& kept = table_.add(std::move(session));
  auto& rt = *runtimes_.emplace(kept.id, std::make_unique<Runtime>(io_)).first->second;
  rt.started = SteadyClock::now();
  const std::int64_t id = kept.id;
  ++launches_in_flight_;  // from here: a start whose pid the table lacks yet
  insert_row(kept, [this, id, job = std::move(job), reply = std::move(reply)](const std::string& error) mutable {
    launch_recorded(id, std::move(job), error, std::move(reply));
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
}

void Supervisor::launch_recorded(std::int64_t id, LaunchJob job, const std::string& insert_error, StartReply reply) {
  Session* session = table_.by_id(id);
  if (insert_error.empty() && session != nullptr && session->state != SessionState::kEnding) {
    launcher_->launch(std::move(job), [this, id, reply = std::move(reply)](LaunchResult result) mutable {
      asio::post(io_, [this, id, result = std::move(result), reply = std::move(reply)]() mutable {
        launched(id, std::move(result), std::move(reply));
      });
    });
    return;
  }
  // Never launched: the index refused the row (it is kept and written again with the outcome below), or the
  // session was ended while its row was written (shutdown, an administrator, the start deadline).
  LaunchResult never;
  never.error = !insert_error.empty() ? "cannot record the session, so it was not started: " + insert_error
                                      : "ended before it started";
  launched(id, std::move(never), [this, reply = std::move(reply), refused = !insert_error.empty()](
                                     const StartOutcome& outcome) {
    if (!refused) return reply(outcome);
    StartOutcome cannot_record = outcome;
    cannot_record.kind = StartOutcome::Kind::kCannotRecord;
    reply(cannot_record);
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

}  // namespace rfbsim::manager
