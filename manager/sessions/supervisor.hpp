// SPDX-License-Identifier: GPL-2.0-or-later
// The Supervisor runs the sessions' lives on the manager's one I/O thread: it starts processes (through the
// ProcessLauncher's thread, so that a fork never stalls the relays), learns when they are ready, ends them at expiry, idle timeout, an administrator's word or shutdown (SIGTERM,
// then SIGKILL after the grace period), reaps them, and writes every change to the index before acting
// on it. All its methods run on the I/O thread.
#pragma once

#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "config/config.hpp"
#include "sessions/index_writer.hpp"
#include "sessions/process_launcher.hpp"
#include "admin/metrics.hpp"
#include "sessions/session_copier.hpp"
#include "sessions/session_index.hpp"
#include "sessions/session_table.hpp"
#include "sessions/yoking.hpp"
#include "admission/start_request.hpp"

namespace rfbsim::manager {

/// What the frontend hears of sessions.
class SessionListener {
 public:
  virtual ~SessionListener() = default;
  /// The session is ready: its port takes connections.
  virtual void session_ready(const Session& session) = 0;
  /// The session is ending or gone (`session.state` says which, and `end_as` why): close its relays.
  virtual void session_closing(const Session& session) = 0;
};

/// The outcome of a /start.
struct StartOutcome {
  /// kTooManyUnspent: the address already started abuse.unspent_sessions_per_address sessions that no
  /// participant has seen yet.
  /// kPreviousEnding: the uid's own session is still ending (seconds from gone); not kBusy, so that nobody
  /// retries on another host, where a second session of the uid would start.
  /// kCannotRecord: the index could not take the new session's row (a full disk), so nothing was started.
  /// kNoRecording: a video-condition link found no session it may show (sessions/yoking.hpp; `message` says why,
  /// for the researcher's log).
  enum class Kind {
    kJoined, kStarted, kBusy, kCompleted, kFailed, kTooManyUnspent, kPreviousEnding, kCannotRecord, kNoRecording
  } kind = Kind::kFailed;
  std::string token;    ///< kJoined, kStarted
  std::string message;  ///< kFailed: why, for the log and the page; kNoRecording: why, for the log only
  std::string uid;      ///< kNoRecording: the link's uid, which the page names to the survey
};

class SocketFolder;  // sessions/socket_folder.hpp

class Supervisor {
 public:
  /// `program` is the resolved session program. Nothing starts until start() is called.
  Supervisor(boost::asio::io_context& io, const ManagerConfig& config, std::string program, SessionIndex& index,
             Metrics& metrics);
  ~Supervisor();
  Supervisor(const Supervisor&) = delete;
  Supervisor& operator=(const Supervisor&) = delete;

  void set_listener(SessionListener* listener) { listener_ = listener; }

  /// What recover_interrupted found and what of it the index took.
  struct Recovery {
    int found = 0;        ///< sessions the index said were live on this host
    int recorded = 0;     ///< of them, marked interrupted in the index now
    std::string error;    ///< why the others were not (they are kept and tried again with the other writes)
  };
  /// After a restart: ends the processes of sessions the index says are live on this host (if they still
  /// run) and marks those sessions interrupted, writing the index at once (nothing else runs yet).
  Recovery recover_interrupted();

  /// Sessions whose newest version the index has not taken yet (a full disk), kept in memory and tried again.
  [[nodiscard]] std::size_t unrecorded() const;

  /// What /start answers with, called on the I/O thread.
  using StartReply = std::function<void(const StartOutcome&)>;
  /// Admits a valid link from client `address` (the limit key): back to the uid's live session, or a new one,
  /// or why not. `participant`: the participant's whole address ("" when unknown), of which a new session's
  /// row records the keyed hash. `reply` is called at once, except for a new session: then once its index row
  /// is committed (on the writer's thread, posted back), so that a redirect always points at a recorded session.
  void start(const StartRequest& request, const std::string& address, const std::string& participant,
             StartReply reply);

  /// Whether this host has any session of `uid`, live or ended, in its table, the index or the writes still
  /// queued: such a uid's /start is this host's to answer, without asking the uid registry. Throws
  /// std::runtime_error when the index cannot be read.
  bool has_session_for_uid(const std::string& uid);

  /// A browser connected to / disconnected from a session (the idle timer counts from the last one gone).
  void client_connected(std::int64_t id);
  void client_disconnected(std::int64_t id);

  /// The session's first picture was delivered to a participant's browser: its link is spent from now on
  /// (recorded once, in the index). A session that ends before this is abandoned, and its uid may start again.
  void picture_delivered(std::int64_t id);

  /// Ends a live session on an administrator's word; false if it is not live.
  bool end_by_admin(std::int64_t id);

  /// Ends every session and calls `done` once all processes are gone (SIGKILL after the grace period).
  void shutdown(std::function<void()> done);

  /// Takes no new participants (true) or takes them again (false): live sessions and their uids' rejoins go
  /// on, and a /start of any other uid is answered kBusy, like a full host, so a balancer may send it elsewhere.
  void set_draining(bool draining) { draining_ = draining; }
  /// Whether set_draining(true) is in force.
  [[nodiscard]] bool draining() const { return draining_; }
  /// Whether shutdown() was called: the sessions are ending and no new one starts.
  [[nodiscard]] bool shutting_down() const { return shutting_down_; }

  /// Live sessions.
  SessionTable& table() { return table_; }
  /// A session by token: live, else from the index.
  std::optional<Session> find(const std::string& token);
  /// The newest `limit` sessions, newest first: the index, with writes still queued taken into account
  /// (throws std::runtime_error on index errors).
  std::vector<Session> recent(int limit);
  /// Sessions by state: live ones from the table, ended ones counted in memory (read from the index once, at
  /// start): /metrics must be cheap.
  std::map<SessionState, std::int64_t> counts_by_state();
  /// Blocks until every queued index write is done (tests and shutdown).
  void flush_index() { writer_->drain(); }

