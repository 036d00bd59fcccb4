// SPDX-License-Identifier: GPL-2.0-or-later
// The sim_manager that bench_manager measures, and the few things every part of it does with a session:
// start one through /start, end it through the admin API, wait for its index row.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "manager_process.hpp"

namespace rfbsim::bench {

/// The admin token bench_manager starts its managers with (24 characters; loopback only).
inline constexpr const char* kBenchAdminToken = "bench-manager-admin-0123";

/// How bench_manager runs sim_manager, whatever it measures.
struct ManagerRun {
  std::string program;   ///< the sim_manager binary
  std::string log;       ///< its stderr and its sessions' launch chatter are appended here
  std::string scenario;  ///< the only scenario it allows, and the one every link asks for
};

/// Starts sim_manager on a free loopback port with its data in `data_dir` (which the caller keeps until the
/// manager is gone), `--max-sessions max_sessions`, the admin token, a one-hour --max-duration-s, then
/// `extra_flags`, then `--session-arg` for each of `session_args`. SIGTERM on destruction ends its sessions;
/// the index is polled every 5 ms.
test::ManagerUnderTest start_manager(const ManagerRun& run, const std::filesystem::path& data_dir,
                                     const std::vector<std::string>& session_args, int max_sessions,
                                     const std::vector<std::string>& extra_flags = {});

/// GET /start for `uid`; returns the token of the 302's /s/<token>/, throws std::runtime_error on any other
/// answer (naming the status and the start of the body).
std::string start_session(const test::ManagerUnderTest& manager, const std::string& uid, const std::string& scenario);

/// POST /api/sessions/<id>/end with kBenchAdminToken; throws std::runtime_error unless the manager accepted it.
void end_session(const test::ManagerUnderTest& manager, std::int64_t id);

/// Polls the index until the session's row satisfies `done`; throws std::runtime_error after `timeout`,
/// naming `what` it never did and the state it was last in.
test::IndexRow wait_for_row(const test::ManagerUnderTest& manager, const std::string& token,
                            const std::function<bool(const test::IndexRow&)>& done,
                            std::chrono::milliseconds timeout, const char* what);

/// Whether an index state is one of a session that still runs (starting, running, ending).
bool is_live_state(const std::string& state);

}  // namespace rfbsim::bench
