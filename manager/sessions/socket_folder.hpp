// SPDX-License-Identifier: GPL-2.0-or-later
// The manager's private folder for its sessions' unix sockets (and x11 sessions' Xauthority files): one per
// data directory, so that a manager restarted after kill -9 finds the folder its predecessor left and clears it,
// rather than leaving one more rfbsim-manager-* folder of stale sockets in /tmp for each crash.
#pragma once

#include <string>

namespace rfbsim::manager {

/// The folder, held for as long as this object lives (a lock inside it tells a second manager of the same data
/// directory to keep off), and removed with it.
class SocketFolder {
 public:
  /// Takes /tmp/rfbsim-manager-<hash of data_dir's absolute path> (mode 0700, this user's): made, or found and
  /// cleared of what a dead predecessor left there. Where that name is not ours (another user's, a link, or a
  /// live manager's), a fresh mkdtemp folder instead. empty() when no folder could be had at all.
  explicit SocketFolder(const std::string& data_dir);
  ~SocketFolder();
  SocketFolder(const SocketFolder&) = delete;
  SocketFolder& operator=(const SocketFolder&) = delete;

  [[nodiscard]] const std::string& path() const { return path_; }
  [[nodiscard]] bool empty() const { return path_.empty(); }
  /// What was found and removed, or why the per-data-directory name could not be used ("" when neither).
  [[nodiscard]] const std::string& note() const { return note_; }

 private:
  bool take(const std::string& path);

  std::string path_;
  std::string note_;
  int lock_fd_ = -1;
};

/// The folder's name for `data_dir` (absolute or not): rfbsim-manager-<16 hex digits>.
std::string socket_folder_name(const std::string& data_dir);

}  // namespace rfbsim::manager