 private:
  struct Runtime;

  void begin_end(Session& session, SessionState end_as, const std::string& detail);
  // SIGTERM to the session's process group, then SIGKILL after the grace period (at once without one).
  void stop_process(Session& session);
  // A start that failed before it had a slot: recorded as failed, and the participant told.
  void fail_start(Session session, const std::string& error, const StartReply& reply);
  // The launcher's result for session `id`, back on the I/O thread: the process joins the session, or the
  // session fails; `reply` answers the /start once the row with the process is committed.
  void launched(std::int64_t id, LaunchResult result, StartReply reply);
  // After shutdown(): calls its `done` once the last session has left the table.
  void notify_if_all_gone();
  void watch_ready_pipe(Session& session);
  // One line from the program's pipe: "ready PORT" while starting, then "outcome completed|timeout".
  // False when the session was failed for it.
  bool take_pipe_line(Session& session, const std::string& line);
  void poll_rfb_port(std::int64_t id);
  void mark_ready(Session& session, int port);
  void reap_children();
  // Reaps `pid` if it has exited (and ends its session); false if it has not.
  bool reap_if_exited(pid_t pid);
  void wait_for_children();
  void process_gone(Session& session, int wait_status);
  void arm_idle_timer(Session& session);
  // Queue a session's newest version (save) or its first row (insert_row) for the writer; `committed` (may be
  // empty) runs on the I/O thread once it is written, with "" or the error.
  void save(const Session& session, std::function<void(const std::string&)> committed = nullptr);
  void insert_row(const Session& session, std::function<void(const std::string&)> committed);
  void queue_write(bool insert, const Session& session, std::function<void(const std::string&)> committed);
  // Writes again, after a pause that doubles up to kMaxIndexRetry, every version the index refused.
  void schedule_index_retry();
  // The launch of a session whose row is committed; a session the index refused, or one ended meanwhile, is
  // never launched and ends here.
  void launch_recorded(std::int64_t id, LaunchJob job, const std::string& insert_error, StartReply reply);
  // The uid's newest session in the index or among writes still queued.
  std::optional<Session> latest_for_uid(const std::string& uid);
  // Rows read from the index with the writes still queued laid over them: each queued version replaces its row
  // (keeping the index's watchers count) or joins the list. Reads must never see an older row than the table.
  void lay_unsaved_over(std::vector<Session>& rows) const;
  // The session a video-condition link shows (sessions/yoking.hpp), from the index with the writes still queued
  // laid over it. Throws std::runtime_error when the index cannot be read.
  YokeChoice choose_source(const StartRequest& request);
  std::string session_log_tail(const Session& session) const;
  // For the save that makes `session`'s folder final: marks its after-session copy 'pending' (in that same row)
  // and returns what queues the copy once the row and manager.json are written; nullptr without a copier or folder.
  std::function<void(const std::string&)> copy_after_commit(Session& session);
  Runtime& runtime(std::int64_t id);
  /// kX11: where session `id`'s Xauthority is written (beside its RFB socket, in the private socket folder).
  std::string x11_xauthority_path(std::int64_t id) const;
  /// Removes the lock file and X socket of `display` (-1: none known) once its X server is gone; looks again
  /// every 250 ms for 5 s while it still runs (killed with the session's group, it may not have exited yet).
  void clean_x11_display(int display, int attempt);

  boost::asio::io_context& io_;
  const ManagerConfig& config_;
  std::string program_;
  SessionIndex& index_;
  Metrics& metrics_;
  SessionTable table_;
  SessionListener* listener_ = nullptr;
  std::map<std::int64_t, std::unique_ptr<Runtime>> runtimes_;
  struct ChildWatch;
  std::unique_ptr<ChildWatch> child_watch_;
  std::function<void()> on_all_gone_;  // set by shutdown()
  bool shutting_down_ = false;
  bool draining_ = false;  // set_draining
  std::unique_ptr<SocketFolder> socket_folder_;  // the sessions' private socket folder, while it is held
  std::string socket_dir_;  // its path (0700): the sessions' unix sockets; "" = they use TCP ports
  std::unique_ptr<IndexWriter> writer_;  // the index's writes, off this thread
  // Session starts, off this thread; its thread must outlive the sessions it started (PR_SET_PDEATHSIG).
  std::unique_ptr<ProcessLauncher> launcher_;
  int launches_in_flight_ = 0;  // starts queued or running on the launcher, whose pids the table lacks yet
  // after_session_command's runs, on a thread of their own; null without one. It reaps its own child.
  std::unique_ptr<SessionCopier> copier_;
  std::int64_t next_id_ = 1;             // session ids are handed out here, above the index's highest
  // Sessions whose latest version is queued for the writer, or was refused by it (a full disk) and waits to be
  // tried again, by id. Reads of the index look here first, so that they never see an older row than the table
  // did: what the index could not take is still served as the truth.
  struct Unsaved {
    std::uint64_t sequence = 0;  // of the newest write queued
    Session session;             // that version
    bool refused = false;        // its write failed; schedule_index_retry writes it again
  };
  std::map<std::int64_t, Unsaved> unsaved_;
  std::unique_ptr<boost::asio::steady_timer> index_retry_;  // armed while some write waits to be tried again
  std::chrono::seconds index_retry_delay_{1};
  std::uint64_t write_sequence_ = 0;
  std::map<SessionState, std::int64_t> ended_counts_;  // ended sessions by state, whole index
};

}  // namespace rfbsim::manager
