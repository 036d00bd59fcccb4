// SPDX-License-Identifier: GPL-2.0-or-later
// IndexWriter: the session index's writes, and each session's manager.json, on a thread of their own.
//
// Why: a commit with synchronous=FULL waits for the disk (milliseconds, far more on a busy or failing disk), and
// the manager's one I/O thread carries every participant's relay. So the I/O thread only queues a copy of the
// session and goes on; this thread writes them in order (a session's insert before its updates) through its
// own SQLite connection, and reports each result through a callback on its own thread (the caller posts it
// back). The I/O thread reads the index through its own connection; WAL lets it read while this one writes.
#pragma once

#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "sessions/session.hpp"
#include "sessions/session_index.hpp"

namespace rfbsim::manager {

class IndexWriter {
 public:
  /// The outcome of one write: "" or what went wrong. Called on the writer's thread.
  using Done = std::function<void(const std::string& error)>;

  /// Opens its own connection to the index at `path` (throws std::runtime_error like SessionIndex).
  explicit IndexWriter(const std::string& path);
  /// Writes what is queued, then stops.
  ~IndexWriter();
  IndexWriter(const IndexWriter&) = delete;
  IndexWriter& operator=(const IndexWriter&) = delete;

  /// Queues a new row for `session` (its id already chosen) and its manager.json.
  void insert(Session session, Done done);
  /// Queues `session`'s mutable fields and its manager.json (its whole row where the index has none yet).
  void update(Session session, Done done);
  /// Blocks until everything queued so far is written (tests, shutdown).
  void drain();

 private:
  struct Job {
    bool insert = false;
    Session session;
    Done done;
  };
  void run();
  void enqueue(Job job);

  SessionIndex index_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable idle_;
  std::deque<Job> jobs_;
  bool busy_ = false;
  bool stopping_ = false;
  std::thread thread_;  // last: starts once everything above exists
};

/// Writes `session` to `index` (a new row with `insert`, else SessionIndex::write) and then its manager.json, on
/// the caller's thread; "" or what went wrong (the index's failure first).
std::string record_session(SessionIndex& index, const Session& session, bool insert);

/// Writes `session_record_json(session)` to `<data_path>/manager.json` through a temporary file renamed over
/// it, so that a reader never sees half of one. "" or what went wrong. Not synced: the index is the durable
/// record, this a copy for the study's tools.
std::string write_session_record(const Session& session);

}  // namespace rfbsim::manager
