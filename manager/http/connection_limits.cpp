// SPDX-License-Identifier: GPL-2.0-or-later
// ConnectionLimits: per-address and total counts of open connections.
#include "http/connection_limits.hpp"

namespace rfbsim::manager {

bool ConnectionLimits::try_open(const std::string& address) {
  if (total_ > 0 && open_total_ >= total_) return false;
  std::size_t& count = per_address_open_[address];
  if (per_address_ > 0 && count >= per_address_) return false;
  ++count;
  ++open_total_;
  return true;
}

bool ConnectionLimits::try_open_uncapped(const std::string& address) {
  if (total_ > 0 && open_total_ >= total_) return false;
  ++per_address_open_[address];
  ++open_total_;
  return true;
}

void ConnectionLimits::closed(const std::string& address) {
  const auto it = per_address_open_.find(address);
  if (it == per_address_open_.end()) return;  // not counted: nothing to undo
  if (--it->second == 0) per_address_open_.erase(it);
  if (open_total_ > 0) --open_total_;
}

std::size_t ConnectionLimits::open(const std::string& address) const {
  const auto it = per_address_open_.find(address);
  return it == per_address_open_.end() ? 0 : it->second;
}

}  // namespace rfbsim::manager
