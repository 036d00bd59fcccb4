// SPDX-License-Identifier: GPL-2.0-or-later
// SyncQueue: ordered appends, syncs and replaces on a thread of their own, bounded, stopping at the first failure.
#include "record/sync_queue.hpp"

#include <unistd.h>

#include <cstring>
#include <stdexcept>
#include <utility>

#include "rfbsim/log.hpp"

namespace rfbsim::sim {

namespace {

constexpr const char* kDocument = "session.json";
constexpr std::size_t kPage = 4096;

}  // namespace

SyncQueue::SyncQueue(std::filesystem::path dir, UniqueFd dir_fd, std::vector<std::pair<std::string, UniqueFd>> files,
                     nlohmann::ordered_json document, SyncQueueLimits limits, WriteFaults faults)
    : dir_(std::move(dir)),
      dir_fd_(std::move(dir_fd)),
      files_(std::move(files)),
      limits_(limits),
      faults_(std::move(faults)),
      document_(std::move(document)) {
  // Room for the failure note: when the disk fills, this file is removed so that session.json can still
  // be rewritten with the reason. Four times today's document leaves room for what it gains by the end.
  if (limits_.reserve_bytes > 0) {
    std::size_t bytes = std::max(limits_.reserve_bytes, 4 * document_.dump(2).size());
    bytes = (bytes + kPage - 1) / kPage * kPage;
    FileResult reserved = reserve_space(reserve_path(), bytes);
    if (reserved.ok()) reserved = sync_dir(dir_fd_.get(), dir_.string());
    if (!reserved.ok()) throw std::runtime_error(dir_.string() + ": " + reserved.error);
    reserve_held_ = true;
  }
  thread_ = std::thread([this] { run(); });
}

SyncQueue::~SyncQueue() { close(); }

void SyncQueue::append(File file, std::string bytes) {
  if (bytes.empty()) return;
  std::lock_guard lock(mutex_);
  if (closing_) return;
  if (failure_) {
    dropped_ += bytes.size();
    return;
  }
  if (queued_bytes_ + bytes.size() > limits_.max_queued_bytes) {
    // The disk takes less than the session makes (or hangs): holding on would grow without bound.
    const std::size_t bound = limits_.max_queued_bytes;
    const std::string amount = bound >= (1u << 20) ? std::to_string(bound >> 20) + " MiB" : std::to_string(bound >> 10) + " KiB";
    failure_ = one_line("the disk fell behind: more than " + amount + " waiting to be written");
    dropped_ += bytes.size();
    log::error("record", "%s: %s; the session goes on, its data is incomplete", dir_.c_str(), failure_->c_str());
    wake_.notify_one();
    return;
  }
  queued_bytes_ += bytes.size();
  queue_.push_back({Step::Kind::Append, static_cast<int>(file), std::move(bytes)});
  wake_.notify_one();
}

void SyncQueue::sync() {
  std::lock_guard lock(mutex_);
  if (closing_ || failure_) return;
  // Two syncs in a row do the work of one.
  if (!queue_.empty() && queue_.back().kind == Step::Kind::Sync) return;
  queue_.push_back({Step::Kind::Sync, 0, {}});
  wake_.notify_one();
}

void SyncQueue::replace_document(nlohmann::ordered_json document) {
  std::lock_guard lock(mutex_);
  if (closing_) return;
  document_ = std::move(document);
  // At most one replace waits, and always last: the document is written after the lines it describes,
  // and a burst of task events costs one rewrite, not one each.
  for (auto it = queue_.begin(); it != queue_.end(); ++it) {
    if (it->kind == Step::Kind::Replace) {
      queue_.erase(it);
      break;
    }
  }
  queue_.push_back({Step::Kind::Replace, 0, {}});
  wake_.notify_one();
}

void SyncQueue::drain() {
  std::unique_lock lock(mutex_);
  // Idle, and no failure waiting to be noted.
  drained_.wait(lock, [this] { return (queue_.empty() && !busy_ && !(failure_ && !failure_handled_)) || stopped_; });
}

void SyncQueue::close() {
  {
    std::lock_guard lock(mutex_);
    if (closing_) return;
    closing_ = true;
  }
  wake_.notify_one();
  if (thread_.joinable()) thread_.join();
  // A clean end gives the reserved space back; after a failure it is already gone.
  if (reserve_held_) {
    ::unlink(reserve_path().c_str());
    sync_dir(dir_fd_.get(), dir_.string());
    reserve_held_ = false;
  }
  drained_.notify_all();
}

std::optional<std::string> SyncQueue::failure() const {
  std::lock_guard lock(mutex_);
  return failure_;
}

std::uint64_t SyncQueue::dropped_bytes() const {
  std::lock_guard lock(mutex_);
  return dropped_;
}

void SyncQueue::run() {
  std::unique_lock lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return !queue_.empty() || closing_ || (failure_ && !failure_handled_); });
    // A failure the simulation thread found (the queue overflowed) is noted before anything else.
    if (failure_ && !failure_handled_) {
      busy_ = true;
      lock.unlock();
      handle_failure();
      lock.lock();
      busy_ = false;
      if (queue_.empty()) drained_.notify_all();
      continue;
    }
    if (queue_.empty()) {
      if (closing_) break;
      continue;
    }
    Step step = std::move(queue_.front());
    queue_.pop_front();
    if (step.kind == Step::Kind::Append) queued_bytes_ -= step.bytes.size();
    busy_ = true;
    lock.unlock();
    perform(step);
    lock.lock();
    busy_ = false;
    if (queue_.empty()) drained_.notify_all();
  }
  // What the last steps appended reaches the disk before the end is reported (no sync is queued after
  // an overflow).
  // After a failure, the note gets the final count of what was dropped.
  const bool failed = failure_.has_value();
  lock.unlock();
  if (!write_failed_) {
    for (const auto& [name, fd] : files_) sync_data(fd.get(), name);
  }
  if (failed) write_document();
  lock.lock();
  stopped_ = true;
  drained_.notify_all();
}

