// SPDX-License-Identifier: GPL-2.0-or-later
// IndexWriter: the index's writes in order, off the I/O thread.
#include "sessions/index_writer.hpp"

#include <filesystem>
#include <fstream>

#include "sessions/session_views.hpp"

namespace rfbsim::manager {

IndexWriter::IndexWriter(const std::string& path) : index_(path), thread_([this] { run(); }) {}

IndexWriter::~IndexWriter() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void IndexWriter::insert(Session session, Done done) { enqueue({true, std::move(session), std::move(done)}); }

void IndexWriter::update(Session session, Done done) { enqueue({false, std::move(session), std::move(done)}); }

void IndexWriter::enqueue(Job job) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    jobs_.push_back(std::move(job));
  }
  wake_.notify_one();
}

void IndexWriter::drain() {
  std::unique_lock<std::mutex> lock(mutex_);
  idle_.wait(lock, [this] { return jobs_.empty() && !busy_; });
}

void IndexWriter::run() {
  for (;;) {
    Job job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return stopping_ || !jobs_.empty(); });
      if (jobs_.empty()) return;  // stopping, and everything is written
      job = std::move(jobs_.front());
      jobs_.pop_front();
      busy_ = true;
    }
    const std::string error = record_session(index_, job.session, job.insert);
    if (job.done) job.done(error);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      busy_ = false;
    }
    idle_.notify_all();
  }
}

std::string record_session(SessionIndex& index, const Session& session, bool insert) {
  std::string error;
  try {
    index.record(session, insert);  // an update writes the row too, where its insert had failed
  } catch (const std::exception& failure) {
    error = std::string("cannot write the index: ") + failure.what();
  }
  const std::string record_error = write_session_record(session);
  return error.empty() ? record_error : error;
}

std::string write_session_record(const Session& session) {
  if (session.data_path.empty()) return "";
  const std::filesystem::path folder(session.data_path);
  std::error_code ec;
  if (!std::filesystem::is_directory(folder, ec)) return "";  // never made (a failed start): nothing to keep
  const std::filesystem::path target = folder / "manager.json";
  const std::filesystem::path temporary = folder / ".manager.json.tmp";
  bool written = false;
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    out << session_record_json(session);
    written = static_cast<bool>(out.flush());
  }
  if (written) std::filesystem::rename(temporary, target, ec);
  if (!written || ec) {
    // No half-written or empty temporary is left behind on a full disk; the last whole manager.json stays.
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    return "cannot write " + target.string() + (ec ? ": " + ec.message() : std::string());
  }
  return "";
}

}  // namespace rfbsim::manager
