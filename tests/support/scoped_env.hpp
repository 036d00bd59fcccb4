// SPDX-License-Identifier: GPL-2.0-or-later
// ScopedEnv: sets an environment variable of the test process for a scope (programs started meanwhile inherit
// it), and puts back the earlier value, or its absence, after. Header-only.
#pragma once

#include <cstdlib>
#include <optional>
#include <string>

namespace rfbsim::test {

class ScopedEnv {
 public:
  /// Sets `name` to `value`, remembering what was there.
  ScopedEnv(std::string name, const std::string& value) : name_(std::move(name)) {
    if (const char* old = std::getenv(name_.c_str())) old_ = old;
    ::setenv(name_.c_str(), value.c_str(), 1);
  }
  /// Puts back the earlier value, or unsets it.
  ~ScopedEnv() {
    if (old_) {
      ::setenv(name_.c_str(), old_->c_str(), 1);
    } else {
      ::unsetenv(name_.c_str());
    }
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  std::string name_;
  std::optional<std::string> old_;
};

}  // namespace rfbsim::test
