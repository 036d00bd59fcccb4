// SPDX-License-Identifier: GPL-2.0-or-later
// WatchRecord: the watcher's session.json, written at the start and replaced at the end.
#include "app/watch_record.hpp"

#include <stdexcept>
#include <system_error>

#include "app/session_setup.hpp"
#include "record/digest.hpp"
#include "record/file_io.hpp"
#include "record/session_writer.hpp"

namespace rfbsim::sim {

namespace {

nlohmann::json text_or_null(const std::optional<std::string>& text) {
  return text ? nlohmann::json(*text) : nlohmann::json(nullptr);
}

}  // namespace

WatchRecord::WatchRecord(const std::filesystem::path& data_dir, const std::string& uid, const SessionMeta& meta,
                         std::optional<std::int64_t> yoked_to, const std::string& uid_key)
    : dir_(data_dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir_, ec);
  if (ec) throw std::runtime_error(dir_.string() + ": cannot create the folder (" + ec.message() + ")");
  const std::string source_hash = hash_uid(uid_key, meta.uid);
  doc_ = {{"kind", "replay"},
          {"condition", "video"},
          {"uid", uid},
          {"yoked_to", yoked_to ? nlohmann::json(*yoked_to) : nlohmann::json(nullptr)},
          {"yoked_to_uid_hash", source_hash},
          {"scenario", meta.scenario},
          {"camera", std::string(camera_mode_name(meta.camera))},
          // What was shown: enough to tell it from another recording of the same walker, and nothing that
          // names them (their folder's name holds their uid).
          {"replay_of",
           {{"uid_hash", source_hash},
            {"scenario", meta.scenario},
            {"seed", std::to_string(meta.seed)},
            {"started_at", meta.started_at},
            {"end_tick", meta.end_tick ? nlohmann::json(*meta.end_tick) : nlohmann::json(nullptr)},
            {"end_reason", text_or_null(meta.end_reason)},
            {"outcome", text_or_null(meta.outcome)}}},
          {"versions", {{"rfbsim", rfbsim_version()}, {"build", rfbsim_build_id()}}},
          {"started_at", iso_utc_now()},
          {"ended_at", nullptr},
          {"end_tick", nullptr},
          {"end_reason", nullptr},
          {"outcome", nullptr},
          {"viewers", 0}};
  if (const std::string error = write(); !error.empty()) throw std::runtime_error(error);
}

std::string WatchRecord::finish(const std::string& reason, std::uint64_t tick, bool watched) {
  doc_["ended_at"] = iso_utc_now();
  doc_["end_tick"] = tick;
  doc_["end_reason"] = reason;
  doc_["outcome"] = watched ? nlohmann::json("watched") : nlohmann::json(nullptr);
  doc_["viewers"] = viewers_;
  return write();
}

std::string WatchRecord::write() {
  std::string error;
  const UniqueFd dir_fd = open_dir(dir_, error);
  if (!dir_fd.valid()) return error;
  // Text of any bytes (a uid, a folder name) is replaced rather than thrown over: the record must be written.
  const std::string text = doc_.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  const FileResult result = replace_file(dir_, dir_fd.get(), "session.json", text);
  return result.ok() ? "" : (dir_ / "session.json").string() + ": " + result.error;
}

}  // namespace rfbsim::sim