void SyncQueue::perform(Step& step) {
  if (faults_.before_step) faults_.before_step();
  const bool failed = write_failed_;
  switch (step.kind) {
    case Step::Kind::Append: {
      if (failed) {
        std::lock_guard lock(mutex_);
        dropped_ += step.bytes.size();
        return;
      }
      const auto& [name, fd] = files_[static_cast<std::size_t>(step.file)];
      std::string_view bytes = step.bytes;
      // The injected fault: the write that crosses the limit stops at it, as on a disk that just filled.
      bool inject = false;
      if (faults_.fail_after_bytes) {
        const std::uint64_t room = *faults_.fail_after_bytes > appended_ ? *faults_.fail_after_bytes - appended_ : 0;
        if (bytes.size() > room) {
          bytes = bytes.substr(0, static_cast<std::size_t>(room));
          inject = true;
        }
      }
      FileResult written = write_all(fd.get(), bytes, name);
      appended_ += written.written;
      if (written.ok() && inject) written.error = one_line(name + ": cannot write (" + std::strerror(faults_.error) + ")");
      if (!written.ok()) {
        {
          std::lock_guard lock(mutex_);
          dropped_ += step.bytes.size() - written.written;
        }
        fail(written.error);
      }
      return;
    }
    case Step::Kind::Sync:
      if (failed) return;  // handle_failure synced what there was
      for (const auto& [name, fd] : files_) {
        const FileResult synced = sync_data(fd.get(), name);
        if (!synced.ok()) {
          fail(synced.error);
          return;
        }
      }
      return;
    case Step::Kind::Replace: {
      const FileResult replaced = write_document();
      if (replaced.ok()) return;
      if (!failed) {
        fail(replaced.error);
      } else {
        log::warn("record", "%s: %s", dir_.c_str(), replaced.error.c_str());  // the failure was told already
      }
      return;
    }
  }
}

void SyncQueue::fail(const std::string& reason) {
  write_failed_ = true;
  {
    std::lock_guard lock(mutex_);
    if (failure_) {
      // The queue had overflowed already: that stays the reason, this one is only logged.
      log::warn("record", "%s: %s", dir_.c_str(), reason.c_str());
      return;
    }
    failure_ = one_line(reason);
  }
  log::error("record", "%s: %s; the session goes on, its data is incomplete", dir_.c_str(), reason.c_str());
  handle_failure();
}

void SyncQueue::handle_failure() {
  {
    std::lock_guard lock(mutex_);
    failure_handled_ = true;
  }
  // Whatever did reach the files is kept: sync it (best effort; the disk may refuse this too).
  for (const auto& [name, fd] : files_) sync_data(fd.get(), name);
  // Give the reserved space back so that the note below fits on a full disk.
  if (reserve_held_) {
    ::unlink(reserve_path().c_str());
    sync_dir(dir_fd_.get(), dir_.string());
    reserve_held_ = false;
  }
  const FileResult noted = write_document();
  if (!noted.ok()) {
    log::error("record", "%s: cannot note the failure in %s: %s", dir_.c_str(), kDocument, noted.error.c_str());
  }
}

FileResult SyncQueue::write_document() {
  nlohmann::ordered_json document;
  {
    std::lock_guard lock(mutex_);
    document = document_;
    if (failure_) document["data_incomplete"] = {{"reason", *failure_}, {"dropped_bytes", dropped_}};
  }
  const std::string text = document.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
  return replace_file(dir_, dir_fd_.get(), kDocument, text);
}

}  // namespace rfbsim::sim
