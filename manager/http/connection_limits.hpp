// SPDX-License-Identifier: GPL-2.0-or-later
// ConnectionLimits: how many connections are open per client address and in all, and whether one more may
// open. Pure: the frontend calls it on accept and on close.
//
// Why both: a per-address cap stops one machine (1,500 idle half-sent requests, a slowloris) from holding the
// descriptors every participant needs; the total cap keeps the manager below its descriptor limit, so that it
// can always still open a session's sockets, pipes and files.
#pragma once

#include <cstddef>
#include <map>
#include <string>

namespace rfbsim::manager {

class ConnectionLimits {
 public:
  /// `per_address` and `total`: the most open at once (0 = no cap).
  ConnectionLimits(std::size_t per_address, std::size_t total) : per_address_(per_address), total_(total) {}

  /// Counts one more connection from `address` if the caps allow it; false (nothing counted) if not.
  bool try_open(const std::string& address);
  /// Counts one more connection under `address` against the total cap only (a trusted front end's, which
  /// carries many participants); false if the total is reached.
  bool try_open_uncapped(const std::string& address);
  /// A connection counted by try_open or try_open_uncapped closed.
  void closed(const std::string& address);

  [[nodiscard]] std::size_t open(const std::string& address) const;
  [[nodiscard]] std::size_t open_total() const { return open_total_; }
  /// Addresses with a connection open (bounded by open_total()).
  [[nodiscard]] std::size_t addresses() const { return per_address_open_.size(); }

 private:
  std::size_t per_address_;
  std::size_t total_;
  std::size_t open_total_ = 0;
  std::map<std::string, std::size_t> per_address_open_;
};

}  // namespace rfbsim::manager
