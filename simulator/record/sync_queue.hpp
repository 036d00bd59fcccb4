// SPDX-License-Identifier: GPL-2.0-or-later
// SyncQueue: the thread that puts a session folder on disk, so that the simulation thread never waits for
// the disk (an fdatasync takes from a fraction of a millisecond to several on an idle disk, far more on a
// busy one). The simulation thread hands over appended bytes, sync requests and session.json's new text;
// the thread does them in order. Memory is bounded: a queue past its limit is a failure like a full disk.
//
// On the first failure the folder stops growing: appends made after it are dropped and counted, what was
// written is synced, the space reserved at the start is given back, and session.json is rewritten with a
// `data_incomplete` key carrying the reason, when the disk still takes it. After a write error (ENOSPC,
// EIO) nothing more is appended; after the queue overflowed (a disk that fell behind) what was already
// queued is still written, so that the files hold an unbroken start of the session either way.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <utility>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "record/file_io.hpp"

namespace rfbsim::sim {

/// Faults a test injects into the writer thread; the defaults inject none.
struct WriteFaults {
  /// Appended bytes the files take in all before a write fails with `error` (the write that crosses the
  /// limit writes up to it, as a filling disk does); none: no injected failure.
  std::optional<std::uint64_t> fail_after_bytes;
  int error = 28;  ///< errno of the injected failure (ENOSPC)
  /// Called on the writer thread before each step; a test blocks in it to stand for a stalled disk.
  std::function<void()> before_step;
};

/// How the writer thread is bounded.
struct SyncQueueLimits {
  std::size_t max_queued_bytes = 16u << 20;  ///< appended bytes waiting; more is a failure (disk fell behind)
  std::size_t reserve_bytes = 16u << 10;     ///< set aside at the start for session.json's failure note
};

class SyncQueue {
 public:
  /// The appended files, by index.
  enum File : int { kTrajectory = 0, kEvents = 1 };

  /// Takes over the open, already written folder `dir`: `files` (opened for appending; trajectories.csv,
  /// events.jsonl) and `dir_fd`, with session.json already in place as `document`. Sets space aside and
  /// starts the thread. Throws std::runtime_error when the space cannot be set aside (a disk already full).
  SyncQueue(std::filesystem::path dir, UniqueFd dir_fd, std::vector<std::pair<std::string, UniqueFd>> files,
            nlohmann::ordered_json document, SyncQueueLimits limits = {}, WriteFaults faults = {});
  /// Finishes what is queued, then stops the thread (close()).
  ~SyncQueue();
  SyncQueue(const SyncQueue&) = delete;
  SyncQueue& operator=(const SyncQueue&) = delete;

  /// Queues `bytes` (whole lines) for the end of `file`; after a failure they are dropped and counted.
  void append(File file, std::string bytes);
  /// Queues an fdatasync of both files (after what is queued before it).
  void sync();
  /// Queues session.json's new content, written after everything queued so far.
  void replace_document(nlohmann::ordered_json document);
  /// Waits until everything queued so far is done (or dropped).
  void drain();
  /// Drains, stops the thread and, when nothing failed, gives the reserved space back. Later calls
  /// to append, sync and replace_document do nothing.
  void close();

  /// Why the folder stopped growing, on one line; none while all is well. Any thread.
  [[nodiscard]] std::optional<std::string> failure() const;
  /// Appended bytes dropped since the failure. Any thread.
  [[nodiscard]] std::uint64_t dropped_bytes() const;

 private:
  struct Step {
    enum class Kind { Append, Sync, Replace } kind = Kind::Sync;
    int file = 0;
    std::string bytes;
  };

  void run();
  void perform(Step& step);
  void fail(const std::string& reason);  // on the writer thread: the first failure stops the appends
  void handle_failure();                 // sync what is there, give the reserve back, note the reason
  FileResult write_document();           // the newest document, with data_incomplete after a failure
  std::filesystem::path reserve_path() const { return dir_ / "session.json.reserve"; }

  const std::filesystem::path dir_;
  UniqueFd dir_fd_;
  std::vector<std::pair<std::string, UniqueFd>> files_;  // (name, descriptor)
  const SyncQueueLimits limits_;
  WriteFaults faults_;
  std::uint64_t appended_ = 0;  // writer thread: bytes appended, for the injected failure

  mutable std::mutex mutex_;
  std::condition_variable wake_;     // a step was queued, or closing
  std::condition_variable drained_;  // the queue emptied and the thread is idle
  std::deque<Step> queue_;
  std::size_t queued_bytes_ = 0;
  bool busy_ = false;  // the thread is doing a step it took off the queue
  bool closing_ = false;
  bool stopped_ = false;  // the thread has left its loop
  std::optional<std::string> failure_;
  std::uint64_t dropped_ = 0;
  nlohmann::ordered_json document_;  // the newest session.json content
  bool reserve_held_ = false;        // writer thread after the start
  bool failure_handled_ = false;     // set by the writer thread as it starts noting the failure
  bool write_failed_ = false;        // writer thread: a write, sync or replace failed; append no more
  std::thread thread_;
};

}  // namespace rfbsim::sim
